#pragma once
// A small log-log line plot as a standalone SVG document (convergence curves).
#include <limits>
#include <string>
#include <vector>

namespace pdflab {

struct PlotSeries {
  std::string label;
  std::vector<double> x, y;  // points with x <= 0 or y <= 0 are skipped (log axes)
  // Linear plots only: an error bar per point (empty: none), a dashed line;
  // a point whose x or y is not finite breaks the line there.
  std::vector<double> y_lo, y_hi;
  bool dashed = false;
};

struct PlotOptions {
  std::string title, x_label, y_label;
  // Draw a dashed guide of this log-log slope (e.g. -0.5 for error ~ 1/sqrt(N)); 0: none.
  double guide_slope = 0.0;
  std::string guide_label;
  int width = 720, height = 480;
  // Linear plots only: a vertical marker at marker_x with a shaded band
  // [marker_lo, marker_hi] and its label; none when marker_x is NaN.
  double marker_x = std::numeric_limits<double>::quiet_NaN();
  double marker_lo = 0.0, marker_hi = 0.0;
  std::string marker_label;
  double x_min = 0.0, x_max = 1.0;  // linear x range
};

std::string loglog_svg(const std::vector<PlotSeries>& series, const PlotOptions& options);
// Linear axes: x over [x_min, x_max], y from 0 to the largest value (error bars included).
std::string linear_svg(const std::vector<PlotSeries>& series, const PlotOptions& options);

}  // namespace pdflab
