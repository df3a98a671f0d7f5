#include "ui/measure_panel.h"
#include "ui/style.h"

#include "renderer/integrator/integrator.h"
#include "renderer/metrics/metrics.h"

#include <imgui.h>
#include <imgui_stdlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

namespace pdflab::ui {

namespace {


// Pinned curves take these in turn; the running one is drawn in white on top.
constexpr ImU32 kPinColours[] = {IM_COL32(90, 170, 255, 255),  IM_COL32(255, 140, 60, 255),
                                 IM_COL32(110, 210, 110, 255), IM_COL32(230, 90, 200, 255),
                                 IM_COL32(240, 220, 80, 255),  IM_COL32(150, 120, 255, 255)};
constexpr ImU32 kLiveColour = IM_COL32(255, 255, 255, 255);

ImU32 to_u32(const Colour& c, float alpha = 1.0f) { return ImGui::ColorConvertFloat4ToU32(ImVec4(c[0], c[1], c[2], alpha)); }

void figure_row(const char* label, const char* tooltip, const char* fmt, double value) {
  ImGui::TableNextColumn();
  ImGui::TextColored(kDim, "%s", label);
  if (tooltip && ImGui::IsItemHovered()) ImGui::SetTooltip("%s", tooltip);
  ImGui::TableNextColumn();
  ImGui::Text(fmt, value);
}

void text_row(const char* label, const char* tooltip, const std::string& value, const ImVec4* colour = nullptr) {
  ImGui::TableNextColumn();
  ImGui::TextColored(kDim, "%s", label);
  if (tooltip && ImGui::IsItemHovered()) ImGui::SetTooltip("%s", tooltip);
  ImGui::TableNextColumn();
  if (colour) ImGui::TextColored(*colour, "%s", value.c_str());
  else ImGui::TextUnformatted(value.c_str());
}

std::string printed(const char* fmt, double a, double b = 0.0) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, a, b);
  return buf;
}

// "Make reference": the button and its settings, or the running build's progress.
void make_reference_controls(MeasureSettings& ms, const MeasureState& m, const UiStatus& status,
                             UiRequests& requests) {
  const ReferenceBuildStatus& b = m.build;
  if (b.running) {
    char overlay[96];
    if (b.finishing) std::snprintf(overlay, sizeof overlay, "storing...");
    else std::snprintf(overlay, sizeof overlay, "%d%%  ~%.0f s left  %u spp", static_cast<int>(b.fraction * 100.0),
                       b.seconds_left, b.spp);
    ImGui::ProgressBar(static_cast<float>(b.fraction), ImVec2(-1.0f, 0.0f), overlay);
    ImGui::TextColored(kDim, "Making a reference: %dx%d on %d threads", b.width, b.height, b.threads);
    ImGui::SameLine();
    if (ImGui::SmallButton("Cancel##reference")) requests.measure.cancel_reference = true;
    return;
  }
  if (ImGui::Button("Make reference")) requests.measure.make_reference = true;
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("Renders a reference in the background (unbiased, seeds no render uses) and stores it in\n"
                      "the reference cache; then every figure is measured against it.");
  ImGui::SameLine();
  const int w = status.width, h = status.height;
  char sizes[3][48];
  for (int i = 0; i < 3; ++i)
    std::snprintf(sizes[i], sizeof sizes[i], "%dx%d%s", std::max(1, w >> i), std::max(1, h >> i),
                  i == 0 ? " (this size)" : "");
  int choice = ms.make_divisor >= 4 ? 2 : (ms.make_divisor >= 2 ? 1 : 0);
  ImGui::SetNextItemWidth(ImGui::GetContentRegionAvail().x);
  if (ImGui::BeginCombo("##make size", sizes[choice])) {
    for (int i = 0; i < 3; ++i)
      if (ImGui::Selectable(sizes[i], choice == i)) choice = i;
    ImGui::EndCombo();
  }
  ms.make_divisor = 1 << choice;
  ImGui::SetNextItemWidth(ImGui::GetContentRegionAvail().x * 0.5f);
  ImGui::SliderFloat("##make seconds", &ms.make_seconds, 5.0f, 600.0f, "%.0f s", ImGuiSliderFlags_Logarithmic);
  ImGui::SameLine();
  ImGui::SetNextItemWidth(ImGui::GetContentRegionAvail().x);
  float percent = ms.make_thread_share * 100.0f;
  ImGui::SliderFloat("##make threads", &percent, 10.0f, 100.0f, "%.0f%% of threads");
  ms.make_thread_share = std::clamp(percent / 100.0f, 0.1f, 1.0f);
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("At 100%% the main render pauses until the reference is done.");
}

void draw_colour_bar(const ColourScale& scale, float width) {
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const float bar_h = ImGui::GetFontSize() * 0.9f;
  const ImVec2 p0 = ImGui::GetCursorScreenPos();
  constexpr int kSegments = 48;
  for (int i = 0; i < kSegments; ++i) {
    const double t0 = static_cast<double>(i) / kSegments, t1 = static_cast<double>(i + 1) / kSegments;
    const auto at = [&](double t) { return scale.diverging ? diverging_colour(2.0 * t - 1.0) : sequential_colour(t); };
    const float x0 = p0.x + width * static_cast<float>(t0), x1 = p0.x + width * static_cast<float>(t1);
    dl->AddRectFilledMultiColor(ImVec2(x0, p0.y), ImVec2(x1, p0.y + bar_h), to_u32(at(t0)), to_u32(at(t1)),
                                to_u32(at(t1)), to_u32(at(t0)));
  }
  dl->AddRect(p0, ImVec2(p0.x + width, p0.y + bar_h), IM_COL32(200, 200, 200, 160));
  const float label_y = p0.y + bar_h + 3.0f;
  const std::vector<LegendTick> ticks = legend_ticks(scale);
  std::vector<float> centre, text_width;
  for (const LegendTick& t : ticks) {
    const float x = width * static_cast<float>(t.position);
    dl->AddLine(ImVec2(p0.x + x, p0.y + bar_h - 3.0f), ImVec2(p0.x + x, p0.y + bar_h + 2.0f), IM_COL32(230, 230, 230, 255));
    centre.push_back(x);
    text_width.push_back(ImGui::CalcTextSize(t.label.c_str()).x);
  }
  // On a narrow bar the inner labels that would run into each other are left out.
  for (const std::size_t i : labels_that_fit(centre, text_width, width, ImGui::GetFontSize() * 0.4f)) {
    const float tx = std::clamp(centre[i] - text_width[i] * 0.5f, 0.0f, std::max(0.0f, width - text_width[i]));
    dl->AddText(ImVec2(p0.x + tx, label_y), IM_COL32(230, 230, 230, 255), ticks[i].label.c_str());
  }
  ImGui::Dummy(ImVec2(width, bar_h + 3.0f + ImGui::GetFontSize()));
}

void draw_legend_window(const ImageRect& area, const ViewerSettings& settings, const MeasureState& m,
                        ImVec2 badges) {
  const ViewMode mode = settings.measure.view_mode;
  // Narrower than the area, so the window never pokes out of its left edge.
  const float width = std::min(area.width - 40.0f, ImGui::GetFontSize() * 18.0f);
  if (width < 80.0f) return;
  // Top right of the image area; below the badges at its top left when the
  // two would overlap.
  const float right = area.x + area.width - 8.0f;
  const float left = right - width - 2.0f * ImGui::GetStyle().WindowPadding.x;
  const float top = badges.y > 0.0f && left < badges.x + 4.0f ? badges.y + 4.0f : area.y + 8.0f;
  ImGui::SetNextWindowPos(ImVec2(right, top), ImGuiCond_Always, ImVec2(1.0f, 0.0f));
  ImGui::SetNextWindowBgAlpha(0.8f);
  const ImGuiWindowFlags flags = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize |
                                 ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoFocusOnAppearing |
                                 ImGuiWindowFlags_NoNav | ImGuiWindowFlags_NoInputs;
  if (ImGui::Begin("##view legend", nullptr, flags)) {
    ImGui::PushTextWrapPos(ImGui::GetCursorPosX() + width);
    ImGui::TextColored(kAmber, "View: %s (V)", view_mode_label(mode));
    if (!m.layer_ok) {
      ImGui::TextColored(kDim, "Showing the image: %s.", m.layer_why.empty() ? "nothing to show" : m.layer_why.c_str());
    } else if (mode == ViewMode::Drops) {
      const char* names[] = {"pdf zero or negative", "pdf NaN or infinite", "radiance not finite", "several reasons"};
      std::uint64_t total = 0;
      for (int r = 0; r <= kDropReasonCount; ++r) {
        const ImVec2 p = ImGui::GetCursorScreenPos();
        const float s = ImGui::GetFontSize();
        ImGui::GetWindowDrawList()->AddRectFilled(ImVec2(p.x, p.y + 2.0f), ImVec2(p.x + s - 4.0f, p.y + s - 2.0f),
                                                  to_u32(drop_reason_colour(r)));
        ImGui::Dummy(ImVec2(s, s));
        ImGui::SameLine();
        const std::uint64_t n = m.layer.drop_pixels[static_cast<std::size_t>(r)];
        total += n;
        ImGui::Text("%s: %llu px", names[r], static_cast<unsigned long long>(n));
      }
      ImGui::TextColored(kDim, total == 0 ? "No pixel dropped a sample." : "Other pixels are dimmed.");
    } else {
      const LayerOptions& o = m.layer_options;
      ImGui::TextColored(kDim, "%s", m.layer.scale.title.c_str());
      draw_colour_bar(m.layer.scale, width);
      if (mode == ViewMode::BestWeight)
        ImGui::TextColored(kDim,
                           "Per %dx%d block, the weight of least predicted second moment (relative to the pixel, as "
                           "relMSE weighs it), from %llu paths traced for the prediction. Red wants %s, blue %s; grey: w does not "
                           "matter there.",
                           m.weight_maps.block, m.weight_maps.block,
                           static_cast<unsigned long long>(m.weight_maps.paths), m.weight_maps.a.c_str(),
                           m.weight_maps.b.c_str());
      else if (mode == ViewMode::TechniqueShare)
        ImGui::TextColored(kDim,
                           "Per %dx%d block, the share of the estimate whose light-reaching direction %s drew "
                           "(each path split by the techniques' parts of the mixture pdf there). Bright: %s found "
                           "it; dark: %s; grey: no light found yet, or lights seen directly.",
                           m.weight_maps.block, m.weight_maps.block, m.weight_maps.a.c_str(),
                           m.weight_maps.a.c_str(), m.weight_maps.b.c_str());
      else
        ImGui::TextColored(kDim, "%s", o.range.automatic ? "range: auto (1st to 99th percentile)" : "range: as set in the panel");
      if (mode == ViewMode::RelativeError && o.metric == ErrorMetric::Relative)
        ImGui::TextColored(kDim, "mean %.4f; per pixel: standard error of the mean / mean", m.figures.mean_relative_standard_error);
      else if (mode == ViewMode::Difference && o.metric == ErrorMetric::Signed)
        ImGui::TextColored(kDim, "blue: darker than the reference, red: brighter");
    }
    ImGui::PopTextWrapPos();
  }
  ImGui::End();
}

void draw_plot(const ViewerSettings& settings, const MeasureState& m, ImVec2 size) {
  const ConvergenceRecorder& rec = m.curves;
  const bool by_spp = settings.measure.plot_against_spp;
  const auto x_of = [&](const CurvePoint& p) { return by_spp ? p.spp : p.seconds; };

  std::vector<const Curve*> curves;
  for (const Curve& c : rec.pins()) curves.push_back(&c);
  curves.push_back(&rec.live());
  std::vector<double> xs, ys;
  for (const Curve* c : curves)
    for (const CurvePoint& p : c->points) {
      xs.push_back(x_of(p));
      ys.push_back(p.error);
    }
  // The 1/sqrt(N) guide through the running curve's first point (or the last pin's).
  const Curve* anchor_curve = !rec.live().points.empty() ? &rec.live() : (rec.pins().empty() ? nullptr : &rec.pins().back());
  const LogRange xr = log_range(xs);
  const LogRange yr = log_range(ys);

  ImDrawList* dl = ImGui::GetWindowDrawList();
  const ImVec2 origin = ImGui::GetCursorScreenPos();
  const float font = ImGui::GetFontSize();
  const float left = font * 3.2f, bottom = font * 2.4f, top = font * 0.5f, right = font * 0.8f;
  const ImVec2 a(origin.x + left, origin.y + top);
  const ImVec2 b(origin.x + size.x - right, origin.y + size.y - bottom);
  ImGui::Dummy(size);
  if (b.x - a.x < 40.0f || b.y - a.y < 40.0f) return;
  dl->AddRectFilled(a, b, IM_COL32(20, 20, 24, 255));
  const auto px = [&](double x) { return a.x + (b.x - a.x) * static_cast<float>(xr.position(x)); };
  const auto py = [&](double y) { return b.y - (b.y - a.y) * static_cast<float>(yr.position(y)); };

  dl->PushClipRect(ImVec2(a.x - 1.0f, a.y - 1.0f), ImVec2(b.x + 1.0f, b.y + 1.0f), true);
  for (double t : decade_ticks(xr.lo, xr.hi)) dl->AddLine(ImVec2(px(t), a.y), ImVec2(px(t), b.y), IM_COL32(70, 70, 80, 255));
  for (double t : decade_ticks(yr.lo, yr.hi)) dl->AddLine(ImVec2(a.x, py(t)), ImVec2(b.x, py(t)), IM_COL32(70, 70, 80, 255));
  if (anchor_curve && !anchor_curve->points.empty() && !xs.empty()) {
    const CurvePoint& p0 = anchor_curve->points.front();
    const double x0 = x_of(p0);
    // Dashed, so it never reads as a measured curve.
    constexpr int kDashes = 40;
    const double l0 = std::log10(xr.lo), l1 = std::log10(xr.hi);
    for (int i = 0; i < kDashes; i += 2) {
      const double xa = std::pow(10.0, l0 + (l1 - l0) * i / kDashes);
      const double xb = std::pow(10.0, l0 + (l1 - l0) * (i + 1) / kDashes);
      dl->AddLine(ImVec2(px(xa), py(p0.error * std::sqrt(x0 / xa))), ImVec2(px(xb), py(p0.error * std::sqrt(x0 / xb))),
                  IM_COL32(170, 170, 170, 200), 1.0f);
    }
  }
  for (std::size_t i = 0; i < curves.size(); ++i) {
    const Curve& c = *curves[i];
    const bool live = i + 1 == curves.size();
    const ImU32 colour = live ? kLiveColour : kPinColours[i % std::size(kPinColours)];
    std::vector<ImVec2> pts;
    for (const CurvePoint& p : c.points) pts.emplace_back(px(x_of(p)), py(p.error));
    if (pts.size() >= 2) dl->AddPolyline(pts.data(), static_cast<int>(pts.size()), colour, 0, live ? 2.0f : 1.6f);
    if (!pts.empty()) dl->AddCircleFilled(pts.back(), live ? 3.5f : 2.5f, colour);
  }
  dl->PopClipRect();
  dl->AddRect(a, b, IM_COL32(140, 140, 150, 255));

  const ImU32 text = IM_COL32(215, 215, 220, 255);
  for (double t : decade_ticks(xr.lo, xr.hi)) {
    const std::string s = tick_label(t);
    const float w = ImGui::CalcTextSize(s.c_str()).x;
    dl->AddText(ImVec2(std::clamp(px(t) - w * 0.5f, a.x - left * 0.5f, b.x - w), b.y + 2.0f), text, s.c_str());
  }
  for (double t : decade_ticks(yr.lo, yr.hi)) {
    const std::string s = tick_label(t);
    const float w = ImGui::CalcTextSize(s.c_str()).x;
    dl->AddText(ImVec2(a.x - w - 4.0f, std::clamp(py(t) - font * 0.5f, a.y - font * 0.5f, b.y - font)), text, s.c_str());
  }
  const char* xlabel = by_spp ? "samples per pixel" : "rendering time (s)";
  dl->AddText(ImVec2((a.x + b.x - ImGui::CalcTextSize(xlabel).x) * 0.5f, b.y + font * 1.25f), text, xlabel);

  // Legend, top right inside the frame.
  const auto curve_name = [](const Curve& c, const char* prefix) {
    return prefix + (c.label.empty() ? std::string("-") : c.label) + (c.estimated ? " (est.)" : "");
  };
  // Right-aligned on the longest entry, so a long mixture name stays inside the frame.
  float widest = ImGui::CalcTextSize("1/sqrt(N) slope").x;
  for (std::size_t i = 0; i < curves.size(); ++i)
    widest = std::max(widest, ImGui::CalcTextSize(curve_name(*curves[i], i + 1 < curves.size() ? "pin: " : "now: ").c_str()).x);
  float ly = a.y + 4.0f;
  const float lx = std::max(a.x + 4.0f, b.x - widest - font * 2.4f);
  const auto legend_line = [&](ImU32 colour, const std::string& label, bool dashed) {
    if (dashed) {
      for (float k = 0.0f; k < 3.0f; k += 1.0f)
        dl->AddLine(ImVec2(lx + k * font * 0.6f, ly + font * 0.5f),
                    ImVec2(lx + k * font * 0.6f + font * 0.35f, ly + font * 0.5f), colour, 1.0f);
    } else {
      dl->AddLine(ImVec2(lx, ly + font * 0.5f), ImVec2(lx + font * 1.6f, ly + font * 0.5f), colour, 2.0f);
    }
    dl->AddText(ImVec2(lx + font * 2.0f, ly), text, label.c_str());
    ly += font * 1.15f;
  };
  for (std::size_t i = 0; i + 1 < curves.size(); ++i)
    legend_line(kPinColours[i % std::size(kPinColours)], curve_name(*curves[i], "pin: "), false);
  if (!rec.live().points.empty()) legend_line(kLiveColour, curve_name(rec.live(), "now: "), false);
  if (anchor_curve) legend_line(IM_COL32(170, 170, 170, 220), "1/sqrt(N) slope", true);
}

void draw_convergence_window(const ImageRect& area, ViewerSettings& settings, const MeasureState& m,
                             UiRequests& requests) {
  const float font = ImGui::GetFontSize();
  const float w = std::min(area.width - 16.0f, font * 34.0f);
  const float h = std::min(area.height * 0.5f, font * 21.0f);
  if (w < font * 12.0f || h < font * 8.0f) return;
  ImGui::SetNextWindowPos(ImVec2(area.x + 8.0f, area.y + area.height - 8.0f), ImGuiCond_Always, ImVec2(0.0f, 1.0f));
  ImGui::SetNextWindowSize(ImVec2(w, h), ImGuiCond_Always);
  ImGui::SetNextWindowBgAlpha(0.88f);
  const ImGuiWindowFlags flags = ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoSavedSettings |
                                 ImGuiWindowFlags_NoFocusOnAppearing | ImGuiWindowFlags_NoScrollbar |
                                 ImGuiWindowFlags_NoCollapse;
  bool open = true;
  if (ImGui::Begin("Convergence (G)", &open, flags)) {
    const bool estimated = m.curves.live().estimated || !m.figures.against_reference;
    ImGui::TextColored(kDim, estimated ? "relative RMS error: ESTIMATE from the variance"
                                       : "relative RMS error sqrt(relMSE) vs the reference");
    ImGui::TextColored(kDim, "against");
    ImGui::SameLine();
    int axis = settings.measure.plot_against_spp ? 1 : 0;
    ImGui::RadioButton("time", &axis, 0);
    ImGui::SameLine();
    ImGui::RadioButton("spp", &axis, 1);
    settings.measure.plot_against_spp = axis == 1;
    const float buttons = ImGui::GetFrameHeightWithSpacing();
    draw_plot(settings, m, ImVec2(ImGui::GetContentRegionAvail().x, ImGui::GetContentRegionAvail().y - buttons));
    if (ImGui::SmallButton("Pin this curve (K)")) requests.measure.pin_curve = true;
    ImGui::SameLine();
    if (ImGui::SmallButton("Clear pins")) requests.measure.clear_pins = true;
    ImGui::SameLine();
    ImGui::TextColored(kDim, "%zu pinned", m.curves.pins().size());
  }
  ImGui::End();
  if (!open) settings.measure.show_plot = false;
}

}  // namespace

void draw_view_mode_selector(ViewerSettings& settings) {
  int mode = static_cast<int>(settings.measure.view_mode);
  if (ImGui::BeginCombo("View (V)", view_mode_label(settings.measure.view_mode))) {
    for (int i = 0; i < kViewModeCount; ++i)
      if (ImGui::Selectable(view_mode_label(static_cast<ViewMode>(i)), mode == i)) mode = i;
    ImGui::EndCombo();
  }
  settings.measure.view_mode = static_cast<ViewMode>(mode);
}

void draw_layer_controls(ViewerSettings& settings, const MeasureState* m) {
  const ViewMode mode = settings.measure.view_mode;
  if (mode != ViewMode::RelativeError && mode != ViewMode::Difference) return;
  LayerOptions& o = settings.measure.layer_options(mode);
  ImGui::Indent();
  const float label_room = ImGui::CalcTextSize("Metric (E)").x + ImGui::GetStyle().ItemInnerSpacing.x;
  ImGui::SetNextItemWidth(ImGui::GetContentRegionAvail().x - label_room);
  if (ImGui::BeginCombo("Metric (E)", error_metric_label(mode, o.metric))) {
    for (int i = 0; i < kErrorMetricCount; ++i) {
      const auto metric = static_cast<ErrorMetric>(i);
      if (!view_offers_metric(mode, metric)) continue;
      if (ImGui::Selectable(error_metric_label(mode, metric), o.metric == metric)) settings.measure.set_metric(metric);
    }
    ImGui::EndCombo();
  }
  const bool signed_metric = mode == ViewMode::Difference && o.metric == ErrorMetric::Signed;
  bool automatic = o.range.automatic;
  if (ImGui::Checkbox("auto range", &automatic)) {
    // Set by hand from where the automatic range was, so nothing jumps.
    if (!automatic && m && m->layer_ok && m->layer_mode == mode) {
      o.range.lo = m->layer.scale.diverging ? -m->layer.scale.hi : m->layer.scale.lo;
      o.range.hi = m->layer.scale.hi;
    }
    o.range.automatic = automatic;
  }
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("On: from the 1st to the 99th percentile of this image's values, rounded.\n"
                      "Off: fixed, so two strategies' maps compare. Ctrl+click a slider to type a value.");
  ImGui::BeginDisabled(automatic);
  const ImGuiSliderFlags log = ImGuiSliderFlags_Logarithmic | ImGuiSliderFlags_AlwaysClamp;
  // An automatic range shows where it is now (and is not stored: the next image moves it).
  const bool shown = automatic && m && m->layer_ok && m->layer_mode == mode;
  float lo = static_cast<float>(shown ? m->layer.scale.lo : o.range.lo);
  float hi = static_cast<float>(shown ? m->layer.scale.hi : o.range.hi);
  if (signed_metric) {
    ImGui::SetNextItemWidth(ImGui::GetContentRegionAvail().x * 0.6f);
    if (ImGui::SliderFloat("+- range", &hi, 1e-6f, 1e6f, "%.3g", log)) o.range.hi = hi;
  } else {
    const float half = (ImGui::GetContentRegionAvail().x - ImGui::GetStyle().ItemSpacing.x) * 0.5f;
    ImGui::SetNextItemWidth(half);
    if (ImGui::SliderFloat("##range lo", &lo, 1e-9f, 1e6f, "min %.3g", log)) o.range.lo = std::min(lo, hi * 0.999f);
    ImGui::SameLine();
    ImGui::SetNextItemWidth(half);
    if (ImGui::SliderFloat("##range hi", &hi, 1e-9f, 1e6f, "max %.3g", log)) o.range.hi = std::max(hi, lo * 1.001f);
  }
  ImGui::EndDisabled();
  o.range = sanitized(o.range, signed_metric);
  ImGui::Unindent();
}

void draw_measure_section(ViewerSettings& settings, const UiStatus& status, UiRequests& requests) {
  const MeasureState* m = status.measure;
  if (!m) return;
  MeasureSettings& ms = settings.measure;
  const ImGuiStyle& style = ImGui::GetStyle();
  ImGui::SetNextItemWidth(ImGui::GetContentRegionAvail().x - ImGui::CalcTextSize("Load").x -
                          style.FramePadding.x * 2.0f - style.ItemSpacing.x);
  const bool entered = ImGui::InputTextWithHint("##reference", "reference image (.pfm)", &ms.reference_field,
                                                ImGuiInputTextFlags_EnterReturnsTrue);
  ImGui::SameLine();
  if ((ImGui::Button("Load##reference") || entered) && !ms.reference_field.empty())
    requests.measure.load_reference = ms.reference_field;
  if (m->reference.loaded()) {
    const ReferenceInfo& ri = m->reference.info;
    ImGui::TextColored(kDim, "reference: %s, %dx%d",
                       m->reference_from_cache ? "from the cache"
                                               : std::filesystem::path(m->reference.path).filename().string().c_str(),
                       m->reference.width, m->reference.height);
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", m->reference.path.c_str());
    ImGui::SameLine();
    if (ImGui::SmallButton("Drop")) requests.measure.clear_reference = true;
    if (ri.spp > 0 || !ri.strategy.empty())
      ImGui::TextColored(kDim, "  %u spp, %s%s", ri.spp, ri.strategy.empty() ? "?" : ri.strategy.c_str(),
                         m->reference.has_variance() ? "" : ", no variance: its noise is not removed");
  } else {
    ImGui::TextColored(kDim, "No reference: errors below are estimates (lower bounds).");
  }
  if (!m->reference_note.empty()) {
    ImGui::PushStyleColor(ImGuiCol_Text, kGreen);
    ImGui::TextWrapped("%s", m->reference_note.c_str());
    ImGui::PopStyleColor();
  }
  if (!m->reference_error.empty()) {
    ImGui::PushStyleColor(ImGuiCol_Text, kRed);
    ImGui::TextWrapped("%s", m->reference_error.c_str());
    ImGui::PopStyleColor();
  }
  make_reference_controls(ms, *m, status, requests);
  const std::string mismatch = m->size_mismatch(status.width, status.height);
  if (!mismatch.empty()) {
    ImGui::PushStyleColor(ImGuiCol_Text, kAmber);
    ImGui::TextWrapped("%s", mismatch.c_str());
    ImGui::PopStyleColor();
    char label[64];
    std::snprintf(label, sizeof label, "Render at %dx%d", m->reference.width, m->reference.height);
    if (ImGui::Button(label)) requests.measure.render_at_reference_size = true;
  }

  const Figures& f = m->figures;
  if (!f.valid) {
    ImGui::TextColored(kDim, "Figures appear after the first full pass.");
  } else {
    ImGui::TextColored(f.against_reference ? kGreen : kAmber, f.against_reference
                                                                  ? "MEASURED against the reference"
                                                                  : "ESTIMATED from the film's own variance");
    if (ImGui::BeginTable("figures", 2, ImGuiTableFlags_SizingStretchProp)) {
      share_columns({0.56f, 0.44f});
      if (f.against_reference) {
        figure_row("RMSE", "root mean squared error against the reference, all pixels and channels", "%.5g", f.rmse);
        text_row("relMSE (eps 1e-2)",
                 "mean of ((x - r)^2 - var(r)) / (r^2 + 0.01): the error against the true image, the reference's own\n"
                 "noise removed, with its 95% interval (docs/measuring.md)",
                 printed("%.4g +- %.2g", f.relmse, f.relmse_interval));
        text_row("relMSE raw", "mean of (x - r)^2 / (r^2 + 0.01), the reference's noise included",
                 printed("%.4g", f.relmse_raw));
        const ImVec4 share_colour = f.reference_share > 0.2 ? kAmber : kDim;
        text_row("reference's share", "the reference's own noise as a part of the raw relMSE",
                 f.reference_corrected ? printed("%.1f%%", 100.0 * f.reference_share) : std::string("unknown"),
                 &share_colour);
        if (f.relmse > 0.0)
          figure_row("efficiency", "1 / (relMSE * seconds): higher is better, flat over time when unbiased", "%.5g",
                     f.efficiency);
        else
          text_row("efficiency", "relMSE is within the reference's noise of 0", "beyond the reference's precision");
      }
      figure_row("mean rel. std. error",
                 "the film's own noise: sqrt(variance of the mean) / mean, averaged over pixels", "%.5g",
                 f.mean_relative_standard_error);
      figure_row(f.against_reference ? "relMSE, estimated" : "relMSE ESTIMATE (lower bound)",
                 "variance of the mean / (mean^2 + 0.01): the expected relMSE of an unbiased strategy, at best.\n"
                 "Blind to what the samples never found (a biased strategy looks good here).",
                 "%.5g", f.estimated_relmse);
      if (f.unbiased)
        figure_row(f.against_reference ? "efficiency, estimated" : "efficiency ESTIMATE",
                   "1 / (estimated relMSE * seconds)", "%.5g", f.estimated_efficiency);
      else if (!f.against_reference)
        text_row("efficiency", nullptr, "none: biased strategy", &kRed);
      ImGui::EndTable();
    }
    if (!f.unbiased && !f.against_reference)
      ImGui::TextWrapped("No efficiency without a reference: this strategy never samples indirect light, so its own "
                         "variance hides the light it misses and would rank it best.");
    if (f.estimate_unreliable && !f.against_reference) {
      ImGui::PushStyleColor(ImGuiCol_Text, kAmber);
      ImGui::TextWrapped("The estimate is unreliable: it did not fall as the samples doubled (rare bright paths are "
                         "still being found). Make a reference to measure.");
      ImGui::PopStyleColor();
    }
    ImGui::TextColored(kDim, "at %u spp, %.2f s of rendering", f.spp, f.seconds);
  }
  ImGui::Checkbox("Convergence plot (G)", &ms.show_plot);
  ImGui::SameLine();
  if (ImGui::Button("Pin")) requests.measure.pin_curve = true;
  ImGui::SameLine();
  if (ImGui::Button("Clear pins")) requests.measure.clear_pins = true;
}

void draw_nee_explanation() {
  // Closed at first: the note is long, the panel is for controls.
  if (!ImGui::TreeNodeEx("why? (how nee-mis differs from a mixture)", ImGuiTreeNodeFlags_None)) return;
  ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(0.85f, 0.85f, 0.88f, 1.0f));
  ImGui::TextWrapped(
      "A mixture (mix:...) draws ONE direction per bounce: it picks a technique by its weight, samples it, and "
      "divides by the mixture's density sum w_i p_i. That is the balance heuristic of MIS in one-sample form.");
  ImGui::Spacing();
  ImGui::TextWrapped(
      "nee-mis takes TWO samples at every diffuse vertex: a light sample (an emitter chosen by power, sampled by "
      "solid angle) tested with a shadow ray, and a cosine sample that continues the path. Each is weighted "
      "against the OTHER technique's pdf for the same direction: power heuristic p_a^2 / (p_a^2 + p_b^2), or "
      "balance p_a / (p_a + p_b). Every path to a light is counted once in total.");
  ImGui::Spacing();
  ImGui::TextWrapped(
      "Unbiased: the cosine sample reaches every direction. Per sample, noise from small lights falls much "
      "faster; but a bounce costs a shadow ray more and paths, continued by cosine sampling alone, rarely end "
      "on a light, so per second it "
      "wins mainly where light comes straight from the lights (compare with the Convergence plot). It aims at "
      "emitters only, not at the glass sphere.");
  ImGui::PopStyleColor();
  ImGui::TreePop();
}

void draw_image_overlays(const ImageRect& image, const ImageRect& area, ViewerSettings& settings,
                         const MeasureState& measure, std::uint32_t texture, UiRequests& requests,
                         ImVec2 badges) {
  const ViewMode mode = settings.measure.view_mode;
  if (mode != ViewMode::Image) {
    if (measure.layer_ok && texture != 0 && image.width > 0.0f)
      ImGui::GetBackgroundDrawList()->AddImage(reinterpret_cast<ImTextureID>(static_cast<std::intptr_t>(texture)),
                                               ImVec2(image.x, image.y),
                                               ImVec2(image.x + image.width, image.y + image.height));
    draw_legend_window(area, settings, measure, badges);
  }
  if (settings.measure.show_plot) draw_convergence_window(area, settings, measure, requests);
}

}  // namespace pdflab::ui
