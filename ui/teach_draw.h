#pragma once
// Small plotting and colour helpers for the teaching views, drawn with ImGui's
// draw list (ImPlot is not packaged on Debian). The axis and tick maths is
// plain code so it can be tested without an ImGui context.
#include "renderer/metrics/ticks.h"

#include <imgui.h>

#include <array>
#include <string>
#include <vector>

namespace pdflab::ui::draw {

// Begins a lab's window (the 1D and 2D labs): at the top left, `fonts_wide`
// by `fonts_high` font sizes within the display, set when it opens and
// whenever the display or the UI scale changes (`sized_for` remembers the
// display's size and font size it was last set for). False: collapsed, and
// the window already ended.
bool begin_lab_window(const char* title, bool* open, std::array<float, 3>& sized_for, float fonts_wide,
                      float fonts_high);

// A data range mapped onto 0..1, linearly or by log10 (log axes clamp values
// at or below zero to the low end instead of producing NaN).
struct Axis {
  double lo = 0.0, hi = 1.0;
  bool log = false;
  double to_unit(double v) const;
};

// Ticks and their labels: the one rule of every plot (renderer/metrics/ticks.h).
using pdflab::decade_ticks;
using pdflab::nice_ticks;
using pdflab::tick_label;
// A range that contains every finite value of `values` (and `extra`), widened
// a little so curves do not touch the frame; positive-only for log axes.
Axis fit_axis(const std::vector<double>& values, bool log, double pad = 0.05);

// Colour map for densities: dark blue through magenta and orange to pale
// yellow, rising in brightness so it still reads in grey. t is clamped to 0..1.
ImU32 colormap(float t);
// One colour per sampling technique (Technique index); -1 (no direction) grey.
ImU32 technique_colour(int technique);

// A plot frame placed at the cursor; ImGui::Dummy reserves its space.
class Plot {
 public:
  Plot(const char* title, ImVec2 size, Axis x, Axis y, const char* x_label = nullptr);
  ~Plot();
  Plot(const Plot&) = delete;
  Plot& operator=(const Plot&) = delete;

  ImVec2 at(double x, double y) const;
  const Axis& x() const { return x_; }
  const Axis& y() const { return y_; }
  ImDrawList* list() const { return list_; }

  void line(const std::vector<double>& xs, const std::vector<double>& ys, ImU32 colour, float thickness = 1.6f) const;
  // Filled band between lo and hi along xs (a confidence band).
  void band(const std::vector<double>& xs, const std::vector<double>& lo, const std::vector<double>& hi,
            ImU32 colour) const;
  // Bars of equal width starting at x0.
  void bars(double x0, double width, const std::vector<double>& heights, ImU32 fill) const;
  void hline(double y, ImU32 colour, bool dashed = true) const;
  // Legend rows in the top-right (or top-left) corner.
  void legend(const std::vector<std::pair<std::string, ImU32>>& entries, bool left = false) const;

 private:
  ImDrawList* list_ = nullptr;
  ImVec2 min_{}, max_{};  // the data area
  Axis x_, y_;
};

// A vertical colour bar with its range as labels, `size` from the cursor.
void colour_bar(ImVec2 size, double lo, double hi, bool log, const char* label);

}  // namespace pdflab::ui::draw
