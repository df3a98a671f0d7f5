#include "ui/split_view.h"
#include "ui/style.h"

#include "renderer/metrics/metrics.h"
#include "ui/layout_report.h"

#include <imgui.h>
#include <imgui_stdlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace pdflab::ui {

namespace {


// A side's figures in short lines, in its corner of the image area (A at the
// top left, B at the top right), clear of each other and of the image's middle.
void side_box(const char* id, const char* side, const SideFigures& f, Corner corner) {
  char lines[4][96];
  std::snprintf(lines[0], sizeof lines[0], "%u spp  %.1f s", f.spp, f.seconds);
  std::snprintf(lines[1], sizeof lines[1], "noise %s", format_figure(f.noise, true).c_str());
  if (f.reference_relmse >= 0.0) std::snprintf(lines[2], sizeof lines[2], "relMSE %s", format_figure(f.reference_relmse).c_str());
  else std::snprintf(lines[2], sizeof lines[2], "relMSE %s est.", format_figure(f.estimated_relmse).c_str());
  if (!f.unbiased && !f.efficiency_from_reference()) std::snprintf(lines[3], sizeof lines[3], "efficiency: none (biased)");
  else
    std::snprintf(lines[3], sizeof lines[3], "efficiency %s%s", format_figure(f.efficiency()).c_str(),
                  f.efficiency_from_reference() ? "" : " est.");
  // As drawn: the side's letter, then the strategy on the same line.
  float natural = ImGui::CalcTextSize(side).x + ImGui::GetStyle().ItemSpacing.x + ImGui::CalcTextSize(f.strategy.c_str()).x + 1.0f;
  for (const auto& l : lines) natural = std::max(natural, ImGui::CalcTextSize(l).x);
  const ImGuiStyle& style = ImGui::GetStyle();
  layout::Overlay o;
  o.corner = corner;
  o.width = natural + 2.0f * style.WindowPadding.x;
  // Each within its own half of the area: A's box never reaches over B's side.
  o.max_width = layout::area().w * 0.5f - ImGui::GetFontSize();
  // Its height at that width: the strategy (a long mixture) may wrap.
  const float text_w = std::min(o.width, o.max_width) - 2.0f * style.WindowPadding.x;
  const float strategy_w = std::max(1.0f, text_w - ImGui::CalcTextSize(side).x - style.ItemSpacing.x);
  const float strategy_lines =
      std::ceil(ImGui::CalcTextSize(f.strategy.c_str(), nullptr, false, strategy_w).y / ImGui::GetTextLineHeight());
  o.height = layout::text_height(static_cast<int>(std::max(1.0f, strategy_lines)) + 4 + (f.unbiased ? 0 : 1));
  o.min_width = 7.0f;
  o.min_lines = 3.0f;
  float wrap = 0.0f;
  if (!layout::place_next_window(id, o, &wrap)) return;
  ImGui::SetNextWindowBgAlpha(0.72f);
  const ImGuiWindowFlags flags = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize |
                                 ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoFocusOnAppearing |
                                 ImGuiWindowFlags_NoNav | ImGuiWindowFlags_NoInputs;
  if (ImGui::Begin(id, nullptr, flags)) {
    ImGui::PushTextWrapPos(ImGui::GetCursorPosX() + wrap);
    ImGui::TextColored(ImVec4(1.0f, 0.85f, 0.4f, 1.0f), "%s", side);
    ImGui::SameLine();
    ImGui::TextWrapped("%s", f.strategy.c_str());
    if (!f.unbiased) ImGui::TextColored(kRed, "biased");
    for (const auto& l : lines) ImGui::TextWrapped("%s", l);
    ImGui::PopTextWrapPos();
  }
  ImGui::End();
}

}  // namespace

SplitThreads split_threads(int hardware_threads) {
  const int half = std::max(1, hardware_threads / 2);
  return {half, half};
}

bool SplitDivider::update(float mouse_x, float mouse_y, bool clicked, bool down, float left, float top, float width,
                          float height, float grab) {
  if (!(width > 0.0f)) return false;
  if (dragging && !down) dragging = false;
  if (clicked) {
    const bool inside_y = mouse_y >= top && mouse_y < top + height;
    dragging = inside_y && std::abs(mouse_x - x(left, width)) <= grab;
  }
  if (dragging) fraction = std::clamp((mouse_x - left) / width, 0.0f, 1.0f);
  return dragging;
}

double SideFigures::efficiency() const {
  // Without a reference a biased strategy's own estimate hides what it misses: no figure.
  if (reference_relmse < 0.0 && !unbiased) return -1.0;
  const double relmse = reference_relmse >= 0.0 ? reference_relmse : estimated_relmse;
  if (!(relmse > 0.0) || !(seconds > 0.0)) return -1.0;
  return pdflab::efficiency(relmse, seconds);
}

std::vector<std::string> split_strategy_choices() {
  return {"cosine",
          "uniform-hemisphere",
          "uniform-sphere",
          "light",
          "light-sa",
          "mix:cosine=0.5,light=0.5",
          "mix:cosine=0.5,light-sa=0.5",
          "mix:cosine=0.9,light=0.1",
          "nee-mis"};
}

std::string format_figure(double value, bool percent) {
  if (!(value >= 0.0) || !std::isfinite(value)) return "-";
  char buf[32];
  if (percent) std::snprintf(buf, sizeof buf, "%.2f%%", value * 100.0);
  else if (value != 0.0 && (value < 1e-2 || value >= 1e4)) std::snprintf(buf, sizeof buf, "%.2e", value);
  else std::snprintf(buf, sizeof buf, "%.3g", value);
  return buf;
}

void draw_split_overlay(const SplitState& s, float left, float top, float width, float height) {
  if (!(width > 0.0f)) return;
  ImDrawList* list = ImGui::GetBackgroundDrawList();
  const float x = s.divider.x(left, width);
  const ImU32 line = s.divider.dragging ? IM_COL32(255, 210, 90, 255) : IM_COL32(255, 255, 255, 200);
  list->AddLine(ImVec2(x, top), ImVec2(x, top + height), IM_COL32(0, 0, 0, 160), 4.0f);
  list->AddLine(ImVec2(x, top), ImVec2(x, top + height), line, 2.0f);
  // A grip in the middle, so the line reads as something to drag.
  const ImVec2 c(x, top + height * 0.5f);
  list->AddCircleFilled(c, 9.0f, IM_COL32(30, 30, 36, 230), 20);
  list->AddCircle(c, 9.0f, line, 20, 2.0f);
  list->AddTriangleFilled(ImVec2(c.x - 6, c.y), ImVec2(c.x - 2, c.y - 4), ImVec2(c.x - 2, c.y + 4), line);
  list->AddTriangleFilled(ImVec2(c.x + 6, c.y), ImVec2(c.x + 2, c.y + 4), ImVec2(c.x + 2, c.y - 4), line);

  // Each over its own side's top corner; the planner keeps them apart.
  side_box("##split_a", "A", s.a, Corner::TopLeft);
  side_box("##split_b", "B", s.b, Corner::TopRight);
}

void draw_split_controls(SplitState& s, SplitRequests& requests) {
  // Bottom left, sized from the font (the UI scale): its fields and labels.
  const float font = ImGui::GetFontSize();
  const ImGuiStyle& style = ImGui::GetStyle();
  const float label = ImGui::CalcTextSize("B (any, Enter)").x + style.ItemInnerSpacing.x;
  layout::Overlay o;
  o.corner = Corner::BottomLeft;
  o.width = font * 12.0f + label + 2.0f * style.WindowPadding.x;
  o.min_width = 10.0f;
  o.min_lines = 5.0f;
  float room = 0.0f;
  if (!layout::place_next_window("##split_controls", o, &room)) return;
  ImGui::SetNextWindowBgAlpha(0.85f);
  const ImGuiWindowFlags flags = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize |
                                 ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoFocusOnAppearing;
  if (!ImGui::Begin("##split_controls", nullptr, flags)) {
    ImGui::End();
    return;
  }
  ImGui::PushTextWrapPos(ImGui::GetCursorPosX() + room);
  ImGui::TextColored(kDim, "Split A/B (S): same seed, equal time");
  ImGui::TextColored(kDim, "A: the panel's strategy, %d thread%s a side", s.threads_per_side,
                     s.threads_per_side == 1 ? "" : "s");
  ImGui::PopTextWrapPos();
  const float field = std::max(font * 5.0f, std::min(font * 12.0f, room - label));
  ImGui::SetNextItemWidth(field);
  if (ImGui::BeginCombo("B strategy", s.b_strategy.c_str())) {
    for (const std::string& choice : split_strategy_choices())
      if (ImGui::Selectable(choice.c_str(), choice == s.b_strategy)) {
        s.b_field = choice;
        if (choice != s.b_strategy) {
          s.b_strategy = choice;
          requests.restart = true;
        }
      }
    ImGui::EndCombo();
  }
  layout::item("split.b_strategy");
  ImGui::SetNextItemWidth(field);
  if (ImGui::InputText("B (any, Enter)", &s.b_field, ImGuiInputTextFlags_EnterReturnsTrue) && s.b_field != s.b_strategy) {
    s.b_strategy = s.b_field;
    requests.restart = true;
  }
  layout::item("split.b_field");
  if (!s.b_error.empty()) {
    ImGui::PushTextWrapPos(ImGui::GetCursorPosX() + room);
    ImGui::TextColored(kRed, "%s", s.b_error.c_str());
    ImGui::PopTextWrapPos();
  }
  ImGui::SetNextItemWidth(field);
  if (ImGui::InputTextWithHint("Reference", "reference .pfm (Enter)", &s.reference_path,
                               ImGuiInputTextFlags_EnterReturnsTrue))
    requests.load_reference = true;
  if (!s.reference_status.empty()) {
    const bool ok = s.reference_status.rfind("loaded", 0) == 0 || s.reference_status.rfind("using", 0) == 0;
    ImGui::PushTextWrapPos(ImGui::GetCursorPosX() + room);
    ImGui::TextColored(ok ? kGreen : kRed, "%s", s.reference_status.c_str());
    ImGui::PopTextWrapPos();
  }
  ImGui::End();
}

}  // namespace pdflab::ui
