#pragma once
#include "renderer/metrics/reference.h"

#include <cstdint>
#include <string>
#include <vector>

namespace pdflab {

struct ReferenceOptions {
  std::string scene;
  int width = 0, height = 0;  // 0: the scene's own
  int max_depth = 0;          // 0: the scene's own
  std::uint32_t spp = 0;      // exactly one of spp, seconds, target_relmse
  double seconds = 0.0;
  double target_relmse = 0.0;
  std::string strategy;  // empty: default_reference_strategy (reference_strategy)
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
// damaged entry is an InputError when `required`, otherwise a warning on
// stderr (with --quiet too: a measurement asked for will not be made), the
// reason in `missing` when given, and an empty Reference. A file is loaded
// as given.
Reference resolve_reference(const std::string& option, const Scene& scene, const std::string& scene_file,
                            const std::string& cache_dir, bool required, bool quiet, std::string* missing = nullptr);

// A note on stderr when `reference` does not record its seeds (a PFM without
// a sidecar, from another program or copied alone): the seed trap cannot
// check it against `seeds`, the runs' own.
void note_unknown_seed(const Reference& reference, const std::vector<std::uint64_t>& seeds);

// `--cache-dir` (or the default cache folder) where a reference will be
// stored: a folder, or one that can be made (no file, symlink loop or file
// on its way), writable. Checked before any rendering; InputError otherwise.
void check_cache_dir(const std::string& cache_dir);

}  // namespace pdflab
