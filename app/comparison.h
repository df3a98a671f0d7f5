#pragma once
// What the headless comparisons (bench, sweep) share: their options, the
// checks of those options, and the reference every run is measured against.
#include "renderer/metrics/reference.h"
#include "renderer/sampling/strategy.h"
#include "renderer/scene/scene.h"

#include <cstdint>
#include <string>
#include <vector>

namespace pdflab {

struct ComparisonOptions {
  std::string scene;
  int roulette_depth = 0;  // --rr: Russian roulette from this depth on in every strategy (0: as given)
  double seconds = 0.0;    // equal time per run (or)
  std::uint32_t spp = 0;   // equal samples per pixel
  std::string reference;   // PFM (its size sets the render size) or "auto" (the cache)
  int width = 0, height = 0;  // with "auto": the size to look up (0: the scene's)
  std::string cache_dir;      // empty: reference_cache_dir()
  // Not render's default (1): a reference rendered with the same seed shares
  // its first samples with the run, and the error would look too small.
  std::uint64_t seed = 2;
  std::string csv;
  std::string plot;  // SVG, optional
  int threads = 0;
  bool quiet = false;
};

// The checks both commands make before any file is read: one of --seconds and
// --spp, the thread count, and every output (the CSV, the plot and
// `other_outputs`, empty ones ignored) writable and distinct. InputError.
void check_comparison_options(const ComparisonOptions& options, const std::vector<std::string>& other_outputs);

// `--reference FILE|auto` of a headless comparison (bench, sweep): sizes and
// prepares `scene` (to the file's size, or to width/height with auto), loads
// the reference, and refuses any of `seeds` x `strategies` that would repeat
// the reference's random numbers. InputError for all of these.
struct ReferenceChoice {
  std::string option;  // a .pfm or "auto"
  std::string scene_file, cache_dir;
  int width = 0, height = 0;  // with auto; 0: the scene's
};
ReferenceChoice reference_choice(const ComparisonOptions& options);
Reference comparison_reference(Scene& scene, const ReferenceChoice& choice, const std::vector<Strategy>& strategies,
                               const std::vector<std::uint64_t>& seeds, bool quiet);

}  // namespace pdflab
