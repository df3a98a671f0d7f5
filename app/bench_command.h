#pragma once
#include <cstdint>
#include <string>

namespace pdflab {

struct BenchOptions {
  std::string scene;
  std::string strategies;  // "S1;S2;..."
  double seconds = 0.0;    // equal time per strategy (or)
  std::uint32_t spp = 0;   // equal samples per pixel
  std::string reference;   // PFM (its size sets the render size) or "auto" (the cache)
  int width = 0, height = 0;  // with "auto": the size to look up (0: the scene's)
  std::string cache_dir;      // empty: reference_cache_dir()
  std::string csv;
  std::string plot;        // SVG, optional
  std::string curves;      // CSV of every checkpoint, optional
  // Not render's default (1): a reference rendered with the same seed shares
  // its first samples with the run, and the error would look too small.
  std::uint64_t seed = 2;
  int threads = 0;
  bool quiet = false;
};

// Runs `pdflab bench`. Returns the exit status; throws InputError for bad input.
int run_bench(const BenchOptions& options);

}  // namespace pdflab
