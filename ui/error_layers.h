#pragma once
// The false-colour layers drawn over or instead of the image: relative
// standard error, difference to the reference, dropped samples.
#include "renderer/metrics/reference.h"
#include "renderer/session/session.h"
#include "ui/colour_scale.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace pdflab::ui {

enum class ViewMode : std::uint8_t {
  Image,
  RelativeError,
  Difference,
  Drops,
  BestWeight,
  TechniqueShare,
  GuidingTree,
  Count
};
inline constexpr int kViewModeCount = static_cast<int>(ViewMode::Count);
const char* view_mode_label(ViewMode mode);
ViewMode next_view_mode(ViewMode mode);
// Whether the view exports as a figure with a colour bar (Ctrl+E): the heat
// map, the difference and the two weight views; not the image itself, nor the
// views drawn over it (dropped samples, path guiding's tree).
bool view_mode_exports(ViewMode mode);
// A view mode by its short name (image, heatmap, difference, drops,
// best-weight, technique-share, guiding-tree); InputError naming them otherwise.
ViewMode parse_view_mode(const std::string& name);

// The per-pixel error a false-colour view shows, chosen as in tev: the signed
// error, its absolute value or square, and those relative to the value (over
// value + 0.01, and value^2 + 0.01 as relMSE has it). The heat map's error is
// the noise of the mean (its standard error), so it has no sign.
enum class ErrorMetric : std::uint8_t { Signed, Absolute, Squared, Relative, RelativeSquared, Count };
inline constexpr int kErrorMetricCount = static_cast<int>(ErrorMetric::Count);
const char* error_metric_label(ViewMode mode, ErrorMetric metric);
bool view_offers_metric(ViewMode mode, ErrorMetric metric);

// A view's value range: from the image (its 1st and 99th percentiles, made
// round) or as set. A signed metric uses `hi` alone, for -hi..hi; the others
// are drawn on a log scale from `lo` to `hi`.
struct ViewRange {
  bool automatic = true;
  double lo = 1e-3, hi = 10.0;
  bool operator==(const ViewRange&) const = default;
};
// A usable range: positive, finite, hi at least kMinRangeRatio times lo (a
// typed 0, a swapped pair or two equal ends is fixed).
inline constexpr double kMinRangeRatio = 1.05;
ViewRange sanitized(const ViewRange& range, bool signed_metric);
struct LayerOptions {
  ErrorMetric metric = ErrorMetric::Relative;
  ViewRange range;
  bool operator==(const LayerOptions&) const = default;
};
// The heat map starts on the relative standard error over a fixed 0.001..10,
// so two strategies' maps compare; the difference view on the signed error, its range automatic.
LayerOptions default_heat_map_options();
LayerOptions default_difference_options();

// The reference (renderer/metrics/reference.h): mean, variance, sidecar.
using ReferenceImage = pdflab::Reference;

// Empty when the sizes agree; otherwise a sentence saying which is which.
std::string reference_size_mismatch(const ReferenceImage& reference, int render_width, int render_height);

// Luminance of (image - reference) per pixel.
std::vector<float> luminance_difference(const std::vector<float>& rgb, const std::vector<float>& reference);
// A half range for the difference view: the 99th percentile of |d|, made nice,
// so a few fireflies do not wash the rest out.
double difference_half_range(const std::vector<float>& difference);
// The values a view shows for `metric`, one per pixel, from the luminance of
// the image, of the reference, and of the film's noise (the heat map: the
// standard error of the mean is the relative one times (mean + 0.01)).
std::vector<float> heat_map_values(const PublishedImage& image, ErrorMetric metric);
std::vector<float> difference_values(const std::vector<float>& rgb, const std::vector<float>& reference,
                                     ErrorMetric metric);
// The colour scale of `values` under `options`: diverging and linear for the
// signed error, else logarithmic; an automatic range from the values.
ColourScale error_scale(ViewMode mode, const LayerOptions& options, const std::vector<float>& values);

// A false-colour layer as RGBA8, row 0 at the top, drawn over (Drops) or
// instead of (the others) the image. Returns false with the reason in `why`
// when the mode cannot be shown for this image (a preview, no reference, ...).
struct ViewLayer {
  std::vector<std::uint8_t> rgba;
  int width = 0, height = 0;
  ColourScale scale;  // for the colour bar (unused for Drops)
  std::array<std::uint64_t, 4> drop_pixels{};  // Drops: pixels per reason (+ several, last)
};
// The mixture-weight views' data (app/viewer_weights.h predicts them): per
// cell of block x block pixels the predicted best weight of technique `a`
// (its share of the pair; negative: w does not matter there), and per pixel
// the share of the light its paths found through `a`'s directions (negative:
// no light found).
struct WeightMaps {
  std::string a, b;  // the pair's techniques; empty: no maps
  std::string why;   // when there are none: why
  int width = 0, height = 0, block = 1;
  std::vector<float> best_weight;  // ceil(width / block) x ceil(height / block)
  std::vector<float> share_a;      // width x height
  std::uint64_t paths = 0;
};
// The best-weight view's scale: diverging about 0.5, 0 (all b) blue, 1 (all a) red.
ColourScale best_weight_scale(const WeightMaps& maps);
// The technique-share view's: sequential, 0 (all found by b) to 1 (all by a).
ColourScale technique_share_scale(const WeightMaps& maps);

// The guiding-tree view's data (the viewer makes it from the session's
// distribution): per pixel the S-tree leaf of the surface it sees
// (guiding_leaf_map; -1: none).
struct GuidingLeafMap {
  int width = 0, height = 0;
  std::vector<std::int32_t> leaf;
  int leaves = 0;     // in the whole tree
  int on_screen = 0;  // distinct leaves in `leaf`
  int pass = 0;       // the training passes it has learned from
};

bool build_view_layer(ViewMode mode, const PublishedImage& image, const ReferenceImage* reference, ViewLayer& out,
                      std::string& why, const LayerOptions* options = nullptr,  // null: the mode's defaults
                      const WeightMaps* maps = nullptr, const GuidingLeafMap* leaves = nullptr);

}  // namespace pdflab::ui
