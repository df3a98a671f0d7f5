#include "ui/teach_draw.h"

#include "renderer/sampling/strategy.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>

namespace pdflab::ui::draw {

bool begin_lab_window(const char* title, bool* open, std::array<float, 3>& sized_for, float fonts_wide,
                      float fonts_high) {
  const ImVec2 display = ImGui::GetIO().DisplaySize;
  const float font = ImGui::GetFontSize();
  const float w = std::max(300.0f, std::min(display.x - 20.0f, font * fonts_wide));
  const float h = std::max(300.0f, std::min(display.y - 20.0f, font * fonts_high));
  const bool resized = sized_for[0] != display.x || sized_for[1] != display.y || sized_for[2] != font;
  sized_for = {display.x, display.y, font};
  ImGui::SetNextWindowPos(ImVec2(10.0f, 10.0f), resized ? ImGuiCond_Always : ImGuiCond_Appearing);
  ImGui::SetNextWindowSize(ImVec2(w, h), resized ? ImGuiCond_Always : ImGuiCond_Appearing);
  ImGui::SetNextWindowBgAlpha(0.97f);
  if (!ImGui::Begin(title, open, ImGuiWindowFlags_NoSavedSettings)) {
    ImGui::End();
    return false;
  }
  return true;
}

double Axis::to_unit(double v) const {
  if (log) {
    const double a = std::log10(std::max(lo, 1e-300));
    const double b = std::log10(std::max(hi, 1e-300));
    const double lv = v > 0.0 ? std::log10(v) : a;
    return b > a ? (lv - a) / (b - a) : 0.5;
  }
  return hi != lo ? (v - lo) / (hi - lo) : 0.5;  // hi < lo: a reversed axis
}

Axis fit_axis(const std::vector<double>& values, bool log, double pad) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (double v : values) {
    if (!std::isfinite(v) || (log && !(v > 0.0))) continue;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  if (!(hi >= lo)) return log ? Axis{0.1, 10.0, true} : Axis{0.0, 1.0, false};
  if (log) {
    const double a = std::log10(lo), b = std::log10(hi);
    const double span = std::max(b - a, 0.5);
    return {std::pow(10.0, a - span * pad), std::pow(10.0, b + span * pad), true};
  }
  const double span = hi > lo ? hi - lo : std::max(std::abs(hi), 1.0);
  return {lo - span * pad, hi + span * pad, false};
}

ImU32 colormap(float t) {
  // Anchors chosen by hand: brightness rises monotonically from one to the next.
  static constexpr std::array<std::array<float, 3>, 6> kStops = {{
      {0.02f, 0.02f, 0.10f},
      {0.20f, 0.10f, 0.45f},
      {0.55f, 0.15f, 0.55f},
      {0.88f, 0.32f, 0.35f},
      {0.99f, 0.64f, 0.22f},
      {0.99f, 0.97f, 0.72f},
  }};
  if (!std::isfinite(t)) t = 0.0f;
  t = std::clamp(t, 0.0f, 1.0f) * static_cast<float>(kStops.size() - 1);
  const int i = std::min(static_cast<int>(t), static_cast<int>(kStops.size()) - 2);
  const float f = t - static_cast<float>(i);
  const auto& a = kStops[static_cast<std::size_t>(i)];
  const auto& b = kStops[static_cast<std::size_t>(i) + 1];
  return ImGui::ColorConvertFloat4ToU32(
      ImVec4(a[0] + (b[0] - a[0]) * f, a[1] + (b[1] - a[1]) * f, a[2] + (b[2] - a[2]) * f, 1.0f));
}

ImU32 technique_colour(int technique) {
  if (technique < 0 || technique >= kTechniqueCount) return IM_COL32(150, 150, 150, 255);  // no direction
  const auto& c = technique_info(static_cast<Technique>(technique)).colour;
  return IM_COL32(c[0], c[1], c[2], 255);
}

namespace {

constexpr ImU32 kFrame = IM_COL32(110, 110, 120, 255);
constexpr ImU32 kGrid = IM_COL32(60, 60, 68, 255);
constexpr ImU32 kLabel = IM_COL32(175, 175, 185, 255);

std::vector<double> ticks_for(const Axis& a, int max_ticks) {
  if (!a.log) return nice_ticks(std::min(a.lo, a.hi), std::max(a.lo, a.hi), max_ticks);
  std::vector<double> t = decade_ticks(a.lo, a.hi);
  // Many decades: every other one, so labels do not collide.
  if (static_cast<int>(t.size()) > max_ticks) {
    std::vector<double> thin;
    for (std::size_t i = 0; i < t.size(); i += 2) thin.push_back(t[i]);
    return thin;
  }
  return t;
}

}  // namespace

Plot::Plot(const char* title, ImVec2 size, Axis x, Axis y, const char* x_label) : x_(x), y_(y) {
  list_ = ImGui::GetWindowDrawList();
  const ImVec2 origin = ImGui::GetCursorScreenPos();
  const float line = ImGui::GetTextLineHeight();
  const float top = origin.y + line + 4.0f;
  const float bottom = origin.y + size.y - line * (x_label ? 2.0f : 1.0f) - 6.0f;
  // The margin fits the widest y label.
  const int max_y_ticks = std::max(2, static_cast<int>((bottom - top) / (line * 1.6f)));
  const std::vector<double> y_ticks = ticks_for(y_, max_y_ticks);
  float left = ImGui::CalcTextSize("0").x;
  for (double t : y_ticks) left = std::max(left, ImGui::CalcTextSize(tick_label(t).c_str()).x);
  min_ = ImVec2(origin.x + left + 6.0f, top);
  max_ = ImVec2(origin.x + size.x - 6.0f, bottom);
  ImGui::Dummy(size);

  list_->AddText(ImVec2(min_.x, origin.y), kLabel, title);
  list_->AddRectFilled(min_, max_, IM_COL32(22, 22, 28, 255));
  const int max_ticks = std::max(2, static_cast<int>((max_.x - min_.x) / 55.0f));
  for (double t : ticks_for(x_, max_ticks)) {
    const float px = at(t, y_.lo).x;
    list_->AddLine(ImVec2(px, min_.y), ImVec2(px, max_.y), kGrid);
    const std::string s = tick_label(t);
    const float w = ImGui::CalcTextSize(s.c_str()).x;
    list_->AddText(ImVec2(px - w * 0.5f, max_.y + 2.0f), kLabel, s.c_str());
  }
  for (double t : y_ticks) {
    const float py = at(x_.lo, t).y;
    list_->AddLine(ImVec2(min_.x, py), ImVec2(max_.x, py), kGrid);
    const std::string s = tick_label(t);
    const float w = ImGui::CalcTextSize(s.c_str()).x;
    list_->AddText(ImVec2(min_.x - w - 3.0f, py - line * 0.5f), kLabel, s.c_str());
  }
  if (x_label) {
    const float w = ImGui::CalcTextSize(x_label).x;
    list_->AddText(ImVec2((min_.x + max_.x - w) * 0.5f, max_.y + line + 3.0f), kLabel, x_label);
  }
  list_->AddRect(min_, max_, kFrame);
  list_->PushClipRect(min_, max_, true);
}

Plot::~Plot() { list_->PopClipRect(); }

ImVec2 Plot::at(double x, double y) const {
  const double ux = x_.to_unit(x), uy = y_.to_unit(y);
  return ImVec2(min_.x + static_cast<float>(ux) * (max_.x - min_.x), max_.y - static_cast<float>(uy) * (max_.y - min_.y));
}

void Plot::line(const std::vector<double>& xs, const std::vector<double>& ys, ImU32 colour, float thickness) const {
  const std::size_t n = std::min(xs.size(), ys.size());
  std::vector<ImVec2> points;
  points.reserve(n);
  const auto flush = [&] {
    if (points.size() >= 2) list_->AddPolyline(points.data(), static_cast<int>(points.size()), colour, 0, thickness);
    points.clear();
  };
  for (std::size_t i = 0; i < n; ++i) {
    // A gap (NaN, or zero on a log axis) breaks the curve instead of diving to the edge.
    if (!std::isfinite(ys[i]) || (y_.log && !(ys[i] > 0.0))) {
      flush();
      continue;
    }
    points.push_back(at(xs[i], ys[i]));
  }
  flush();
}

void Plot::band(const std::vector<double>& xs, const std::vector<double>& lo, const std::vector<double>& hi,
                ImU32 colour) const {
  const std::size_t n = std::min({xs.size(), lo.size(), hi.size()});
  for (std::size_t i = 0; i + 1 < n; ++i) {
    if (!std::isfinite(lo[i]) || !std::isfinite(hi[i]) || !std::isfinite(lo[i + 1]) || !std::isfinite(hi[i + 1]))
      continue;
    list_->AddQuadFilled(at(xs[i], lo[i]), at(xs[i], hi[i]), at(xs[i + 1], hi[i + 1]), at(xs[i + 1], lo[i + 1]),
                         colour);
  }
}

void Plot::bars(double x0, double width, const std::vector<double>& heights, ImU32 fill) const {
  for (std::size_t i = 0; i < heights.size(); ++i) {
    if (!(heights[i] > 0.0)) continue;
    const double a = x0 + width * static_cast<double>(i);
    ImVec2 p0 = at(a, heights[i]), p1 = at(a + width, y_.log ? y_.lo : 0.0);
    p0.x += 0.5f;  // a hairline gap between bars
    list_->AddRectFilled(p0, p1, fill);
  }
}

void Plot::hline(double y, ImU32 colour, bool dashed) const {
  const float py = at(x_.lo, y).y;
  if (!dashed) {
    list_->AddLine(ImVec2(min_.x, py), ImVec2(max_.x, py), colour, 1.5f);
    return;
  }
  for (float x = min_.x; x < max_.x; x += 10.0f)
    list_->AddLine(ImVec2(x, py), ImVec2(std::min(x + 6.0f, max_.x), py), colour, 1.5f);
}

void Plot::legend(const std::vector<std::pair<std::string, ImU32>>& entries, bool left) const {
  const float line = ImGui::GetTextLineHeight();
  float width = 0.0f;
  for (const auto& e : entries) width = std::max(width, ImGui::CalcTextSize(e.first.c_str()).x);
  const float box_w = width + line + 14.0f;
  const ImVec2 p0(left ? min_.x + 6.0f : max_.x - box_w - 6.0f, min_.y + 6.0f);
  list_->AddRectFilled(p0, ImVec2(p0.x + box_w, p0.y + line * static_cast<float>(entries.size()) + 6.0f),
                       IM_COL32(15, 15, 20, 215));
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const float y = p0.y + 3.0f + line * static_cast<float>(i);
    list_->AddRectFilled(ImVec2(p0.x + 5.0f, y + line * 0.3f), ImVec2(p0.x + 5.0f + line * 0.7f, y + line * 0.7f),
                         entries[i].second);
    list_->AddText(ImVec2(p0.x + line + 9.0f, y), IM_COL32(225, 225, 230, 255), entries[i].first.c_str());
  }
}

void colour_bar(ImVec2 size, double lo, double hi, bool log, const char* label) {
  ImDrawList* list = ImGui::GetWindowDrawList();
  const ImVec2 origin = ImGui::GetCursorScreenPos();
  const float line = ImGui::GetTextLineHeight();
  const float bar_w = std::min(14.0f, size.x * 0.3f);
  const float top = origin.y + line + 2.0f, bottom = origin.y + size.y - line - 2.0f;
  ImGui::Dummy(size);
  list->AddText(origin, IM_COL32(175, 175, 185, 255), label);
  const int steps = 48;
  for (int i = 0; i < steps; ++i) {
    const float y0 = bottom - (bottom - top) * static_cast<float>(i + 1) / steps;
    const float y1 = bottom - (bottom - top) * static_cast<float>(i) / steps;
    list->AddRectFilled(ImVec2(origin.x, y0), ImVec2(origin.x + bar_w, y1 + 0.5f),
                        colormap((static_cast<float>(i) + 0.5f) / steps));
  }
  list->AddRect(ImVec2(origin.x, top), ImVec2(origin.x + bar_w, bottom), kFrame);
  const std::string hi_s = tick_label(hi), lo_s = tick_label(lo);
  list->AddText(ImVec2(origin.x + bar_w + 4.0f, top - line * 0.5f), kLabel, hi_s.c_str());
  list->AddText(ImVec2(origin.x + bar_w + 4.0f, bottom - line * 0.5f), kLabel, lo_s.c_str());
  if (log) list->AddText(ImVec2(origin.x + bar_w + 4.0f, (top + bottom) * 0.5f - line * 0.5f), kLabel, "log");
}

}  // namespace pdflab::ui::draw
