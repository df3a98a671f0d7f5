#pragma once
#include "renderer/metrics/reference.h"

#include <cstdint>
#include <string>

namespace pdflab {

struct ReferenceOptions {
  std::string scene;
  int width = 0, height = 0;  // 0: the scene's own
  int max_depth = 0;          // 0: the scene's own
  std::uint32_t spp = 0;      // exactly one of spp, seconds, target_relmse
  double seconds = 0.0;
  double target_relmse = 0.0;
  std::string strategy;  // empty: default_reference_strategy
  int roulette_depth = 0;  // --rr: Russian roulette from this depth on in every strategy (0: as given)
  std::uint32_t seed_stream = 0;
  std::string out;        // optional: also written here
  std::string cache_dir;  // empty: reference_cache_dir()
  int threads = 0;
  bool quiet = false;
};

// Runs `pdflab reference`. Returns the exit status; throws InputError for bad input.
int run_reference(const ReferenceOptions& options);

// `--reference FILE` or `--reference auto` of render and bench, for `scene` at
// the size and depth it will render. auto looks in the cache: a miss or a
// damaged entry is an InputError when `required`, otherwise a note on stderr
// (unless quiet) and an empty Reference. A file is loaded as given.
Reference resolve_reference(const std::string& option, const Scene& scene, const std::string& scene_file,
                            const std::string& cache_dir, bool required, bool quiet);

}  // namespace pdflab
