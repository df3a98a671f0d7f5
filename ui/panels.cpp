#include "ui/panels.h"
#include "ui/style.h"

#include "renderer/integrator/integrator.h"
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

// Beside the w slider: the efficiency predicted at every w from the paths
// drawn so far, the predicted best marked, a button that moves the slider
// there, auto weight and its history, and why the sampling weight keeps away
// from 0 and 1 while predicting.
void draw_weight_curve(ViewerSettings& settings, const WeightCurveStatus& c, int a, int b) {
  SamplingSettings& s = settings.sampling;
  const std::string name_a(technique_name(static_cast<Technique>(a))), name_b(technique_name(static_cast<Technique>(b)));
  if (!c.active) {
    ImGui::TextColored(kDim, "Predicted efficiency: %s", c.why.c_str());
  } else {
    ImGui::TextColored(kDim, "Predicted efficiency against w (%llu paths)", static_cast<unsigned long long>(c.paths));
    const float width = ImGui::GetContentRegionAvail().x, height = ImGui::GetFontSize() * 5.0f;
    const ImVec2 p0 = ImGui::GetCursorScreenPos();
    ImGui::PlotLines("##predicted", c.relative_efficiency.data(), static_cast<int>(c.relative_efficiency.size()), 0,
                     nullptr, 0.0f, 1.05f, ImVec2(width, height));
    const auto heavy = [&](std::size_t i) { return i < c.largest_share.size() && c.largest_share[i] > c.dominant_share; };
    if (ImGui::IsItemHovered()) {
      const float t = std::clamp((ImGui::GetIO().MousePos.x - p0.x) / width, 0.0f, 1.0f);
      const std::size_t i = static_cast<std::size_t>(std::lround(t * static_cast<float>(c.weight.size() - 1)));
      if (heavy(i))
        ImGui::SetTooltip("w = %.2f: %.0f%% of the best, likely too high (one path carries %.0f%% of the moment)",
                          c.weight[i], 100.0f * c.relative_efficiency[i], 100.0f * c.largest_share[i]);
      else
        ImGui::SetTooltip("w = %.2f: %.0f%% of the best", c.weight[i], 100.0f * c.relative_efficiency[i]);
    }
    // Grey over the weights whose prediction one path dominates, the predicted
    // best (amber) and the weight the paths came from (white).
    ImDrawList* dl = ImGui::GetWindowDrawList();
    bool any_heavy = false;
    const float step = c.weight.size() > 1 ? width / static_cast<float>(c.weight.size() - 1) : width;
    for (std::size_t i = 0; i < c.weight.size(); ++i)
      if (heavy(i)) {
        any_heavy = true;
        const float x = p0.x + static_cast<float>(i) * step;
        dl->AddRectFilled(ImVec2(std::max(p0.x, x - 0.5f * step), p0.y), ImVec2(std::min(p0.x + width, x + 0.5f * step), p0.y + height),
                          IM_COL32(150, 150, 150, 110));
      }
    const auto mark = [&](double w, ImU32 colour, float thickness) {
      const float x = p0.x + static_cast<float>(w) * width;
      dl->AddLine(ImVec2(x, p0.y), ImVec2(x, p0.y + height), colour, thickness);
    };
    if (c.sampling >= 0.0) mark(c.sampling, IM_COL32(230, 230, 230, 200), 1.0f);
    if (c.best >= 0.0) mark(c.best, IM_COL32(255, 190, 60, 255), 2.0f);
    if (any_heavy) {
      ImGui::TextColored(kDim, "grey: one path dominates, likely too high");
      if (ImGui::IsItemHovered())
        ImGui::SetTooltip("There a single path carries more than %.0f%% of the predicted second moment. With a\n"
                          "finite moment that share falls as paths are added; where it stays large the moment is\n"
                          "infinite or carried by paths too rare for the samples so far, so the predicted variance\n"
                          "is too low and the efficiency too high. A render there has the same trouble: its error\n"
                          "falls slower than 1/N.",
                          100.0 * static_cast<double>(c.dominant_share));
    }
    ImGui::TextColored(kAmber, "predicted best w = %.2f", c.best);
    ImGui::SameLine();
    if (ImGui::Button("Use the best weight") && c.best >= 0.0) {
      s.weights[a] = static_cast<float>(c.best);
      s.weights[b] = 1.0f - static_cast<float>(c.best);
    }
    if (c.fixed_cost_rays >= 0.0) {
      ImGui::TextColored(kDim, "a sample costs its rays + %.1f rays (%s)", c.fixed_cost_rays,
                         c.cost_fitted ? "fitted to the passes' times" : "prior");
      if (ImGui::IsItemHovered())
        ImGui::SetTooltip("Time per sample = fixed cost + cost per ray x rays. The fixed cost (the camera ray's set-up,\n"
                          "the film, the pass's bookkeeping) is fitted to auto weight's passes once their rays differ\n"
                          "enough; until then it is a prior.");
    }
  }
  ImGui::Checkbox("Auto weight", &settings.auto_weight);
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("Between passes (at 16, 32, 64, ... spp) w moves to the best the passes so far predict;\n"
                      "each pass's weight is fixed before it starts, so the accumulated image stays unbiased.");
  if (!c.history.empty()) {
    ImGui::SameLine();
    std::string h;
    for (std::size_t i = c.history.size() > 6 ? c.history.size() - 6 : 0; i < c.history.size(); ++i) {
      char buf[16];
      std::snprintf(buf, sizeof buf, "%s%.2f", h.empty() ? "" : " > ", c.history[i]);
      h += buf;
    }
    ImGui::TextColored(kDim, "w: %s", h.c_str());
    ImGui::PlotLines("##history", c.history.data(), static_cast<int>(c.history.size()), 0, nullptr, 0.0f, 1.0f,
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
    if (!Strategy::single(t).is_unbiased()) name += "   (biased alone)";
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
void pair_weight_slider(ViewerSettings& settings, PanelState& state, const UiStatus& status) {
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
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("Ctrl+click to type an exact value");
  draw_weight_curve(settings, status.weights, a, b);
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
  bool any = false;
  for (float w : s.weights) any = any || w > 0.0f;
  if (!any) ImGui::TextColored(kRed, "All weights are 0: the image keeps the last valid mixture.");
}

// The presets' buttons in a row that wraps where the panel ends.
void preset_buttons(SamplingSettings& s) {
  const ImGuiStyle& style = ImGui::GetStyle();
  const float right = ImGui::GetWindowPos().x + ImGui::GetWindowContentRegionMax().x;
  const auto flow_button = [&](const char* label, bool first) {
    const float w = ImGui::CalcTextSize(label).x + style.FramePadding.x * 2.0f;
    if (!first && ImGui::GetItemRectMax().x + style.ItemSpacing.x + w <= right) ImGui::SameLine();
    return ImGui::Button(label);
  };
  for (int p = 1; p <= kPresetCount; ++p) {
    char label[48];
    std::snprintf(label, sizeof label, "%d: %s", p, preset_label(static_cast<Preset>(p)));
    if (flow_button(label, p == 1)) s = preset_sampling(static_cast<Preset>(p));
  }
  if (flow_button("4: nee-mis", false)) s = SamplingSettings::from(Strategy::nee());
  if (flow_button("fastest", false)) s = fastest_sampling();
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("pdflab's most efficient unbiased strategy for general scenes: %s", kFastestStrategy.data());
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
  }
  ImGui::Checkbox("Sobol sampler", &s.sobol);
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("Owen-scrambled Sobol points for %s random numbers, stratified\n"
                      "across each pixel's samples (+sobol); off: every number independent",
                      stratified_vertices().c_str());
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
    ImGui::TextWrapped("Its pdf is zero away from the importance targets, so indirect light is missing.");
    ImGui::PopStyleColor();
  }
}

// The Sampling section, in the order it reads: the strategy, its parameters,
// its weights, the presets, the path options, the strategy as text; any edit
// restarts the render.
void sampling_section(ViewerSettings& settings, PanelState& state, const UiStatus& status, UiRequests& requests) {
  SamplingSettings& s = settings.sampling;
  const SamplingSettings before = s;
  strategy_combo(s);
  technique_parameters(s);
  if (s.nee_mis) draw_nee_explanation();
  if (s.mixture && !s.nee_mis) {
    pair_weight_slider(settings, state, status);
    mixture_weights(s);
  }
  preset_buttons(s);
  path_options(s);
  strategy_line(s);
  if (!status.settings_error.empty()) {
    ImGui::PushStyleColor(ImGuiCol_Text, kRed);
    ImGui::TextWrapped("%s", status.settings_error.c_str());
    ImGui::PopStyleColor();
  }
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
  ImGui::SetNextItemWidth(ImGui::GetContentRegionAvail().x - ImGui::CalcTextSize("Load").x -
                          ImGui::GetStyle().FramePadding.x * 2.0f - ImGui::GetStyle().ItemSpacing.x);
  const bool entered = ImGui::InputTextWithHint("##path", "scene file path", &state.scene_path_field,
                                                ImGuiInputTextFlags_EnterReturnsTrue);
  ImGui::SameLine();
  if ((ImGui::Button("Load") || entered) && !state.scene_path_field.empty()) requests.load_scene = state.scene_path_field;
  ImGui::TextColored(kDim, "%s, %dx%d", status.scene_name.c_str(), status.width, status.height);
  if (!status.scene_error.empty()) {
    ImGui::PushStyleColor(ImGuiCol_Text, kRed);
    ImGui::TextWrapped("%s", status.scene_error.c_str());
    ImGui::PopStyleColor();
  }

  ImGui::Spacing();
  if (ImGui::SliderInt("Max depth", &settings.max_depth, 1, 100, "%d", ImGuiSliderFlags_AlwaysClamp))
    requests.restart_render = true;
  const std::uint64_t step = 1;
  if (ImGui::InputScalar("Seed", ImGuiDataType_U64, &settings.seed, &step)) requests.restart_render = true;

  char current[48];
  std::snprintf(current, sizeof current, "%.0f%%  (%dx%d)", settings.resolution_scale * 100.0, status.width,
                status.height);
  if (ImGui::BeginCombo("Resolution", current)) {
    for (float scale : kResolutionScales) {
      char label[48];
      std::snprintf(label, sizeof label, "%.0f%%  (%dx%d)", scale * 100.0,
                    std::max(1, static_cast<int>(static_cast<float>(status.base_width) * scale + 0.5f)),
                    std::max(1, static_cast<int>(static_cast<float>(status.base_height) * scale + 0.5f)));
      if (ImGui::Selectable(label, scale == settings.resolution_scale) &&
          (scale != settings.resolution_scale || settings.width_override > 0)) {
        settings.resolution_scale = scale;
        settings.width_override = settings.height_override = 0;
        requests.restart_render = true;
      }
    }
    ImGui::EndCombo();
  }

  const std::uint32_t spp_step = 16;
  if (ImGui::InputScalar("Stop at spp", ImGuiDataType_U32, &settings.stop_spp, &spp_step))
    requests.stop_changed = true;
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("0: never stop. Changing it does not restart.");

  if (ImGui::Button(settings.paused ? "Resume (Space)" : "Pause (Space)")) {
    settings.paused = !settings.paused;
    requests.pause_changed = true;
  }
  ImGui::SameLine();
  if (ImGui::Button("Restart (R)")) requests.restart_render = true;
  if (ImGui::Button(status.camera_mode ? "Leave camera mode (O)" : "Camera mode (O)")) requests.toggle_camera_mode = true;
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("Drag orbits, right-drag pans, the wheel dollies");
  ImGui::SameLine();
  ImGui::BeginDisabled(!status.camera_moved);
  if (ImGui::Button("Reset camera (Home)")) requests.reset_camera = true;
  ImGui::EndDisabled();
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
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("Larger text for a projector (also: pdflab --ui-scale 1.5)");
  if (ImGui::Button("Presentation mode (F11)")) requests.toggle_presentation = true;
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("Full screen, the image alone: no panel, badges or inspector. F11 or Esc leaves.");
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
  if (settings.stop_spp > 0) {
    char overlay[48];
    std::snprintf(overlay, sizeof overlay, "%u / %u spp", st.spp, settings.stop_spp);
    ImGui::ProgressBar(static_cast<float>(st.progress), ImVec2(-1.0f, 0.0f), overlay);
  }
}

void screenshot_section(ViewerSettings& settings, const UiStatus& status, UiRequests& requests) {
  ImGui::InputText("Folder", &settings.screenshot_dir);
  ImGui::BeginDisabled(status.screenshot_pending);
  if (ImGui::Button(status.screenshot_pending ? "Saving..." : "Save screenshot (F12)")) requests.screenshot = true;
  ImGui::EndDisabled();
  if (status.can_retry_screenshot) {
    ImGui::SameLine();
    if (ImGui::Button("Retry save")) requests.retry_screenshot = true;
  }
  if (!status.notice.text.empty()) {
    ImGui::PushStyleColor(ImGuiCol_Text, status.notice.error ? kRed : kGreen);
    ImGui::TextWrapped("%s", status.notice.text.c_str());
    ImGui::PopStyleColor();
  }
}

}  // namespace

void draw_side_panel(float width, float display_height, ViewerSettings& settings, PanelState& state,
                     const UiStatus& status, UiRequests& requests) {
  if (!state.scene_field_initialised) {
    state.scene_path_field = status.scene_path;
    state.scene_field_initialised = true;
  }
  const ImGuiViewport* vp = ImGui::GetMainViewport();
  ImGui::SetNextWindowPos(ImVec2(vp->Pos.x + vp->Size.x - width, vp->Pos.y));
  ImGui::SetNextWindowSize(ImVec2(width, display_height));
  // Behind every other window, always: it is the background the views open over.
  const ImGuiWindowFlags flags = ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse |
                                 ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoTitleBar |
                                 ImGuiWindowFlags_NoBringToFrontOnFocus;
  // The viewer clears the panel's rectangle itself (kPanelBackground): a
  // full-height filled quad is the costliest thing ImGui draws on a software
  // rasteriser, a clear costs next to nothing.
  ImGui::PushStyleColor(ImGuiCol_WindowBg, ImVec4(0.0f, 0.0f, 0.0f, 0.0f));
  ImGui::Begin("pdflab", nullptr, flags);
  ImGui::PopStyleColor();
  ImGui::PushItemWidth(ImGui::GetContentRegionAvail().x * 0.62f);
  if (ImGui::CollapsingHeader("Sampling", ImGuiTreeNodeFlags_DefaultOpen)) sampling_section(settings, state, status, requests);
  if (ImGui::CollapsingHeader("Scene and render", ImGuiTreeNodeFlags_DefaultOpen))
    scene_section(settings, state, status, requests);
  if (ImGui::CollapsingHeader("Statistics", ImGuiTreeNodeFlags_DefaultOpen)) statistics_section(settings, status);
  if (ImGui::CollapsingHeader("Measure", ImGuiTreeNodeFlags_DefaultOpen)) draw_measure_section(settings, status, requests);
  if (ImGui::CollapsingHeader("Display", ImGuiTreeNodeFlags_DefaultOpen)) display_section(settings, status, requests);
  if (ImGui::CollapsingHeader("Screenshot", ImGuiTreeNodeFlags_DefaultOpen))
    screenshot_section(settings, status, requests);
  ImGui::PopItemWidth();
  ImGui::Spacing();
  if (ImGui::Button("Help (H)")) state.show_help = !state.show_help;
  ImGui::End();
}

void draw_help_overlay(PanelState& state, float area_width, float area_height) {
  if (!state.show_help) return;
  ImGui::SetNextWindowPos(ImVec2(area_width * 0.5f, area_height * 0.5f), ImGuiCond_Always, ImVec2(0.5f, 0.5f));
  ImGui::SetNextWindowBgAlpha(0.9f);
  const ImGuiWindowFlags flags = ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoMove |
                                 ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoCollapse;
  if (ImGui::Begin("Keys", &state.show_help, flags)) {
    static constexpr const char* kKeys[][2] = {
        {"Space", "pause / resume"},
        {"R", "restart the accumulation"},
        {"1", "preset: cosine only"},
        {"2", "preset: light only"},
        {"3", "preset: book 50/50 (cosine + light)"},
        {"4", "next-event estimation (nee-mis)"},
        {"V", "next view: image, noise heat map, difference, drops"},
        {"E, Shift+E", "next, previous error metric of the heat map or difference view"},
        {"G", "show / hide the convergence plot (graph)"},
        {"K", "keep (pin) the running convergence curve"},
        {"M", "make a reference (Measure section; M again cancels)"},
        {"F12", "screenshot: PNG + PFM + JSON"},
        {"S", "split screen A/B: two strategies, equal time"},
        {"P", "pixel probe: click a pixel (C: chi-square)"},
        {"L", "1D lab: f, p, inverse CDF, pi"},
        {"wheel", "zoom about the cursor (+ and - about the centre)"},
        {"drag", "pan (right or middle button; left outside probe mode)"},
        {"Z, F", "one image pixel per screen pixel; fit the window"},
        {"Ctrl+C", "copy the pixel inspector's values"},
        {"F11", "presentation mode: full screen, the image alone"},
        {"O", "camera mode: drag orbits, right-drag pans, wheel dollies"},
        {"Home", "back to the scene's camera"},
        {"H, F1", "this help"},
        {"Esc", "close a drop-down, cancel an edit, leave probe mode"},
        {"Ctrl+Q", "quit (asks first when a render is unsaved)"},
    };
    for (const auto& k : kKeys) {
      ImGui::TextColored(kAmber, "%s", k[0]);
      ImGui::SameLine(ImGui::GetFontSize() * 5.0f);
      ImGui::TextUnformatted(k[1]);
    }
    ImGui::Separator();
    ImGui::TextColored(kDim, "Any change to sampling, scene or render settings\nrestarts the accumulation at once.");
  }
  ImGui::End();
}

ImVec2 draw_image_badges(const ViewerSettings& settings, const UiStatus& status) {
  std::string text;
  if (status.showing_preview) text = "preview";
  else if (settings.paused) text = "paused";
  if (!settings.sampling.strategy().is_unbiased()) text += text.empty() ? "biased strategy" : "  |  biased strategy";
  if (text.empty()) return ImVec2(0.0f, 0.0f);
  const ImGuiViewport* vp = ImGui::GetMainViewport();
  ImGui::SetNextWindowPos(ImVec2(vp->Pos.x + 8.0f, vp->Pos.y + 8.0f));
  ImGui::SetNextWindowBgAlpha(0.6f);
  const ImGuiWindowFlags flags = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize |
                                 ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoFocusOnAppearing |
                                 ImGuiWindowFlags_NoNav | ImGuiWindowFlags_NoInputs;
  ImVec2 corner(0.0f, 0.0f);
  if (ImGui::Begin("##badges", nullptr, flags)) {
    ImGui::TextColored(kAmber, "%s", text.c_str());
    // The window's size settles on its first frame; the text's own extent is
    // known at once.
    const ImVec2 pad = ImGui::GetStyle().WindowPadding;
    corner = ImVec2(ImGui::GetItemRectMax().x + pad.x, ImGui::GetItemRectMax().y + pad.y);
  }
  ImGui::End();
  return corner;
}

void draw_hint(const char* text) {
  const ImGuiViewport* vp = ImGui::GetMainViewport();
  ImGui::SetNextWindowPos(ImVec2(vp->Pos.x + vp->Size.x * 0.5f, vp->Pos.y + 12.0f), ImGuiCond_Always, ImVec2(0.5f, 0.0f));
  ImGui::SetNextWindowBgAlpha(0.7f);
  const ImGuiWindowFlags flags = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize |
                                 ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoFocusOnAppearing |
                                 ImGuiWindowFlags_NoNav | ImGuiWindowFlags_NoInputs;
  if (ImGui::Begin("##hint", nullptr, flags)) ImGui::TextColored(kAmber, "%s", text);
  ImGui::End();
}

void draw_notice_toast(const Notice& notice, float area_width, float area_height) {
  ImGui::SetNextWindowPos(ImVec2(area_width * 0.5f, area_height - 12.0f), ImGuiCond_Always, ImVec2(0.5f, 1.0f));
  ImGui::SetNextWindowBgAlpha(0.85f);
  const ImGuiWindowFlags flags = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize |
                                 ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoFocusOnAppearing |
                                 ImGuiWindowFlags_NoNav | ImGuiWindowFlags_NoInputs;
  if (ImGui::Begin("##notice", nullptr, flags)) {
    ImGui::PushTextWrapPos(std::max(ImGui::GetFontSize() * 10.0f, area_width - 40.0f));
    ImGui::TextColored(notice.error ? kRed : kGreen, "%s", notice.text.c_str());
    ImGui::PopTextWrapPos();
  }
  ImGui::End();
}

QuitChoice draw_quit_dialog(double unsaved_seconds, bool saving, const Notice& notice) {
  const ImGuiViewport* vp = ImGui::GetMainViewport();
  // A dimmed cover that takes every click, then the question on top of it.
  ImGui::SetNextWindowPos(vp->Pos);
  ImGui::SetNextWindowSize(vp->Size);
  ImGui::SetNextWindowFocus();
  ImGui::SetNextWindowBgAlpha(0.55f);
  const ImGuiWindowFlags cover = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove |
                                 ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoNav;
  ImGui::Begin("##quit cover", nullptr, cover);
  ImGui::End();
  QuitChoice choice = QuitChoice::None;
  ImGui::SetNextWindowPos(ImVec2(vp->Pos.x + vp->Size.x * 0.5f, vp->Pos.y + vp->Size.y * 0.5f), ImGuiCond_Always,
                          ImVec2(0.5f, 0.5f));
  ImGui::SetNextWindowFocus();
  ImGui::SetNextWindowBgAlpha(1.0f);
  const ImGuiWindowFlags dialog = ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoMove |
                                  ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoCollapse;
  if (ImGui::Begin("Quit pdflab?", nullptr, dialog)) {
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
    ImGui::SameLine();
    if (ImGui::Button("Quit anyway (Ctrl+Q)")) choice = QuitChoice::Quit;
    ImGui::SameLine();
    if (ImGui::Button("Cancel (Esc)")) choice = QuitChoice::Cancel;
  }
  ImGui::End();
  return choice;
}

}  // namespace pdflab::ui
