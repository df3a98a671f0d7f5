#include "ui/panels.h"
#include "ui/style.h"

#include "renderer/integrator/integrator.h"
#include "ui/layout_report.h"
#include "ui/measure_panel.h"
#include "ui/split_view.h"

#include <imgui.h>
#include <imgui_stdlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

namespace pdflab::ui {

namespace {


std::string format_seconds(double s) {
  char buf[32];
  if (s < 1.0) std::snprintf(buf, sizeof buf, "%.0f ms", s * 1e3);
  else if (s < 120.0) std::snprintf(buf, sizeof buf, "%.2f s", s);
  else std::snprintf(buf, sizeof buf, "%dm %02ds", static_cast<int>(s) / 60, static_cast<int>(s) % 60);
  return buf;
}

// One label/value pair in a four-column statistics table.
void stat_cell(const char* label, const char* fmt, auto... args) {
  ImGui::TableNextColumn();
  ImGui::TextColored(kDim, "%s", label);
  ImGui::TableNextColumn();
  ImGui::Text(fmt, args...);
}

// One line of text that never wraps: cut with "..." where the panel ends, the
// whole text in its tooltip. What keeps a message from pushing controls down.
void one_line(const std::string& text, const ImVec4& colour, const char* tooltip_extra = nullptr, float leave = 0.0f) {
  const float room = ImGui::GetContentRegionAvail().x - leave;
  std::string shown = text;
  std::replace(shown.begin(), shown.end(), '\n', ' ');
  if (ImGui::CalcTextSize(shown.c_str()).x > room) {
    while (!shown.empty() && ImGui::CalcTextSize((shown + "...").c_str()).x > room) shown.pop_back();
    shown += "...";
  }
  ImGui::TextColored(colour, "%s", shown.c_str());
  if (ImGui::IsItemHovered() && (shown.size() != text.size() || tooltip_extra)) {
    ImGui::BeginTooltip();
    ImGui::PushTextWrapPos(ImGui::GetFontSize() * 30.0f);
    ImGui::TextUnformatted(text.c_str());
    if (tooltip_extra) ImGui::TextUnformatted(tooltip_extra);
    ImGui::PopTextWrapPos();
    ImGui::EndTooltip();
  }
}

// The predicted curve's box: relative efficiency 0..1 against w 0..1, with
// ticks on both axes. Greyed (a curve of an earlier generation while the next
// is computed) when `current` is false. Always the same size, curve or not.
void weight_curve_plot(const WeightCurveStatus& c, bool current, const std::string& note) {
  const float font = ImGui::GetFontSize();
  const float width = ImGui::GetContentRegionAvail().x, height = font * 6.5f;
  const ImVec2 origin = ImGui::GetCursorScreenPos();
  ImGui::Dummy(ImVec2(width, height));
  layout::item("sampling.curve");
  const float left = ImGui::CalcTextSize("0.5").x + font * 0.4f, bottom = font * 1.2f;
  const ImVec2 p0(origin.x + left, origin.y + font * 0.3f);
  const ImVec2 p1(origin.x + width - font * 0.5f, origin.y + height - bottom);
  const float pw = p1.x - p0.x, ph = p1.y - p0.y;
  ImDrawList* dl = ImGui::GetWindowDrawList();
  dl->AddRectFilled(p0, p1, IM_COL32(20, 20, 24, 255));
  const ImU32 grid = IM_COL32(60, 60, 70, 255), label = IM_COL32(200, 200, 205, 255);
  for (const double t : {0.0, 0.25, 0.5, 0.75, 1.0}) {
    const float x = p0.x + static_cast<float>(t) * pw;
    dl->AddLine(ImVec2(x, p0.y), ImVec2(x, p1.y), grid);
    const std::string s = tick_label(t);
    const float tw = ImGui::CalcTextSize(s.c_str()).x;
    dl->AddText(ImVec2(std::clamp(x - tw * 0.5f, origin.x, origin.x + width - tw), p1.y + 2.0f), label, s.c_str());
  }
  for (const double t : {0.0, 0.5, 1.0}) {
    const float y = p1.y - static_cast<float>(t) * ph;
    dl->AddLine(ImVec2(p0.x, y), ImVec2(p1.x, y), grid);
    const std::string s = tick_label(t);
    dl->AddText(ImVec2(p0.x - ImGui::CalcTextSize(s.c_str()).x - font * 0.2f, y - font * 0.5f), label, s.c_str());
  }
  dl->AddRect(p0, p1, IM_COL32(140, 140, 150, 255));
  const std::size_t n = std::min(c.weight.size(), c.relative_efficiency.size());
  const auto at = [&](std::size_t i) {
    return ImVec2(p0.x + c.weight[i] * pw, p1.y - std::clamp(c.relative_efficiency[i], 0.0f, 1.05f) / 1.05f * ph);
  };
  const auto heavy = [&](std::size_t i) { return i < c.largest_share.size() && c.largest_share[i] > c.dominant_share; };
  if (n >= 2) {
    // Grey over the weights whose prediction one path dominates.
    const float step = pw / static_cast<float>(n - 1);
    if (current)
      for (std::size_t i = 0; i < n; ++i)
        if (heavy(i)) {
          const float x = at(i).x;
          dl->AddRectFilled(ImVec2(std::max(p0.x, x - 0.5f * step), p0.y), ImVec2(std::min(p1.x, x + 0.5f * step), p1.y),
                            IM_COL32(150, 150, 150, 90));
        }
    std::vector<ImVec2> pts;
    for (std::size_t i = 0; i < n; ++i) pts.push_back(at(i));
    dl->AddPolyline(pts.data(), static_cast<int>(pts.size()),
                    current ? IM_COL32(120, 190, 255, 255) : IM_COL32(120, 120, 130, 200), 0, 2.0f);
    const auto mark = [&](double w, ImU32 colour, float thickness) {
      if (!(w >= 0.0)) return;
      const float x = p0.x + static_cast<float>(w) * pw;
      dl->AddLine(ImVec2(x, p0.y), ImVec2(x, p1.y), colour, thickness);
    };
    mark(c.sampling, current ? IM_COL32(230, 230, 230, 200) : IM_COL32(150, 150, 150, 160), 1.0f);
    mark(c.best, current ? IM_COL32(255, 190, 60, 255) : IM_COL32(170, 150, 110, 200), 2.0f);
    if (current && ImGui::IsItemHovered()) {
      const float t = std::clamp((ImGui::GetIO().MousePos.x - p0.x) / pw, 0.0f, 1.0f);
      const std::size_t i = static_cast<std::size_t>(std::lround(t * static_cast<float>(n - 1)));
      if (heavy(i))
        ImGui::SetTooltip("w = %.2f: %.0f%% of the best, likely too high (one path carries %.0f%% of the moment)",
                          c.weight[i], 100.0f * c.relative_efficiency[i], 100.0f * c.largest_share[i]);
      else
        ImGui::SetTooltip("w = %.2f: %.0f%% of the best", c.weight[i], 100.0f * c.relative_efficiency[i]);
    }
  }
  if (!note.empty()) {
    // Inside the box, so its wording never moves what is below.
    const ImVec2 size = ImGui::CalcTextSize(note.c_str(), nullptr, false, pw - font);
    const ImVec2 at_text(p0.x + (pw - size.x) * 0.5f, p0.y + (ph - size.y) * 0.5f);
    dl->AddRectFilled(ImVec2(at_text.x - 4.0f, at_text.y - 2.0f), ImVec2(at_text.x + size.x + 4.0f, at_text.y + size.y + 2.0f),
                      IM_COL32(20, 20, 24, 220));
    dl->AddText(ImGui::GetFont(), font, at_text, IM_COL32(200, 200, 205, 255), note.c_str(), nullptr, pw - font);
  }
}

// Beside the w slider, in lines of fixed height whatever the state: the
// efficiency predicted at every w from the paths drawn so far (the last curve
// greyed while the next is computed), the predicted best with a button that
// moves the slider there, the cost model, auto weight and its history, and why
// the sampling weight keeps away from 0 and 1 while predicting.
void draw_weight_curve(ViewerSettings& settings, PanelState& state, const UiStatus& status, int a, int b,
                       UiRequests& requests) {
  SamplingSettings& s = settings.sampling;
  const WeightCurveStatus& now = status.weights;
  const std::array<int, 2> pair{a, b};
  if (now.active) {
    state.last_curve = now;
    state.last_curve_pair = pair;
  }
  const bool depth_one = status.max_depth > 0 && status.max_depth <= 1;
  const bool have_last = state.last_curve_pair == pair && !state.last_curve.weight.empty();
  const WeightCurveStatus& c = now.active ? now : state.last_curve;
  const bool shown = !depth_one && (now.active || have_last);
  const std::string name_a(technique_name(static_cast<Technique>(a))), name_b(technique_name(static_cast<Technique>(b)));

  char title[96];
  if (depth_one) std::snprintf(title, sizeof title, "Predicted efficiency: none at max depth 1");
  else if (now.active) std::snprintf(title, sizeof title, "Predicted efficiency (%llu paths)", static_cast<unsigned long long>(now.paths));
  else std::snprintf(title, sizeof title, "Predicted efficiency against w");
  // The title gives way to the Export button at the line's end.
  const float export_w = ImGui::CalcTextSize("Export").x + ImGui::GetStyle().FramePadding.x * 2.0f;
  one_line(title, kDim, nullptr, export_w + ImGui::GetStyle().ItemSpacing.x);
  ImGui::SameLine(std::max(0.0f, ImGui::GetWindowContentRegionMax().x - export_w));
  ImGui::BeginDisabled(!status.can_export_curve);
  if (ImGui::SmallButton("Export##curve")) requests.export_curve = true;
  ImGui::EndDisabled();
  layout::item("sampling.export_curve");
  if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
    ImGui::SetTooltip("The predicted curve as SVG and CSV, in the screenshot folder");

  std::string note;
  if (depth_one) note = "w cannot matter: at max depth 1 no sampled direction is ever followed";
  else if (!now.active) note = have_last ? "recomputing... (" + now.why + ")" : now.why;
  weight_curve_plot(shown ? c : WeightCurveStatus{}, now.active && !depth_one, note);

  bool any_heavy = false;
  for (std::size_t i = 0; i < c.largest_share.size() && shown; ++i) any_heavy = any_heavy || c.largest_share[i] > c.dominant_share;
  ImGui::TextColored(kDim, "%s", any_heavy ? "grey: one path dominates, likely too high" : " ");
  if (any_heavy && ImGui::IsItemHovered())
    ImGui::SetTooltip("There a single path carries more than %.0f%% of the predicted second moment. With a\n"
                      "finite moment that share falls as paths are added; where it stays large the moment is\n"
                      "infinite or carried by paths too rare for the samples so far, so the predicted variance\n"
                      "is too low and the efficiency too high. A render there has the same trouble: its error\n"
                      "falls slower than 1/N.",
                      100.0 * static_cast<double>(c.dominant_share));
  if (shown && c.best >= 0.0) ImGui::TextColored(now.active ? kAmber : kDim, "predicted best w = %.2f", c.best);
  else ImGui::TextColored(kDim, "predicted best w = -");
  ImGui::SameLine();
  ImGui::BeginDisabled(!now.active || depth_one || !(now.best >= 0.0));
  if (ImGui::Button("Use the best weight") && now.best >= 0.0) {
    s.weights[a] = static_cast<float>(now.best);
    s.weights[b] = 1.0f - static_cast<float>(now.best);
  }
  ImGui::EndDisabled();
  layout::item("sampling.use_best");
  if (shown && c.fixed_cost_rays >= 0.0) {
    ImGui::TextColored(kDim, "a sample costs its rays + %.1f rays (%s)", c.fixed_cost_rays,
                       c.cost_fitted ? "fitted to the passes' times" : "prior");
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip("Time per sample = fixed cost + cost per ray x rays. The fixed cost (the camera ray's set-up,\n"
                        "the film, the pass's bookkeeping) is fitted to auto weight's passes once their rays differ\n"
                        "enough; until then it is a prior.");
  } else {
    ImGui::TextColored(kDim, "a sample costs: not priced yet");
  }
  ImGui::BeginDisabled(depth_one);
  ImGui::Checkbox("Auto weight", &settings.auto_weight);
  ImGui::EndDisabled();
  layout::item("sampling.auto_weight");
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("Between passes (at 16, 32, 64, ... spp) w moves to the best the passes so far predict;\n"
                      "each pass's weight is fixed before it starts, so the accumulated image stays unbiased.\n"
                      "With guided, every pass draws from the distribution the first one learned.");
  if (settings.auto_weight) {
    // Its history's line and plot are there while auto weight is on, filled or not.
    ImGui::SameLine();
    std::string h;
    for (std::size_t i = now.history.size() > 6 ? now.history.size() - 6 : 0; i < now.history.size(); ++i) {
      char buf[16];
      std::snprintf(buf, sizeof buf, "%s%.2f", h.empty() ? "" : " > ", now.history[i]);
      h += buf;
    }
    one_line("w: " + (h.empty() ? std::string("-") : h), kDim);
    ImGui::PlotLines("##history", now.history.data(), static_cast<int>(now.history.size()), 0, nullptr, 0.0f, 1.0f,
                     ImVec2(ImGui::GetContentRegionAvail().x, ImGui::GetFontSize() * 2.5f));
  }
  if (ImGui::TreeNode("Why is w kept inside [0.05, 0.95] while predicting?")) {
    ImGui::PushTextWrapPos(0.0f);
    ImGui::TextColored(kDim,
                       "The curve reweights each path drawn at w by the ratio of its densities, p_w / p_w', to say "
                       "what it would have cost at w'. That ratio is at most max(w'/w, (1-w')/(1-w)): bounded "
                       "while w stays away from 0 and 1, but as w nears 0 (or 1) directions that only %s (or %s) "
                       "draws are almost never seen, and the few that are carry huge ratios, so the prediction "
                       "at the far end becomes noise. At w = 0 or 1 it cannot see them at all. So the prediction "
                       "waits outside this floor, and auto weight never goes past it.",
                       name_a.c_str(), name_b.c_str());
    ImGui::PopTextWrapPos();
    ImGui::TreePop();
  }
}

// The strategy drop-down: each technique alone, then the mixture, then nee-mis
// with either heuristic.
void strategy_combo(SamplingSettings& s) {
  std::string current = s.mixture ? "mixture" : std::string(technique_name(s.single));
  if (s.nee_mis) current = s.heuristic == MisHeuristic::Power ? "nee-mis (power heuristic)" : "nee-mis (balance heuristic)";
  if (!ImGui::BeginCombo("Strategy", current.c_str())) return;
  for (int i = 0; i < kTechniqueCount; ++i) {
    const auto t = static_cast<Technique>(i);
    std::string name(technique_name(t));
    // Biased alone at the parameter the panel holds (uniform-cone is not at 90 degrees).
    Strategy alone = Strategy::single(t);
    alone.parameters = s.parameters;
    if (!alone.is_unbiased()) name += "   (biased alone)";
    if (ImGui::Selectable(name.c_str(), !s.nee_mis && !s.mixture && s.single == t)) {
      s.nee_mis = false;
      s.mixture = false;
      s.single = t;
    }
  }
  if (ImGui::Selectable("mixture", !s.nee_mis && s.mixture)) {
    s.nee_mis = false;
    if (!s.mixture) {
      // Start the mixture from what was shown, so the image does not jump.
      s.weights = {};
      s.weights[static_cast<int>(s.single)] = 1.0f;
    }
    s.mixture = true;
  }
  ImGui::Separator();
  for (const MisHeuristic h : {MisHeuristic::Power, MisHeuristic::Balance}) {
    const char* label = h == MisHeuristic::Power ? "nee-mis (power heuristic)" : "nee-mis (balance heuristic)";
    if (ImGui::Selectable(label, s.nee_mis && s.heuristic == h)) {
      s.nee_mis = true;
      s.heuristic = h;
    }
  }
  ImGui::EndCombo();
}

// A slider for each parameter a technique in use takes (cosine-power's N).
void technique_parameters(SamplingSettings& s) {
  for (int i = 0; i < kTechniqueCount && !s.nee_mis; ++i) {
    const TechniqueInfo& t = technique_info(static_cast<Technique>(i));
    const bool used = s.mixture ? s.weights[i] > 0.0f : s.single == static_cast<Technique>(i);
    if (t.parameter.empty() || !used) continue;
    ImGui::PushID(100 + i);
    const std::string label = std::string(t.name) + " " + std::string(t.parameter);
    ImGui::SliderFloat(label.c_str(), &s.parameters[i], t.parameter_min, t.parameter_max, "%.1f",
                       ImGuiSliderFlags_AlwaysClamp | ImGuiSliderFlags_Logarithmic);
    ImGui::PopID();
  }
}

// The book's two-technique mixture as one number, w * A + (1 - w) * B, with
// the predicted curve beside it.
void pair_weight_slider(ViewerSettings& settings, PanelState& state, const UiStatus& status, UiRequests& requests) {
  SamplingSettings& s = settings.sampling;
  state.w_pair = two_technique_pair(s, state.w_pair);
  if (state.w_pair[0] < 0) return;
  const int a = state.w_pair[0], b = state.w_pair[1];
  const float sum = s.weights[a] + s.weights[b];
  float w = sum > 0.0f ? s.weights[a] / sum : 0.5f;
  ImGui::TextColored(kDim, "w\xc2\xb7%s + (1-w)\xc2\xb7%s", std::string(technique_name(static_cast<Technique>(a))).c_str(),
                     std::string(technique_name(static_cast<Technique>(b))).c_str());
  ImGui::SetNextItemWidth(ImGui::GetContentRegionAvail().x * 0.62f);
  if (ImGui::SliderFloat("w##pair", &w, 0.0f, 1.0f, "%.3f", ImGuiSliderFlags_AlwaysClamp)) {
    s.weights[a] = w;
    s.weights[b] = 1.0f - w;
  }
  layout::item("sampling.w");
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("Ctrl+click to type an exact value");
  draw_weight_curve(settings, state, status, a, b, requests);
}

// One raw weight slider per technique, each with its fraction of the mixture.
void mixture_weights(SamplingSettings& s) {
  const auto norm = s.normalised();
  ImGui::TextColored(kDim, "weight per technique         fraction");
  for (int i = 0; i < kTechniqueCount; ++i) {
    ImGui::PushID(i);
    ImGui::SetNextItemWidth(ImGui::GetContentRegionAvail().x * 0.62f);
    const std::string name(technique_name(static_cast<Technique>(i)));
    ImGui::SliderFloat("##w", &s.weights[i], 0.0f, 1.0f, (name + " %.3g").c_str(), ImGuiSliderFlags_AlwaysClamp);
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("Raw weight; the renderer normalises. Ctrl+click to type one.");
    ImGui::SameLine();
    if (norm[i] > 0.0f) ImGui::Text("%.1f%%", norm[i] * 100.0f);
    else ImGui::TextColored(kDim, "0%%");
    ImGui::PopID();
  }
  // All weights 0: the message line says so (the viewer refuses the mixture).
}

// The presets in their one place, the section's first row, whatever the
// strategy: 1-5 as the keys have them, the current one marked. The row wraps
// where the panel ends, the same way for every strategy.
void preset_buttons(SamplingSettings& s) {
  const ImGuiStyle& style = ImGui::GetStyle();
  const float right = ImGui::GetWindowPos().x + ImGui::GetWindowContentRegionMax().x;
  const int current = preset_key_of(s);
  for (int key = 1; key <= kPresetKeyCount; ++key) {
    char label[48];
    std::snprintf(label, sizeof label, "%d %s", key, preset_key_label(key));
    const float w = ImGui::CalcTextSize(label).x + style.FramePadding.x * 2.0f;
    if (key > 1 && ImGui::GetItemRectMax().x + style.ItemSpacing.x + w <= right) ImGui::SameLine();
    if (key == current) ImGui::PushStyleColor(ImGuiCol_Button, ImGui::GetStyleColorVec4(ImGuiCol_ButtonActive));
    if (ImGui::Button(label)) s = preset_by_key(key);
    if (key == current) ImGui::PopStyleColor();
    char name[24];
    std::snprintf(name, sizeof name, "preset.%d", key);
    layout::item(name);
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip("Key %d: %s", key, preset_by_key(key).strategy().to_string().c_str());
  }
}

// Russian roulette and the Sobol sampler, for any strategy.
void path_options(SamplingSettings& s) {
  bool roulette = s.roulette_depth > 0;
  if (ImGui::Checkbox("Russian roulette", &roulette)) s.roulette_depth = roulette ? kDefaultRouletteDepth : 0;
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("From depth D on, a path goes on with probability min(1, throughput x albedo) and is\n"
                      "divided by it: unbiased, shorter paths; off is the book's estimator");
  if (roulette) {
    ImGui::SameLine();
    ImGui::SetNextItemWidth(ImGui::GetContentRegionAvail().x * 0.5f);
    ImGui::SliderInt("from depth", &s.roulette_depth, 1, 20, "%d", ImGuiSliderFlags_AlwaysClamp);
    if (s.strategy_without_name().uses(Technique::Guided)) {
      ImGui::Checkbox("by the learned light", &s.guided_roulette);
      if (ImGui::IsItemHovered())
        ImGui::SetTooltip("+rr:guided: a path goes on in proportion to the light the guide expects it to\n"
                          "bring over what its pixel was expected to get, however small its throughput;\n"
                          "where the guide learned nothing, the throughput rule from the depth above");
    }
  }
  ImGui::Checkbox("Sobol sampler", &s.sobol);
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("Owen-scrambled Sobol points for %s random numbers, stratified\n"
                      "across each pixel's samples (+sobol); off: every number independent",
                      stratified_vertices().c_str());
  if (!s.nee_mis) return;
  // nee-mis's light choice: the scene's (its light_choice), or one of LightChoice's.
  const char* items[] = {"the scene's", "power", "uniform", "tree"};
  int current = s.light_choice ? 1 + static_cast<int>(*s.light_choice) : 0;
  ImGui::SetNextItemWidth(ImGui::GetContentRegionAvail().x * 0.5f);
  if (ImGui::Combo("light choice", &current, items, 4))
    s.light_choice = current == 0 ? std::nullopt : std::optional<LightChoice>(static_cast<LightChoice>(current - 1));
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("How nee-mis chooses the emitter of its light sample (+lights:CHOICE): by power, uniformly,\n"
                      "or by the light tree (power, distance and orientation from the point, for many lights)");
}

// The strategy as `pdflab render --strategy` takes it, wrapped before a '+'
// where it is wider than the panel (fastest's is), never inside a weight; the
// bias label after it, on the next line if it does not fit.
void strategy_line(const SamplingSettings& s) {
  const Strategy strategy = s.strategy();
  bool any = strategy.nee_mis;
  for (float w : strategy.weights) any = any || w > 0.0f;
  if (!any) return;
  const std::string text = strategy.to_string();
  const float line_end = ImGui::GetCursorScreenPos().x + ImGui::GetContentRegionAvail().x;
  const auto same_line_if_fits = [&](const char* next, float spacing) {
    ImGui::SameLine(0.0f, spacing);
    if (ImGui::GetCursorScreenPos().x + ImGui::CalcTextSize(next).x > line_end) ImGui::NewLine();
  };
  bool hovered = false;
  for (std::size_t begin = 0; begin < text.size();) {
    const std::size_t end = std::min(text.find('+', begin + 1), text.size());
    const std::string piece = text.substr(begin, end - begin);
    if (begin > 0) same_line_if_fits(piece.c_str(), 0.0f);
    ImGui::TextUnformatted(piece.c_str());
    hovered = hovered || ImGui::IsItemHovered();
    begin = end;
  }
  if (hovered) ImGui::SetTooltip("The same strategy for `pdflab render --strategy`");
  same_line_if_fits(strategy.is_unbiased() ? "unbiased" : "BIASED", ImGui::GetStyle().ItemSpacing.x);
  if (strategy.is_unbiased()) {
    ImGui::TextColored(kGreen, "unbiased");
  } else {
    ImGui::TextColored(kRed, "BIASED");
    ImGui::PushStyleColor(ImGuiCol_Text, kRed);
    ImGui::TextWrapped("%s: its pdf is zero where light may arrive, which it then never sees.",
                       strategy.bias_reason().c_str());
    ImGui::PopStyleColor();
  }
}

// The Sampling section, in the order it reads: the presets, the strategy, its
// parameters, its weights, the path options, the strategy as text; any edit
// restarts the render.
void sampling_section(ViewerSettings& settings, PanelState& state, const UiStatus& status, UiRequests& requests) {
  SamplingSettings& s = settings.sampling;
  const SamplingSettings before = s;
  preset_buttons(s);
  strategy_combo(s);
  layout::item("sampling.strategy");
  technique_parameters(s);
  if (s.nee_mis) draw_nee_explanation(s, s.light_choice.value_or(status.scene_light_choice));
  if (s.mixture && !s.nee_mis) {
    pair_weight_slider(settings, state, status, requests);
    mixture_weights(s);
  }
  path_options(s);
  strategy_line(s);
  // A refused strategy is said on the panel's message line, which moves nothing.
  if (!(s == before)) requests.restart_render = true;
}

void scene_section(ViewerSettings& settings, PanelState& state, const UiStatus& status, UiRequests& requests) {
  namespace fs = std::filesystem;
  const std::string current_name = fs::path(status.scene_path).filename().string();
  if (ImGui::BeginCombo("Scene", current_name.c_str())) {
    for (const std::string& file : status.scene_files) {
      const std::string name = fs::path(file).filename().string();
      if (ImGui::Selectable(name.c_str(), file == status.scene_path)) {
        requests.load_scene = file;
        state.scene_path_field = file;
      }
    }
    ImGui::EndCombo();
  }
  layout::item("scene.combo");
  ImGui::SetNextItemWidth(ImGui::GetContentRegionAvail().x - ImGui::CalcTextSize("Load").x -
                          ImGui::GetStyle().FramePadding.x * 2.0f - ImGui::GetStyle().ItemSpacing.x);
  const bool entered = ImGui::InputTextWithHint("##path", "scene file path", &state.scene_path_field,
                                                ImGuiInputTextFlags_EnterReturnsTrue);
  layout::item("scene.path");
  ImGui::SameLine();
  if ((ImGui::Button("Load") || entered) && !state.scene_path_field.empty()) requests.load_scene = state.scene_path_field;
  layout::item("scene.load");
  // A refused file is said on the message line (and the current scene goes on rendering).
  ImGui::TextColored(kDim, "%s, %dx%d", status.scene_name.c_str(), status.width, status.height);

  ImGui::Spacing();
  if (ImGui::SliderInt("Max depth", &settings.max_depth, 1, 100, "%d", ImGuiSliderFlags_AlwaysClamp))
    requests.restart_render = true;
  layout::item("scene.depth");
  const std::uint64_t step = 1;
  if (ImGui::InputScalar("Seed", ImGuiDataType_U64, &settings.seed, &step)) requests.restart_render = true;
  layout::item("scene.seed");

  // At a size set to match a reference the combo says that size, not a scale it is not.
  char current[64];
  if (settings.width_override > 0 && settings.height_override > 0)
    std::snprintf(current, sizeof current, "%dx%d (the reference's)", status.width, status.height);
  else
    std::snprintf(current, sizeof current, "%.0f%%  (%dx%d)", settings.resolution_scale * 100.0, status.width,
                  status.height);
  if (ImGui::BeginCombo("Resolution", current)) {
    for (float scale : kResolutionScales) {
      char label[48];
      std::snprintf(label, sizeof label, "%.0f%%  (%dx%d)", scale * 100.0,
                    std::max(1, static_cast<int>(static_cast<float>(status.base_width) * scale + 0.5f)),
                    std::max(1, static_cast<int>(static_cast<float>(status.base_height) * scale + 0.5f)));
      const bool is_current = scale == settings.resolution_scale && settings.width_override == 0;
      if (ImGui::Selectable(label, is_current) && !is_current) {
        settings.resolution_scale = scale;
        settings.width_override = settings.height_override = 0;
        requests.restart_render = true;
      }
    }
    ImGui::EndCombo();
  }
  layout::item("scene.resolution");

  const std::uint32_t spp_step = 16;
  if (ImGui::InputScalar("Stop at spp", ImGuiDataType_U32, &settings.stop_spp, &spp_step))
    requests.stop_changed = true;
  layout::item("scene.stop_spp");
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("0: never stop. Changing it does not restart.");
  if (ImGui::InputFloat("Stop at seconds", &settings.stop_seconds, 5.0f, 60.0f, "%.0f s")) {
    settings.stop_seconds = std::clamp(settings.stop_seconds, 0.0f, 1e6f);
    requests.stop_changed = true;
  }
  layout::item("scene.stop_seconds");
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("0: no time limit. The render stops at the first pass boundary after this much\n"
                      "rendering time (pauses not counted); whichever stop comes first ends it.");

  if (ImGui::Button(settings.paused ? "Resume (Space)" : "Pause (Space)")) {
    settings.paused = !settings.paused;
    requests.pause_changed = true;
  }
  layout::item("scene.pause");
  ImGui::SameLine();
  if (ImGui::Button("Restart (R)")) requests.restart_render = true;
  layout::item("scene.restart");
  if (ImGui::Button(status.camera_mode ? "Leave camera mode (O)" : "Camera mode (O)")) requests.toggle_camera_mode = true;
  layout::item("scene.camera");
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("Drag orbits, right-drag pans, the wheel dollies");
  ImGui::SameLine();
  ImGui::BeginDisabled(!status.camera_moved);
  if (ImGui::Button("Reset camera (Home)")) requests.reset_camera = true;
  ImGui::EndDisabled();
  layout::item("scene.reset_camera");
}

void display_section(ViewerSettings& settings, const UiStatus& status, UiRequests& requests) {
  ImGui::SliderFloat("Exposure", &settings.exposure_ev, -6.0f, 6.0f, "%+.1f EV");
  if (ImGui::IsItemClicked(ImGuiMouseButton_Right)) settings.exposure_ev = 0.0f;
  int transfer = settings.srgb ? 1 : 0;
  ImGui::RadioButton("gamma 2 (book)", &transfer, 0);
  ImGui::SameLine();
  ImGui::RadioButton("sRGB", &transfer, 1);
  settings.srgb = transfer == 1;
  draw_view_mode_selector(settings);
  layout::item("display.view");
  draw_layer_controls(settings, status.measure);
  char scale[16];
  std::snprintf(scale, sizeof scale, "%.0f%%", settings.ui_scale * 100.0f);
  if (ImGui::BeginCombo("UI scale", scale)) {
    for (float s : kUiScales) {
      std::snprintf(scale, sizeof scale, "%.0f%%", s * 100.0f);
      if (ImGui::Selectable(scale, s == settings.ui_scale)) settings.ui_scale = s;
    }
    ImGui::EndCombo();
  }
  layout::item("display.ui_scale");
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("Larger text for a projector (also: pdflab --ui-scale 1.5)");
  if (ImGui::Button("Presentation mode (F11)")) requests.toggle_presentation = true;
  layout::item("display.presentation");
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("Full screen, the image alone: no panel, badges or inspector. F11 or Esc leaves.");
  ImGui::Checkbox("Caption in presentation mode", &settings.caption);
  layout::item("display.caption");
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("A line under the image for the class: strategy, spp, time");
}

// In the split the main render rests: the two sides are what runs.
void split_statistics(const SplitState& split) {
  ImGui::TextColored(kAmber, "Split screen: A left, B right (S to leave)");
  if (ImGui::BeginTable("split stats", 3, ImGuiTableFlags_SizingStretchProp | ImGuiTableFlags_RowBg)) {
    ImGui::TableSetupColumn("");
    ImGui::TableSetupColumn("A");
    ImGui::TableSetupColumn("B");
    ImGui::TableHeadersRow();
    const auto row = [](const char* label, const std::string& a, const std::string& b) {
      ImGui::TableNextColumn();
      ImGui::TextColored(kDim, "%s", label);
      ImGui::TableNextColumn();
      ImGui::TextWrapped("%s", a.c_str());
      ImGui::TableNextColumn();
      ImGui::TextWrapped("%s", b.c_str());
    };
    const auto num = [](const char* fmt, double v) {
      char buf[48];
      std::snprintf(buf, sizeof buf, fmt, v);
      return std::string(buf);
    };
    const SideFigures &a = split.a, &b = split.b;
    row("strategy", a.strategy + (a.unbiased ? "" : " (biased)"), b.strategy + (b.unbiased ? "" : " (biased)"));
    row("spp", std::to_string(a.spp), std::to_string(b.spp));
    row("elapsed", format_seconds(a.seconds), format_seconds(b.seconds));
    row("samples/s", num("%.3f M", a.samples_per_second * 1e-6), num("%.3f M", b.samples_per_second * 1e-6));
    row("noise", format_figure(a.noise, true), format_figure(b.noise, true));
    row("efficiency", format_figure(a.efficiency()), format_figure(b.efficiency()));
    ImGui::EndTable();
  }
  ImGui::TextColored(kDim, "%d threads a side; the main render rests meanwhile.", split.threads_per_side);
}

void statistics_section(const ViewerSettings& settings, const UiStatus& status) {
  if (status.split) {
    split_statistics(*status.split);
    return;
  }
  const SessionStats& st = status.stats;
  const std::uint64_t dropped = st.dropped.total();
  if (ImGui::BeginTable("stats", 4, ImGuiTableFlags_SizingStretchProp)) {
    share_columns({0.22f, 0.28f, 0.22f, 0.28f});
    stat_cell("spp", "%u%s", st.spp, st.done ? " done" : (st.paused ? " paused" : ""));
    stat_cell("elapsed", "%s", format_seconds(st.seconds).c_str());
    stat_cell("samples/s", "%.3f M", st.samples_per_second * 1e-6);
    stat_cell("per spp", "%s", st.spp > 0 ? format_seconds(st.seconds / st.spp).c_str() : "-");
    stat_cell("samples", "%.3f M", static_cast<double>(st.samples) * 1e-6);
    stat_cell("threads", "%d", status.threads);
    ImGui::TableNextColumn();
    ImGui::TextColored(kDim, "dropped");
    ImGui::TableNextColumn();
    if (dropped == 0) ImGui::TextUnformatted("0");
    else {
      const double percent =
          st.samples ? 100.0 * static_cast<double>(dropped) / static_cast<double>(st.samples) : 0.0;
      if (percent < 0.001) ImGui::TextColored(kAmber, "%llu (<0.001%%)", static_cast<unsigned long long>(dropped));
      else ImGui::TextColored(kAmber, "%llu (%.3f%%)", static_cast<unsigned long long>(dropped), percent);
    }
    stat_cell("UI frame", "%.1f ms", status.frame_ms);
    ImGui::EndTable();
  }
  // Why samples were dropped, one reason each: the DropReason names of the renderer.
  ImGui::TextColored(kDim, "dropped by reason:");
  for (int r = 0; r < kDropReasonCount; ++r) {
    const std::string name(drop_reason_name(static_cast<DropReason>(r)));
    ImGui::TextColored(kDim, "  %s", name.c_str());
    ImGui::SameLine();
    ImGui::Text("%llu", static_cast<unsigned long long>(st.dropped.by_reason[r]));
    if (r + 1 < kDropReasonCount) ImGui::SameLine();
  }
  // Path guiding's training (a strategy with `guided`): where it is, and the trees it learned.
  if (st.guiding_passes > 0) {
    if (st.guiding_pass < st.guiding_passes)
      ImGui::TextColored(kAmber, "path guiding: learning, training pass %d of %d (%u spp, discarded)",
                         st.guiding_pass + 1, st.guiding_passes, 1u << st.guiding_pass);
    else
      ImGui::Text("path guiding: trained in %d passes (%u spp, discarded)", st.guiding_passes,
                  (1u << st.guiding_passes) - 1u);
    ImGui::PushStyleColor(ImGuiCol_Text, kDim);
    ImGui::TextWrapped("  %.1f M records; the SD-tree: %d leaves, %zu quadtree nodes, %d levels deep, %.1f MiB",
                       static_cast<double>(st.guiding_records) * 1e-6, st.guiding.leaves, st.guiding.nodes,
                       st.guiding.max_depth, static_cast<double>(st.guiding.bytes) / (1024.0 * 1024.0));
    ImGui::PopStyleColor();
  }
  if (settings.stop_spp > 0) {
    char overlay[48];
    std::snprintf(overlay, sizeof overlay, "%u / %u spp", st.spp, settings.stop_spp);
    ImGui::ProgressBar(static_cast<float>(st.progress), ImVec2(-1.0f, 0.0f), overlay);
  }
}

void screenshot_section(ViewerSettings& settings, const UiStatus& status, UiRequests& requests) {
  ImGui::InputText("Folder", &settings.screenshot_dir);
  layout::item("shots.folder");
  ImGui::BeginDisabled(status.screenshot_pending);
  if (ImGui::Button(status.screenshot_pending ? "Saving..." : "Save screenshot (F12)")) requests.screenshot = true;
  ImGui::EndDisabled();
  layout::item("shots.screenshot");
  ImGui::SameLine();
  if (status.can_retry_screenshot) {
    if (ImGui::Button("Retry save")) requests.retry_screenshot = true;
  } else if (ImGui::Button("Save film (Ctrl+S)")) {
    requests.save_film = true;
  }
  layout::item("shots.film");
  ImGui::TextColored(kDim, "Figures of what is shown, for a report:");
  ImGui::BeginDisabled(!status.can_export_view);
  if (ImGui::Button("View as PNG (Ctrl+E)")) requests.export_view = true;
  ImGui::EndDisabled();
  layout::item("export.view");
  if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
    ImGui::SetTooltip("The heat map, difference, best-weight or technique-share view as a PNG\n"
                      "with its colour bar and a caption (V picks the view)");
  ImGui::SameLine();
  ImGui::BeginDisabled(!status.can_export_curve);
  if (ImGui::Button("Curve")) requests.export_curve = true;
  ImGui::EndDisabled();
  layout::item("export.curve");
  if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
    ImGui::SetTooltip("The predicted efficiency against w as SVG and CSV");
  ImGui::SameLine();
  ImGui::BeginDisabled(!status.can_export_convergence);
  if (ImGui::Button("Convergence")) requests.export_convergence = true;
  ImGui::EndDisabled();
  layout::item("export.convergence");
  if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
    ImGui::SetTooltip("The convergence plot's curves (pins and the running one) as SVG and CSV");
  // Saves and exports report on the message line (and over the image).
}

// The panel's head, which never scrolls: where the render stands, its headline
// figure (measured, rough or estimated) and the message line, all one line
// each, so nothing below moves when they change.
void summary_header(const ViewerSettings& settings, const UiStatus& status, UiRequests& requests) {
  const SessionStats& st = status.stats;
  char line[160];
  if (status.split) {
    std::snprintf(line, sizeof line, "split: A %u spp, B %u spp", status.split->a.spp, status.split->b.spp);
  } else {
    std::snprintf(line, sizeof line, "%u spp   %s   %.2f M samples/s%s", st.spp, format_seconds(st.seconds).c_str(),
                  st.samples_per_second * 1e-6, st.done ? "   done" : (st.paused || settings.paused ? "   paused" : ""));
    // Path guiding's training passes, before the first kept sample.
    if (st.guiding_pass < st.guiding_passes)
      std::snprintf(line, sizeof line, "guiding: learning, pass %d of %d   %s", st.guiding_pass + 1, st.guiding_passes,
                    format_seconds(st.seconds).c_str());
  }
  one_line(line, ImVec4(0.92f, 0.92f, 0.95f, 1.0f));
  layout::item("summary.render");
  // Hide the panel: the button at the head's right end.
  const float hide_w = ImGui::CalcTextSize(">>").x + ImGui::GetStyle().FramePadding.x * 2.0f;
  ImGui::SameLine(std::max(0.0f, ImGui::GetWindowContentRegionMax().x - hide_w));
  if (ImGui::SmallButton(">>")) requests.toggle_panel = true;
  layout::item("panel.hide");
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("Hide the panel (Tab); drag its left edge to resize it");

  const Figures* f = status.measure ? &status.measure->figures : nullptr;
  if (!f || !f->valid) {
    one_line("figures after the first full pass", kDim);
  } else if (f->against_reference && f->rough_reference) {
    std::snprintf(line, sizeof line, "relMSE %.3g ROUGH: the reference's noise is %.0f%% of it", f->relmse,
                  100.0 * f->reference_share);
    one_line(line, kAmber);
  } else if (f->against_reference) {
    std::snprintf(line, sizeof line, "relMSE %.3g +- %.2g measured, efficiency %.3g", f->relmse, f->relmse_interval,
                  f->efficiency);
    one_line(line, kGreen);
  } else {
    if (f->unbiased)
      std::snprintf(line, sizeof line, "relMSE %.3g estimated, efficiency %.3g est.%s", f->estimated_relmse,
                    f->estimated_efficiency, f->estimate_unreliable ? ", unreliable" : "");
    else
      std::snprintf(line, sizeof line, "relMSE %.3g estimated (biased: no efficiency)", f->estimated_relmse);
    one_line(line, kAmber);
  }
  layout::item("summary.figures");

  // The message line: the most pressing message, all of them in its tooltip.
  if (status.messages.empty()) {
    one_line("H: keys and help   Tab: hide the panel", kDim);
  } else {
    const PanelMessage& m = status.messages.front();
    std::string all;
    for (std::size_t i = 1; i < status.messages.size(); ++i) all += (all.empty() ? "" : "\n") + status.messages[i].text;
    one_line(m.text, m.kind == PanelMessage::Error ? kRed : (m.kind == PanelMessage::Warning ? kAmber : kGreen),
             all.empty() ? nullptr : all.c_str());
  }
  layout::item("summary.message");
  ImGui::Separator();
}

}  // namespace

void draw_side_panel(const Box& box, ViewerSettings& settings, PanelState& state, const UiStatus& status,
                     UiRequests& requests) {
  if (!state.scene_field_initialised) {
    state.scene_path_field = status.scene_path;
    state.scene_field_initialised = true;
  }
  ImGui::SetNextWindowPos(ImVec2(box.x, box.y));
  ImGui::SetNextWindowSize(ImVec2(box.w, box.h));
  // Behind every other window, always: it is the background the views open over.
  const ImGuiWindowFlags flags = ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse |
                                 ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoTitleBar |
                                 ImGuiWindowFlags_NoBringToFrontOnFocus | ImGuiWindowFlags_NoScrollbar |
                                 ImGuiWindowFlags_NoScrollWithMouse;
  // The viewer clears the panel's rectangle itself (kPanelBackground): a
  // full-height filled quad is the costliest thing ImGui draws on a software
  // rasteriser, a clear costs next to nothing.
  ImGui::PushStyleColor(ImGuiCol_WindowBg, ImVec4(0.0f, 0.0f, 0.0f, 0.0f));
  ImGui::Begin("pdflab", nullptr, flags);
  ImGui::PopStyleColor();
  layout::region("panel", box);
  summary_header(settings, status, requests);
  // The sections scroll under the head.
  ImGui::PushStyleColor(ImGuiCol_ChildBg, ImVec4(0.0f, 0.0f, 0.0f, 0.0f));
  ImGui::BeginChild("##sections", ImVec2(0.0f, 0.0f), false);
  ImGui::PopStyleColor();
  layout::region("panel.sections", {ImGui::GetWindowPos().x, ImGui::GetWindowPos().y, ImGui::GetWindowSize().x,
                                    ImGui::GetWindowSize().y});
  ImGui::PushItemWidth(ImGui::GetContentRegionAvail().x * 0.62f);
  for (int i = 0; i < kPanelSectionCount; ++i) {
    ImGui::SetNextItemOpen(state.open[static_cast<std::size_t>(i)], ImGuiCond_Always);
    const bool open = ImGui::CollapsingHeader(kPanelSections[static_cast<std::size_t>(i)]);
    state.open[static_cast<std::size_t>(i)] = open;
    char name[32];
    std::snprintf(name, sizeof name, "section.%d", i);
    layout::item(name);
    if (!open) continue;
    switch (i) {
      case 0: sampling_section(settings, state, status, requests); break;
      case 1: scene_section(settings, state, status, requests); break;
      case 2: statistics_section(settings, status); break;
      case 3: draw_measure_section(settings, status, requests); break;
      case 4: display_section(settings, status, requests); break;
      default: screenshot_section(settings, status, requests); break;
    }
  }
  ImGui::PopItemWidth();
  ImGui::Spacing();
  if (ImGui::Button("Help (H)")) state.show_help = !state.show_help;
  layout::item("panel.help");
  ImGui::EndChild();
  ImGui::End();
}

float draw_panel_edge(const Box& panel, float scale, float window_width, ViewerSettings& settings) {
  // A strip over the panel's left edge: drag to resize, double-click for the default width.
  const float grip = std::max(6.0f, 4.0f * scale);
  ImGui::SetNextWindowPos(ImVec2(panel.x - grip * 0.5f, panel.y));
  ImGui::SetNextWindowSize(ImVec2(grip, panel.h));
  const ImGuiWindowFlags flags = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoSavedSettings |
                                 ImGuiWindowFlags_NoBackground | ImGuiWindowFlags_NoFocusOnAppearing |
                                 ImGuiWindowFlags_NoNav;
  ImGui::PushStyleVar(ImGuiStyleVar_WindowPadding, ImVec2(0.0f, 0.0f));
  ImGui::PushStyleVar(ImGuiStyleVar_WindowMinSize, ImVec2(1.0f, 1.0f));  // the grip's width, not ImGui's smallest window
  ImGui::Begin("##panel edge", nullptr, flags);
  ImGui::PopStyleVar(2);
  ImGui::InvisibleButton("##splitter", ImVec2(grip, panel.h));
  layout::item("panel.splitter");
  const bool active = ImGui::IsItemActive(), hovered = ImGui::IsItemHovered();
  if (active || hovered) ImGui::SetMouseCursor(ImGuiMouseCursor_ResizeEW);
  if (hovered && ImGui::IsMouseDoubleClicked(ImGuiMouseButton_Left)) settings.panel_width = kDefaultPanelWidth;
  float width = panel.w;
  if (active) {
    const float right = panel.x + panel.w;
    width = std::clamp(right - ImGui::GetIO().MousePos.x, kMinPanelWidth * scale, kMaxPanelShare * window_width);
    settings.panel_width = width / scale;
  }
  const float x = panel.x;
  ImGui::GetWindowDrawList()->AddLine(ImVec2(x, panel.y), ImVec2(x, panel.y + panel.h),
                                      active ? IM_COL32(255, 200, 90, 255)
                                             : (hovered ? IM_COL32(200, 200, 210, 255) : IM_COL32(70, 70, 80, 255)),
                                      active || hovered ? 3.0f : 1.0f);
  ImGui::End();
  return width;
}

void draw_panel_tab(UiRequests& requests) {
  // While the panel is hidden: a small tab at the top right to bring it back,
  // placed first among the boxes over the image.
  layout::Overlay o;
  o.corner = Corner::TopRight;
  o.width = ImGui::CalcTextSize("<< panel").x + 2.0f * (ImGui::GetStyle().FramePadding.x + ImGui::GetStyle().WindowPadding.x);
  o.height = ImGui::GetFrameHeight() + 2.0f * ImGui::GetStyle().WindowPadding.y;
  o.min_width = 4.0f;
  if (!layout::place_next_window("##panel tab", o)) return;
  ImGui::SetNextWindowBgAlpha(0.6f);
  const ImGuiWindowFlags flags = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize |
                                 ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoFocusOnAppearing |
                                 ImGuiWindowFlags_NoNav | ImGuiWindowFlags_NoMove;
  if (ImGui::Begin("##panel tab", nullptr, flags)) {
    if (ImGui::SmallButton("<< panel")) requests.toggle_panel = true;
    layout::item("panel.show");
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("Show the panel (Tab)");
  }
  ImGui::End();
}

void draw_help_overlay(PanelState& state, float area_width, float area_height) {
  if (!state.show_help) return;
  ImGui::SetNextWindowPos(ImVec2(area_width * 0.5f, area_height * 0.5f), ImGuiCond_Always, ImVec2(0.5f, 0.5f));
  ImGui::SetNextWindowBgAlpha(0.9f);
  // Never taller than the window: it scrolls instead.
  ImGui::SetNextWindowSizeConstraints(ImVec2(0.0f, 0.0f), ImVec2(std::max(200.0f, area_width - 20.0f),
                                                                  std::max(200.0f, area_height - 20.0f)));
  const ImGuiWindowFlags flags = ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoMove |
                                 ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoCollapse;
  if (ImGui::Begin("Keys", &state.show_help, flags)) {
    std::string views;
    for (int i = 0; i < kViewModeCount; ++i)
      views += std::string(i ? ", " : "") + view_mode_label(static_cast<ViewMode>(i));
    const std::string view_line = "next view: " + views;
    const std::string keys[][2] = {
        {"Space", "pause / resume"},
        {"R", "restart the accumulation"},
        {"1", "preset: cosine only"},
        {"2", "preset: light only"},
        {"3", "preset: book 50/50 (cosine + light)"},
        {"4", "next-event estimation (nee-mis)"},
        {"5", "fastest (nee-mis with a mixture, Sobol, roulette)"},
        {"V", view_line},
        {"E, Shift+E", "next, previous error metric of the heat map or difference view"},
        {"G", "show / hide the convergence plot (graph)"},
        {"K", "keep (pin) the running convergence curve"},
        {"M", "make a reference (Measure section; M again cancels)"},
        {"F12", "screenshot: PNG + PFM + JSON"},
        {"Ctrl+S", "save the film (continue it with --resume)"},
        {"Ctrl+E", "export the view as a PNG figure with its legend"},
        {"S", "split screen A/B: two strategies, equal time"},
        {"P", "pixel probe: click a pixel (C: chi-square)"},
        {"L", "1D lab: f, p, inverse CDF, pi"},
        {"D", "2D lab: an environment map's marginal and conditional CDFs"},
        {"wheel", "zoom about the cursor (+ and - about the centre)"},
        {"drag", "pan (right or middle button; left outside probe mode)"},
        {"Z, F", "one image pixel per screen pixel; fit the window"},
        {"Ctrl+C", "copy the pixel inspector's values"},
        {"Tab", "hide / show the side panel (drag its edge to resize)"},
        {"F11", "presentation mode: full screen, the image alone"},
        {"O", "camera mode: drag orbits, right-drag pans, wheel dollies"},
        {"Home", "back to the scene's camera"},
        {"H, F1", "this help"},
        {"Esc", "close a drop-down, cancel an edit, leave probe mode"},
        {"Ctrl+Q", "quit (asks first when a render is unsaved)"},
    };
    const float column = ImGui::GetFontSize() * 6.0f;
    ImGui::PushTextWrapPos(std::min(ImGui::GetFontSize() * 34.0f, area_width - 40.0f));
    for (const auto& k : keys) {
      ImGui::TextColored(kAmber, "%s", k[0].c_str());
      ImGui::SameLine(column);
      ImGui::TextWrapped("%s", k[1].c_str());
    }
    ImGui::Separator();
    ImGui::TextWrapped("Keys do nothing while a text field is being edited. Any change to sampling, scene or render "
                       "settings restarts the accumulation at once.");
    ImGui::PopTextWrapPos();
  }
  ImGui::End();
}

namespace {

constexpr ImGuiWindowFlags kOverlayFlags = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize |
                                           ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoFocusOnAppearing |
                                           ImGuiWindowFlags_NoNav | ImGuiWindowFlags_NoInputs;

// A one-box overlay of text lines in `corner`; false when there was no room.
bool text_overlay(const char* name, Corner corner, const std::vector<std::pair<std::string, ImVec4>>& lines,
                  float alpha) {
  float natural = 0.0f;
  for (const auto& [text, colour] : lines) natural = std::max(natural, ImGui::CalcTextSize(text.c_str()).x);
  float wrap = 0.0f;
  layout::Overlay o;
  o.corner = corner;
  o.width = natural + 2.0f * ImGui::GetStyle().WindowPadding.x;
  o.height = layout::text_height(static_cast<int>(lines.size()));
  o.min_width = 6.0f;
  if (!layout::place_next_window(name, o, &wrap)) return false;
  ImGui::SetNextWindowBgAlpha(alpha);
  if (ImGui::Begin(name, nullptr, kOverlayFlags)) {
    ImGui::PushTextWrapPos(ImGui::GetCursorPosX() + wrap);
    for (const auto& [text, colour] : lines) {
      ImGui::PushStyleColor(ImGuiCol_Text, colour);
      ImGui::TextWrapped("%s", text.c_str());
      ImGui::PopStyleColor();
    }
    ImGui::PopTextWrapPos();
  }
  ImGui::End();
  return true;
}

}  // namespace

void draw_image_badges(const ViewerSettings& settings, const UiStatus& status) {
  std::string text;
  if (status.showing_preview) text = "preview";
  else if (settings.paused) text = "paused";
  else if (status.stats.done) text = "done";
  const Strategy strategy = settings.sampling.strategy();
  if (!strategy.is_unbiased())
    text += (text.empty() ? "biased: " : "  |  biased: ") + strategy.bias_reason();
  if (text.empty()) return;
  text_overlay("##badges", Corner::TopLeft, {{text, kAmber}}, 0.6f);
}

void draw_hint(const char* text) { text_overlay("##hint", Corner::TopLeft, {{text, kAmber}}, 0.7f); }

void draw_notice_toast(const Notice& notice) {
  text_overlay("##notice", Corner::BottomRight, {{notice.text, notice.error ? kRed : kGreen}}, 0.85f);
}

void draw_caption(const ViewerSettings& settings, const UiStatus& status) {
  const SessionStats& st = status.stats;
  char line[96];
  std::snprintf(line, sizeof line, "%u spp   %s", st.spp, format_seconds(st.seconds).c_str());
  text_overlay("##caption", Corner::BottomLeft,
               {{settings.sampling.strategy().to_string(), ImVec4(1.0f, 1.0f, 1.0f, 1.0f)},
                {line, ImVec4(0.85f, 0.85f, 0.88f, 1.0f)}},
               0.7f);
}

QuitChoice draw_quit_dialog(bool asking, double unsaved_seconds, bool saving, const Notice& notice) {
  // A modal popup: ImGui dims the rest and lets nothing else take the mouse,
  // and its buttons keep the clicks they get (a window focused anew every
  // frame would drop a press before its release).
  constexpr const char* kTitle = "Quit pdflab?";
  if (asking && !ImGui::IsPopupOpen(kTitle)) ImGui::OpenPopup(kTitle);
  const ImGuiViewport* vp = ImGui::GetMainViewport();
  ImGui::SetNextWindowPos(ImVec2(vp->Pos.x + vp->Size.x * 0.5f, vp->Pos.y + vp->Size.y * 0.5f), ImGuiCond_Always,
                          ImVec2(0.5f, 0.5f));
  QuitChoice choice = QuitChoice::None;
  const ImGuiWindowFlags flags = ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoMove |
                                 ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoCollapse;
  if (!ImGui::BeginPopupModal(kTitle, nullptr, flags)) return choice;
  if (!asking) {
    ImGui::CloseCurrentPopup();
    ImGui::EndPopup();
    return choice;
  }
  ImGui::Text("This render has run %.0f s since it was last saved;", unsaved_seconds);
  ImGui::Text("quitting loses it.");
  if (notice.error && !notice.text.empty()) {
    ImGui::PushTextWrapPos(ImGui::GetFontSize() * 28.0f);
    ImGui::TextColored(kRed, "%s", notice.text.c_str());
    ImGui::PopTextWrapPos();
  }
  ImGui::Spacing();
  ImGui::BeginDisabled(saving);
  if (ImGui::Button(saving ? "Saving..." : "Save screenshot, then quit")) choice = QuitChoice::SaveAndQuit;
  ImGui::EndDisabled();
  layout::item("quit.save");
  ImGui::SameLine();
  if (ImGui::Button("Quit anyway (Ctrl+Q)")) choice = QuitChoice::Quit;
  layout::item("quit.quit");
  ImGui::SameLine();
  if (ImGui::Button("Cancel (Esc)")) choice = QuitChoice::Cancel;
  layout::item("quit.cancel");
  if (choice == QuitChoice::Cancel || choice == QuitChoice::Quit) ImGui::CloseCurrentPopup();
  ImGui::EndPopup();
  return choice;
}

}  // namespace pdflab::ui
