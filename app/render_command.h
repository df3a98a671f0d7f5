#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace pdflab {

struct RenderOptions {
  // Given or not: with resume, the scene and strategy default to the film's;
  // the image may be left out when a film is written.
  std::string scene;
  bool scene_given = true;
  std::string strategy;
  bool strategy_given = true;
  int roulette_depth = 0;  // --rr: Russian roulette from this depth on in every strategy (0: as given)
  std::uint32_t spp = 0;
  bool spp_given = true;
  std::string out;
  bool out_given = true;
  std::uint64_t seed = 1;
  bool seed_given = false;
  std::uint32_t first_sample = 0;
  bool first_sample_given = false;
  int threads = 0;
  int width = 0, height = 0;  // 0: the scene's own
  std::string stats_json;
  std::string transfer = "gamma2";
  std::string reference;  // optional: a PFM or "auto" (the cache) to measure against
  std::string cache_dir;  // empty: reference_cache_dir()
  bool quiet = false;
  std::string film_out;          // the accumulation as a film file (film_file.h)
  std::string resume;            // continue this film (film_out defaults to it)
  double checkpoint_seconds = 60.0;  // with film_out: save the film this often (0: only at the end)
};

// Runs `pdflab render`. Returns the process exit status; throws InputError for bad input.
int run_render(const RenderOptions& options);

struct MergeOptions {
  std::vector<std::string> films;
  std::string out, film_out, stats_json;
  std::string transfer = "gamma2";
  // > 0: the films must hold exactly the samples [0, expect_spp) of one seed
  // (a fan-out's whole); a gap or anything beyond is refused, named.
  std::uint32_t expect_spp = 0;
};

// Runs `pdflab merge`: adds films of one scene and settings with disjoint
// sample ranges. Returns the exit status; InputError for bad input.
int run_merge(const MergeOptions& options);

}  // namespace pdflab
