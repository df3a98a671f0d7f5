#pragma once
// Colour maps of the false-colour views and their scales and legends.
#include "renderer/metrics/ticks.h"

#include <array>
#include <cstddef>
#include <string>
#include <vector>

namespace pdflab::ui {

// A logarithmic axis snapped to whole decades.
struct LogRange {
  double lo = 1.0, hi = 10.0;
  double position(double v) const;  // 0 at lo, 1 at hi
};
// Covers every positive finite value; one decade at least; [1, 10] when there is none.
LogRange log_range(const std::vector<double>& values);

using Colour = std::array<float, 3>;  // display RGB in 0..1
// Dark purple to pale yellow, monotonic in lightness so a grey print still orders it.
Colour sequential_colour(double t);  // t in 0..1
// Blue below zero, near-white at zero, red above.
Colour diverging_colour(double t);  // t in -1..1
// One colour per DropReason, and one for a pixel with several reasons.
Colour drop_reason_colour(int reason);
inline constexpr Colour kSeveralDropReasonsColour = {1.0f, 1.0f, 1.0f};
// A path guiding leaf's colour (the guiding-tree view, the probe's swatch):
// hues a golden angle apart, so neighbouring numbers differ.
Colour guiding_leaf_colour(int leaf);

// The value scale of a false-colour view and its legend.
struct ColourScale {
  bool logarithmic = false;
  bool diverging = false;  // symmetric: -hi..hi
  double lo = 0.0, hi = 1.0;
  double label_offset = 0.0;  // diverging: the legend labels v + label_offset (a scale about 0.5)
  std::string title;
  double position(double v) const;  // 0..1 along the colour bar
  Colour colour(double v) const;
};
struct LegendTick {
  double position = 0.0;  // 0..1 along the bar
  std::string label;
};
std::vector<LegendTick> legend_ticks(const ColourScale& scale);
// Which of the labels, centred at `centre` (pixels along the bar) with widths
// `width`, to draw so that none overlaps another: both ends always (clamped to
// the bar's [0, bar] span), the inner ones left to right while they keep `gap`
// from the last one drawn and from the end label. Returns their indices.
std::vector<std::size_t> labels_that_fit(const std::vector<float>& centre, const std::vector<float>& width, float bar,
                                         float gap);

// The heat map's scale: relative standard error, logarithmic, 0.001 to 10.
ColourScale relative_error_scale();
// The difference view's: symmetric about 0, up to `half_range`.
ColourScale difference_scale(double half_range);

}  // namespace pdflab::ui
