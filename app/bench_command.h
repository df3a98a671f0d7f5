#pragma once
#include "renderer/metrics/reference.h"
#include "renderer/sampling/strategy.h"
#include "renderer/scene/scene.h"

#include <cstdint>
#include <string>
#include <vector>

namespace pdflab {

struct BenchOptions {
  std::string scene;
  std::string strategies;  // "S1;S2;..."
  int roulette_depth = 0;  // --rr: Russian roulette from this depth on in every strategy (0: as given)
  double seconds = 0.0;    // equal time per strategy (or)
  std::uint32_t spp = 0;   // equal samples per pixel
  std::string reference;   // PFM (its size sets the render size) or "auto" (the cache)
  int width = 0, height = 0;  // with "auto": the size to look up (0: the scene's)
  std::string cache_dir;      // empty: reference_cache_dir()
  std::string csv;
  std::string plot;        // SVG, optional
  std::string curves;      // CSV of every checkpoint, optional
  // "A,B": predict, from the paths of the strategy nearest w = 0.5 among those
  // mixing A and B (A's share w of the pair, the others as in the first such
  // strategy), the efficiency of every other such strategy. Optional.
  std::string predict;
  // Not render's default (1): a reference rendered with the same seed shares
  // its first samples with the run, and the error would look too small.
  std::uint64_t seed = 2;
  int threads = 0;
  bool quiet = false;
};

// `--reference FILE|auto` of a headless comparison (bench, sweep): sizes and
// prepares `scene` (to the file's size, or to width/height with auto), loads
// the reference, and refuses any of `seeds` x `strategies` that would repeat
// the reference's random numbers. InputError for all of these.
struct ReferenceChoice {
  std::string option;  // a .pfm or "auto"
  std::string scene_file, cache_dir;
  int width = 0, height = 0;  // with auto; 0: the scene's
};
Reference comparison_reference(Scene& scene, const ReferenceChoice& choice, const std::vector<Strategy>& strategies,
                               const std::vector<std::uint64_t>& seeds, bool quiet);

// Runs `pdflab bench`. Returns the exit status; throws InputError for bad input.
int run_bench(const BenchOptions& options);

}  // namespace pdflab
