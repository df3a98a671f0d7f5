#pragma once
// A small log-log line plot as a standalone SVG document (convergence curves).
#include <string>
#include <vector>

namespace pdflab {

struct PlotSeries {
  std::string label;
  std::vector<double> x, y;  // points with x <= 0 or y <= 0 are skipped (log axes)
};

struct PlotOptions {
  std::string title, x_label, y_label;
  // Draw a dashed guide of this log-log slope (e.g. -0.5 for error ~ 1/sqrt(N)); 0: none.
  double guide_slope = 0.0;
  std::string guide_label;
  int width = 720, height = 480;
};

std::string loglog_svg(const std::vector<PlotSeries>& series, const PlotOptions& options);

}  // namespace pdflab
