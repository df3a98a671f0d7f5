#include "ui/measure_panel.h"
#include "ui/style.h"

#include "renderer/integrator/integrator.h"
#include "renderer/metrics/metrics.h"
#include "ui/layout_report.h"
#include "ui/panels.h"

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

void text_row(const char* label, const char* tooltip, const std::string& value, const ImVec4* colour = nullptr) {
  ImGui::TableNextColumn();
  ImGui::TextColored(kDim, "%s", label);
  if (tooltip && ImGui::IsItemHovered()) ImGui::SetTooltip("%s", tooltip);
  ImGui::TableNextColumn();
  if (colour) ImGui::TextColored(*colour, "%s", value.c_str());
  else ImGui::TextUnformatted(value.c_str());
}

// One line that never wraps (cut with "...", the whole text in the tooltip).
void one_line(const std::string& text, const ImVec4& colour, float leave = 0.0f) {
  const float room = ImGui::GetContentRegionAvail().x - leave;
  std::string shown = text;
  std::replace(shown.begin(), shown.end(), '\n', ' ');
  if (ImGui::CalcTextSize(shown.c_str()).x > room) {
    while (!shown.empty() && ImGui::CalcTextSize((shown + "...").c_str()).x > room) shown.pop_back();
    shown += "...";
  }
  ImGui::TextColored(colour, "%s", shown.c_str());
  if (shown.size() != text.size() && ImGui::IsItemHovered()) {
    ImGui::BeginTooltip();
    ImGui::PushTextWrapPos(ImGui::GetFontSize() * 30.0f);
    ImGui::TextUnformatted(text.c_str());
    ImGui::PopTextWrapPos();
    ImGui::EndTooltip();
  }
}

std::string printed(const char* fmt, double a, double b = 0.0) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, a, b);
  return buf;
}

// "Make reference": the button and its settings, or the running build's
// progress, in three lines either way.
void make_reference_controls(MeasureSettings& ms, const MeasureState& m, const UiStatus& status,
                             UiRequests& requests) {
  const ReferenceBuildStatus& b = m.build;
  if (b.running) {
    char overlay[96];
    if (b.finishing) std::snprintf(overlay, sizeof overlay, "storing...");
    else std::snprintf(overlay, sizeof overlay, "%d%%  ~%.0f s left  %u spp", static_cast<int>(b.fraction * 100.0),
                       b.seconds_left, b.spp);
    ImGui::ProgressBar(static_cast<float>(b.fraction), ImVec2(-1.0f, 0.0f), overlay);
    layout::item("measure.reference_progress");
    char line[128];
    std::snprintf(line, sizeof line, "Making a reference: %dx%d on %d thread%s, at most %.0f s", b.width, b.height,
                  b.threads, b.threads == 1 ? "" : "s", b.max_seconds);
    one_line(line, kDim);
    one_line(b.target, kDim);
    ImGui::SameLine();
    if (ImGui::SmallButton("Cancel##reference")) requests.measure.cancel_reference = true;
    layout::item("measure.cancel_reference");
    return;
  }
  if (ImGui::Button("Make reference")) requests.measure.make_reference = true;
  layout::item("measure.make_reference");
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("Renders a reference in the background (unbiased, seeds no render uses) to its target, and\n"
                      "stores it in the reference cache; then every figure is measured against it. One stopped by\n"
                      "its time limit short of the target is kept for this session only.");
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
  // The target: a share of the figures shown now, or a stated spp.
  char share_label[48];
  std::snprintf(share_label, sizeof share_label, "noise <= %.0f%% of now", 100.0 * kTargetShare);
  const char* targets[] = {share_label, "spp"};
  int target = ms.make_target == ReferenceTarget::Spp ? 1 : 0;
  ImGui::SetNextItemWidth(ImGui::GetContentRegionAvail().x * 0.5f);
  if (ImGui::BeginCombo("##make target", targets[target])) {
    for (int i = 0; i < 2; ++i) {
      if (ImGui::Selectable(targets[i], target == i)) target = i;
      layout::item(i == 0 ? "measure.target.share" : "measure.target.spp");
    }
    ImGui::EndCombo();
  }
  layout::item("measure.make_target");
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("noise <= %.0f%%: a reference whose own noise is at most %.0f%% of the raw error of the\n"
                      "figures shown now (a relMSE %.3g of theirs); spp: as many samples per pixel as set.",
                      100.0 * kTargetShare, 100.0 * kTargetShare, kTargetShare / (1.0 - kTargetShare));
  ms.make_target = target == 1 ? ReferenceTarget::Spp : ReferenceTarget::Share;
  ImGui::SameLine();
  ImGui::SetNextItemWidth(ImGui::GetContentRegionAvail().x);
  if (ms.make_target == ReferenceTarget::Spp) {
    int spp = static_cast<int>(ms.make_spp);
    if (ImGui::InputInt("##make spp", &spp, 64, 1024)) ms.make_spp = static_cast<std::uint32_t>(std::clamp(spp, 1, 1 << 20));
    layout::item("measure.make_spp");
  } else {
    ImGui::TextColored(kDim, "(%s)", m.figures.valid ? "from the figures" : "waits for figures: spp");
  }
  ImGui::SetNextItemWidth(ImGui::GetContentRegionAvail().x * 0.5f);
  ImGui::SliderFloat("##make seconds", &ms.make_seconds, 2.0f, 1800.0f, "at most %.0f s", ImGuiSliderFlags_Logarithmic);
  layout::item("measure.make_seconds");
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("Its time limit: it stops by then, target reached or not.");
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

void draw_legend_window(const ViewerSettings& settings, const MeasureState& m) {
  const ViewMode mode = settings.measure.view_mode;
  // Top right of the image area, clear of the other boxes and the image's middle.
  layout::Overlay place;
  place.corner = Corner::TopRight;
  place.width = ImGui::GetFontSize() * 18.0f + 2.0f * ImGui::GetStyle().WindowPadding.x;
  place.min_width = 9.0f;
  place.min_lines = 3.0f;
  float width = 0.0f;
  if (!layout::place_next_window("##view legend", place, &width)) return;
  ImGui::SetNextWindowBgAlpha(0.8f);
  const ImGuiWindowFlags flags = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize |
                                 ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoFocusOnAppearing |
                                 ImGuiWindowFlags_NoNav | ImGuiWindowFlags_NoInputs;
  if (ImGui::Begin("##view legend", nullptr, flags)) {
    ImGui::PushTextWrapPos(ImGui::GetCursorPosX() + width);
    // The heat map and the difference view name their metric, not only the view.
    const bool metric_view = mode == ViewMode::RelativeError || mode == ViewMode::Difference;
    if (metric_view)
      ImGui::TextColored(kAmber, "View: %s, %s (V, E)", mode == ViewMode::RelativeError ? "noise heat map" : "difference",
                         error_metric_label(mode, settings.measure.layer_options(mode).metric));
    else
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
    } else if (mode == ViewMode::GuidingTree) {
      const GuidingLeafMap& g = m.guiding_leaves;
      ImGui::Text("%d of the tree's %d leaves in view, learned from %d training pass%s", g.on_screen, g.leaves, g.pass,
                  g.pass == 1 ? "" : "es");
      ImGui::TextColored(kDim,
                         "Each colour is one leaf of the S-tree: a box of the scene in which the surfaces facing one "
                         "way share one learned distribution of directions (a quadtree). A leaf splits when its "
                         "records outgrow the pass's threshold, so leaves are small where many paths arrive. Click a "
                         "pixel (P) for its leaf's quadtree.");
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

  // The legend has a column of its own right of the frame, so however many
  // curves are pinned it never covers one.
  const float font = ImGui::GetFontSize();
  std::vector<std::pair<ImU32, std::string>> entries;
  for (std::size_t i = 0; i + 1 < curves.size(); ++i)
    entries.emplace_back(kPinColours[i % std::size(kPinColours)], "pin: " + curve_label(*curves[i]));
  if (!rec.live().points.empty()) entries.emplace_back(kLiveColour, "now: " + curve_label(rec.live()));
  float widest = 0.0f;
  for (const auto& e : entries) widest = std::max(widest, ImGui::CalcTextSize(e.second.c_str()).x);
  if (anchor_curve) widest = std::max(widest, ImGui::CalcTextSize("1/sqrt(N) slope").x);
  const float legend_w = std::min(widest + font * 2.2f, size.x * 0.42f);

  ImDrawList* dl = ImGui::GetWindowDrawList();
  const ImVec2 origin = ImGui::GetCursorScreenPos();
  const float left = font * 3.2f, bottom = font * 2.4f, top = font * 0.5f, right = font * 0.8f + legend_w;
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

  // The legend's column: a swatch and the curve's name (strategy, size), cut to fit.
  const float lx = b.x + font * 0.6f, text_room = legend_w - font * 2.2f;
  float ly = a.y;
  const auto legend_line = [&](ImU32 colour, std::string label, bool dashed) {
    if (ly + font > origin.y + size.y) return;
    if (dashed) {
      for (float k = 0.0f; k < 3.0f; k += 1.0f)
        dl->AddLine(ImVec2(lx + k * font * 0.6f, ly + font * 0.5f),
                    ImVec2(lx + k * font * 0.6f + font * 0.35f, ly + font * 0.5f), colour, 1.0f);
    } else {
      dl->AddLine(ImVec2(lx, ly + font * 0.5f), ImVec2(lx + font * 1.6f, ly + font * 0.5f), colour, 2.0f);
    }
    if (ImGui::CalcTextSize(label.c_str()).x > text_room) {
      while (!label.empty() && ImGui::CalcTextSize((label + "...").c_str()).x > text_room) label.pop_back();
      label += "...";
    }
    dl->AddText(ImVec2(lx + font * 2.0f, ly), text, label.c_str());
    ly += font * 1.15f;
  };
  for (const auto& [colour, label] : entries) legend_line(colour, label, false);
  if (anchor_curve) legend_line(IM_COL32(170, 170, 170, 220), "1/sqrt(N) slope", true);
}

// The convergence plot, bottom left of the image area: a plot that would rather
// be shorter than narrower. False when the area has no room for it.
bool draw_convergence_window(ViewerSettings& settings, const MeasureState& m, UiRequests& requests) {
  const float font = ImGui::GetFontSize();
  layout::Overlay o;
  o.corner = Corner::BottomLeft;
  o.width = font * 38.0f;
  o.height = font * 21.0f;
  o.min_width = 14.0f;
  o.min_lines = 6.0f;
  o.prefer_narrow = false;
  if (!layout::place_next_window("Convergence (G)", o)) return false;
  // Its size is what the planner gave (the constraint's maximum), every frame.
  const Box& area = layout::area();
  ImGui::SetNextWindowSize(ImVec2(std::min(o.width, area.w), std::min(o.height, area.h)), ImGuiCond_Always);
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
    if (ImGui::SmallButton("Pin (K)")) requests.measure.pin_curve = true;
    layout::item("plot.pin");
    ImGui::SameLine();
    if (ImGui::SmallButton("Clear")) requests.measure.clear_pins = true;
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("Clear the pinned curves");
    ImGui::SameLine();
    if (ImGui::SmallButton("Export")) requests.export_convergence = true;
    layout::item("plot.export");
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("The curves as SVG and CSV, in the screenshot folder");
    ImGui::SameLine();
    ImGui::TextColored(kDim, "%zu pinned", m.curves.pins().size());
  }
  ImGui::End();
  if (!open) settings.measure.show_plot = false;
  return true;
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
  const bool toggled = ImGui::Checkbox("auto range", &automatic);
  layout::item("display.auto_range");
  if (toggled) {
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
    // The two ends never meet: moving one past the other pushes the other along.
    if (ImGui::SliderFloat("##range lo", &lo, 1e-9f, 1e6f, "min %.3g", log)) {
      o.range.lo = lo;
      o.range.hi = std::max(static_cast<double>(hi), lo * kMinRangeRatio);
    }
    layout::item("display.range_min");
    ImGui::SameLine();
    ImGui::SetNextItemWidth(half);
    if (ImGui::SliderFloat("##range hi", &hi, 1e-9f, 1e6f, "max %.3g", log)) {
      o.range.hi = hi;
      o.range.lo = std::min(static_cast<double>(lo), hi / kMinRangeRatio);
    }
    layout::item("display.range_max");
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
  layout::item("measure.reference_field");
  ImGui::SameLine();
  if ((ImGui::Button("Load##reference") || entered) && !ms.reference_field.empty())
    requests.measure.load_reference = ms.reference_field;
  layout::item("measure.load_reference");

  // The reference in two lines, whatever it is: what it is, then how it came
  // or why it does not measure the render (with what would make it).
  if (m->reference.loaded()) {
    const ReferenceInfo& ri = m->reference.info;
    char line[200];
    const std::string spp = ri.spp > 0 ? ", " + std::to_string(ri.spp) + " spp" : std::string();
    std::snprintf(line, sizeof line, "reference: %s, %dx%d%s%s",
                  m->reference_from_cache ? "from the cache"
                                          : std::filesystem::path(m->reference.path).filename().string().c_str(),
                  m->reference.width, m->reference.height, spp.c_str(),
                  m->reference.has_variance() ? "" : ", no variance");
    const float drop_w = ImGui::CalcTextSize("Drop").x + style.FramePadding.x * 2.0f + style.ItemSpacing.x;
    one_line(line, kDim, drop_w);
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip("%s\n%s%s", m->reference.path.c_str(), ri.strategy.empty() ? "strategy unknown" : ri.strategy.c_str(),
                        m->reference.has_variance() ? "" : "\nno variance: its noise is not removed");
    ImGui::SameLine(std::max(0.0f, ImGui::GetWindowContentRegionMax().x - drop_w + style.ItemSpacing.x));
    if (ImGui::SmallButton("Drop")) requests.measure.clear_reference = true;
    layout::item("measure.drop_reference");
  } else {
    one_line("No reference: the figures are estimates (lower bounds).", kDim);
  }
  const std::string why = m->reference_mismatch();
  const std::string size_mismatch = m->size_mismatch(status.width, status.height);
  if (!m->reference_error.empty()) {
    one_line(m->reference_error, kRed);
  } else if (!why.empty()) {
    if (!size_mismatch.empty()) {
      char label[64];
      std::snprintf(label, sizeof label, "Render at %dx%d", m->reference.width, m->reference.height);
      if (ImGui::SmallButton(label)) requests.measure.render_at_reference_size = true;
      layout::item("measure.render_at_reference_size");
      ImGui::SameLine();
    }
    one_line(why, kAmber);
  } else if (!m->reference_note.empty()) {
    one_line(m->reference_note, m->reference_note_warns ? kAmber : kGreen);
  } else {
    ImGui::TextUnformatted(" ");
  }
  make_reference_controls(ms, *m, status, requests);

  // The figures: the same rows measured or not ("-" where there is no figure),
  // so the table keeps its height when a reference comes or goes.
  const Figures& f = m->figures;
  const bool measured = f.valid && f.against_reference;
  if (!f.valid) ImGui::TextColored(kDim, "Figures appear after the first full pass.");
  else if (measured && f.rough_reference)
    ImGui::TextColored(kAmber, "ROUGH: the reference's own noise is %.0f%% of the error", 100.0 * f.reference_share);
  else if (measured)
    ImGui::TextColored(kGreen, "MEASURED against the reference");
  else
    ImGui::TextColored(kAmber, "ESTIMATED from the film's own variance");
  layout::item("measure.source");
  if (measured && f.rough_reference && ImGui::IsItemHovered())
    ImGui::SetTooltip("A reference whose noise is more than %.0f%% of the raw error says little about the render:\n"
                      "make a better one (Make reference aims at %.0f%%).",
                      100.0 * kRoughShare, 100.0 * kTargetShare);
  const auto dash = [&](bool known, const std::string& value) { return known ? value : std::string("-"); };
  if (ImGui::BeginTable("figures", 2, ImGuiTableFlags_SizingStretchProp)) {
    share_columns({0.56f, 0.44f});
    const ImVec4 measured_colour = f.rough_reference ? kAmber : ImVec4(0.92f, 0.92f, 0.95f, 1.0f);
    text_row("relMSE (eps 1e-2)",
             "mean of ((x - r)^2 - var(r)) / (r^2 + 0.01): the error against the true image, the reference's own\n"
             "noise removed, with its 95% interval (docs/measuring.md)",
             dash(measured, printed("%.4g +- %.2g", f.relmse, f.relmse_interval)), &measured_colour);
    text_row("relMSE raw", "mean of (x - r)^2 / (r^2 + 0.01), the reference's noise included",
             dash(measured, printed("%.4g", f.relmse_raw)));
    const ImVec4 share_colour = f.reference_share > kRoughShare ? kAmber : kDim;
    text_row("reference's share", "the reference's own noise as a part of the raw relMSE",
             dash(measured, f.reference_corrected ? printed("%.1f%%", 100.0 * f.reference_share) : std::string("unknown")),
             &share_colour);
    text_row("efficiency", "1 / (relMSE * seconds): higher is better, flat over time when unbiased",
             !measured ? std::string("-")
                       : (f.relmse > 0.0 ? printed("%.5g", f.efficiency) : std::string("beyond the reference")),
             &measured_colour);
    text_row("mean rel. std. error", "the film's own noise: sqrt(variance of the mean) / mean, averaged over pixels",
             dash(f.valid, printed("%.5g", f.mean_relative_standard_error)));
    text_row("relMSE ESTIMATE (lower bound)",
             "variance of the mean / (mean^2 + 0.01): the expected relMSE of an unbiased strategy, at best.\n"
             "Blind to what the samples never found (a biased strategy looks good here).",
             dash(f.valid, printed("%.5g", f.estimated_relmse)));
    if (f.valid && !f.unbiased)
      text_row("efficiency ESTIMATE",
               "No efficiency without a reference: this strategy never samples indirect light, so its own\n"
               "variance hides the light it misses and would rank it best.",
               "none: biased", &kRed);
    else
      text_row("efficiency ESTIMATE", "1 / (estimated relMSE * seconds)", dash(f.valid, printed("%.5g", f.estimated_efficiency)));
    ImGui::EndTable();
  }
  // One reserved line: the estimate's reliability, or where the figures stand.
  if (f.valid && f.estimate_unreliable && !measured) {
    one_line("The estimate is unreliable now: it did not fall as the samples doubled.", kAmber);
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip("Rare bright paths are still being found, so the variance the film sees is not yet the\n"
                        "strategy's. The warning clears once the estimate falls as 1/spp again; or make a reference.");
  } else if (f.valid) {
    ImGui::TextColored(kDim, "at %u spp, %.2f s of rendering", f.spp, f.seconds);
  } else {
    ImGui::TextUnformatted(" ");
  }
  ImGui::Checkbox("Convergence plot (G)", &ms.show_plot);
  layout::item("measure.plot");
  ImGui::SameLine();
  if (ImGui::Button("Pin")) requests.measure.pin_curve = true;
  ImGui::SameLine();
  if (ImGui::Button("Clear pins")) requests.measure.clear_pins = true;
}

namespace {
// How the note says nee-mis chooses its light sample's emitter.
const char* light_choice_words(LightChoice choice) {
  switch (choice) {
    case LightChoice::Uniform: return "an emitter chosen uniformly";
    case LightChoice::Tree: return "an emitter chosen by the light tree, from power, distance and orientation";
    case LightChoice::Power: break;
  }
  return "an emitter chosen by power";
}
}  // namespace

void draw_nee_explanation(const SamplingSettings& s, LightChoice choice) {
  // Closed at first: the note is long, the panel is for controls.
  const bool open = ImGui::TreeNodeEx("why? (how nee-mis differs from a mixture)", ImGuiTreeNodeFlags_None);
  layout::item("sampling.nee_why");
  if (!open) return;
  // What continues the path: cosine alone (plain nee-mis) or a mixture (fastest's).
  const Strategy strategy = s.strategy();
  std::string continuation;
  bool cosine_alone = true;
  for (int i = 0; i < kTechniqueCount; ++i) {
    if (!(strategy.weights[i] > 0.0f)) continue;
    if (static_cast<Technique>(i) != Technique::Cosine) cosine_alone = false;
    char part[64];
    std::snprintf(part, sizeof part, "%s%s %.2g", continuation.empty() ? "" : " + ",
                  std::string(technique_name(static_cast<Technique>(i))).c_str(), static_cast<double>(strategy.weights[i]));
    continuation += part;
  }
  ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(0.85f, 0.85f, 0.88f, 1.0f));
  ImGui::TextWrapped(
      "A mixture (mix:...) draws ONE direction per bounce: it picks a technique by its weight, samples it, and "
      "divides by the mixture's density sum w_i p_i. That is the balance heuristic of MIS in one-sample form.");
  ImGui::Spacing();
  if (cosine_alone) {
    ImGui::TextWrapped(
        "nee-mis takes TWO samples at every diffuse vertex: a light sample (%s, sampled by solid angle) tested "
        "with a shadow ray, and a cosine sample that continues the path. Each is weighted against the OTHER "
        "technique's pdf for the same direction: power heuristic p_a^2 / (p_a^2 + p_b^2), or balance "
        "p_a / (p_a + p_b). Every path to a light is counted once in total.",
        light_choice_words(choice));
    ImGui::Spacing();
    ImGui::TextWrapped(
        "Unbiased: the cosine sample reaches every direction. Per sample, noise from small lights falls much "
        "faster; but a bounce costs a shadow ray more and paths, continued by cosine sampling alone, rarely end "
        "on a light, so per second it wins mainly where light comes straight from the lights (compare with the "
        "Convergence plot). It aims at emitters only, not at the glass sphere.");
  } else {
    ImGui::TextWrapped(
        "This strategy takes TWO samples at every diffuse vertex: a light sample (%s) tested with a shadow ray, "
        "and a sample of the mixture %s that continues the path. The light sample is weighted against the "
        "MIXTURE's density for its direction and emission the continuation reaches against the light "
        "technique's, by the %s heuristic, so every path to a light is counted once in total.",
        light_choice_words(choice), continuation.c_str(), strategy.heuristic == MisHeuristic::Power ? "power" : "balance");
    ImGui::Spacing();
    ImGui::TextWrapped(
        "Unbiased while the mixture has a technique that reaches every direction (cosine). Its other techniques aim "
        "the continuation: specular-objects at the glass and metal objects, so paths through the book's glass "
        "sphere (its caustic) are found far more often than by cosine sampling alone.%s",
        strategy.sobol || strategy.roulette_depth > 0
            ? " Sobol points stratify the first bounce, and Russian roulette ends long paths early."
            : "");
  }
  ImGui::PopStyleColor();
  ImGui::TreePop();
}

void draw_image_overlays(const ImageRect& image, ViewerSettings& settings, const MeasureState& measure,
                         std::uint32_t texture, UiRequests& requests) {
  const ViewMode mode = settings.measure.view_mode;
  if (mode != ViewMode::Image) {
    if (measure.layer_ok && texture != 0 && image.width > 0.0f)
      ImGui::GetBackgroundDrawList()->AddImage(reinterpret_cast<ImTextureID>(static_cast<std::intptr_t>(texture)),
                                               ImVec2(image.x, image.y),
                                               ImVec2(image.x + image.width, image.y + image.height));
    draw_legend_window(settings, measure);
  }
  if (settings.measure.show_plot && !draw_convergence_window(settings, measure, requests))
    draw_hint("No room for the convergence plot here: hide the panel (Tab) or lower the UI scale");
}

}  // namespace pdflab::ui
