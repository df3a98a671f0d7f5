#pragma once
// The current view as a figure to hand in or put on a slide: a false-colour
// view (heat map, difference, dropped samples, best weight, technique share)
// as a PNG with its colour bar, title and a caption; the predicted efficiency
// curve and the convergence plot as SVG (renderer/metrics/svg_plot) and CSV.
// No ImGui frame or window is needed: text is drawn from a font atlas of the
// figure's own, so tests make figures as the viewer does.
#include "ui/convergence.h"
#include "ui/error_layers.h"
#include "ui/settings.h"

#include <cstdint>
#include <ctime>
#include <string>
#include <vector>

namespace pdflab::ui {

// Text under a figure: what it shows and how it was made.
struct FigureCaption {
  std::string title;               // the view, e.g. "relative standard error per pixel (log)"
  std::vector<std::string> lines;  // scene, strategy, spp and time, the figures measured
};

// A PNG of `layer` (nearest-neighbour, enlarged to be at least `min_width`
// pixels wide) with the view's legend beneath: its colour bar and tick labels
// (the drop colours with their counts for the drops view), the scale's title
// and the caption, on white. Its size: see view_figure_size.
std::vector<std::uint8_t> view_figure_png(ViewMode mode, const ViewLayer& layer, const FigureCaption& caption,
                                          int min_width = 480);
// The RGB pixels of the same figure (for tests), width and height set.
std::vector<std::uint8_t> view_figure_rgb(ViewMode mode, const ViewLayer& layer, const FigureCaption& caption,
                                          int min_width, int& width, int& height);
// The factor the image is enlarged by, and where it lies in the figure.
struct FigureGeometry {
  int scale = 1;
  int image_x = 0, image_y = 0;  // top left of the image
  int width = 0, height = 0;     // of the whole figure
};
FigureGeometry view_figure_geometry(ViewMode mode, const ViewLayer& layer, const FigureCaption& caption,
                                    int min_width);

// The predicted efficiency against w: one row per grid weight.
std::string weight_curve_csv(const WeightCurveStatus& curve);
std::string weight_curve_svg(const WeightCurveStatus& curve, const std::string& a, const std::string& b,
                             const std::string& title);
// Every curve of the convergence plot (pins first, then the running one):
// one row per point.
std::string convergence_csv(const ConvergenceRecorder& curves);
std::string convergence_svg(const ConvergenceRecorder& curves, bool against_spp, const std::string& title);

// Writes the files of one figure into `folder` (created if missing) as
// pdflab-YYYYMMDD-HHMMSS-N-KIND.EXT with the smallest N free for all of them,
// each to a temporary name and renamed. Returns their paths in the order given.
// Throws IoError (InputError for an empty folder); nothing is left behind on failure.
struct FigureFile {
  std::string extension;  // "png", "svg", "csv"
  std::vector<std::uint8_t> bytes;
};
std::vector<std::string> save_figure_files(const std::string& folder, const std::string& kind,
                                           const std::vector<FigureFile>& files, std::time_t when);

}  // namespace pdflab::ui
