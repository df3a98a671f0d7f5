#pragma once
#include <cstdint>
#include <string>

namespace pdflab {

struct RenderOptions {
  std::string scene;
  std::string strategy;
  std::uint32_t spp = 0;
  std::string out;
  std::uint64_t seed = 1;
  int threads = 0;
  int width = 0, height = 0;  // 0: the scene's own
  std::string stats_json;
  std::string transfer = "gamma2";
  std::string reference;  // optional: a PFM or "auto" (the cache) to measure against
  std::string cache_dir;  // empty: reference_cache_dir()
  bool quiet = false;
};

// Runs `pdflab render`. Returns the process exit status; throws InputError for bad input.
int run_render(const RenderOptions& options);

}  // namespace pdflab
