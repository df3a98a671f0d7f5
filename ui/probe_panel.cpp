#include "ui/probe_panel.h"
#include "ui/style.h"

#include "renderer/error.h"
#include "ui/colour_scale.h"
#include "ui/layout_report.h"
#include "ui/teach_draw.h"

#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

namespace pdflab::ui {

namespace {


constexpr int kProbeDirections = 400;
constexpr int kMapWidth = 96, kMapHeight = 48;
// Paths per map cell of the brute-force incident light (incident_light_map).
constexpr int kIncidentPaths = 36;
constexpr int kLobeWidth = 64, kLobeHeight = 32;
constexpr int kChiSamples = 200000;

// Each map cell shows the pdf averaged over the cell (kSupersample^2 points):
// a small light or a sharp glossy lobe narrower than a cell still shows.
constexpr int kSupersample = 8;

// A map titled `title` whose values `values()` computes; an InputError it
// throws becomes the map's error line.
template <class Values>
ProbeMap make_map_of(const char* title, int w, int h, Values values) {
  ProbeMap map;
  map.title = title;
  try {
    map.values = values();
    map.width = w;
    map.height = h;
    for (float v : map.values)
      if (std::isfinite(v)) map.max_value = std::max(map.max_value, v);
  } catch (const InputError& e) {
    map.error = e.what();
  }
  return map;
}

ProbeMap make_map(const char* title, const Scene& scene, const Strategy& strategy, const ProbePoint& at, int w, int h,
                  const GuidingDistribution* guide = nullptr) {
  return make_map_of(title, w, h, [&] {
    SamplingPlan plan = SamplingPlan::make(strategy, scene);
    plan.guiding = guide;
    return pdf_map(plan, at, w, h, kSupersample);
  });
}

ProbeMap make_bsdf_map(const Scene& scene, const ProbePoint& at, int w, int h) {
  return make_map_of("bsdf alone (the material's lobe)", w, h,
                     [&] { return bsdf_pdf_map(scene, at, w, h, kSupersample); });
}

// A map value's place on the colour map: linear up to `top`, or four decades below it.
float map_shade(double v, double top, bool log_scale) {
  return static_cast<float>(log_scale ? (v > 0.0 ? 1.0 + std::log10(v / top) / 4.0 : 0.0) : v / top);
}

// The map as coloured cells. Log scale: four decades below the maximum, so a
// mixture's broad cosine part shows beside its sharp light part. `scale_top`:
// the value at the top of the colour scale (0: the map's own maximum), so
// maps drawn side by side can share one scale.
void draw_map(const ProbeMap& map, ImVec2 size, bool log_scale, double scale_top = 0.0) {
  ImGui::TextUnformatted(map.title.c_str());
  const ImVec2 p0 = ImGui::GetCursorScreenPos();
  ImGui::Dummy(size);
  ImDrawList* list = ImGui::GetWindowDrawList();
  if (!map.error.empty() || map.width == 0) {
    list->AddRectFilled(p0, ImVec2(p0.x + size.x, p0.y + size.y), IM_COL32(30, 30, 36, 255));
    list->AddText(ImGui::GetFont(), ImGui::GetFontSize(), ImVec2(p0.x + 6, p0.y + 6), IM_COL32(255, 110, 100, 255),
                  map.error.empty() ? "no surface" : map.error.c_str(), nullptr, size.x - 12.0f);
    return;
  }
  const float cw = size.x / static_cast<float>(map.width), ch = size.y / static_cast<float>(map.height);
  const double top = scale_top > 0.0 ? scale_top : map.max_value > 0.0f ? map.max_value : 1.0;
  for (int r = 0; r < map.height; ++r)
    for (int c = 0; c < map.width; ++c) {
      const double v = map.values[static_cast<std::size_t>(r) * map.width + c];
      const float x = p0.x + cw * static_cast<float>(c), y = p0.y + ch * static_cast<float>(r);
      list->AddRectFilled(ImVec2(x, y), ImVec2(x + cw + 0.5f, y + ch + 0.5f), draw::colormap(map_shade(v, top, log_scale)));
    }
  // The horizon: above it the hemisphere of the surface, below it the directions into it.
  const float hy = p0.y + size.y * 0.5f;
  list->AddLine(ImVec2(p0.x, hy), ImVec2(p0.x + size.x, hy), IM_COL32(255, 255, 255, 120));
  list->AddRect(p0, ImVec2(p0.x + size.x, p0.y + size.y), IM_COL32(110, 110, 120, 255));
}

void draw_disc(ImDrawList* list, ImVec2 centre, float radius, const char* label) {
  list->AddCircleFilled(centre, radius, IM_COL32(24, 24, 30, 255), 64);
  for (float f : {0.5f, std::sqrt(0.5f)})  // cos theta = 0.75 and 0.5 (equal-area radii)
    list->AddCircle(centre, radius * f, IM_COL32(70, 70, 80, 255), 48);
  list->AddCircle(centre, radius, IM_COL32(130, 130, 140, 255), 64, 1.5f);
  list->AddLine(ImVec2(centre.x - radius, centre.y), ImVec2(centre.x + radius, centre.y), IM_COL32(55, 55, 65, 255));
  list->AddLine(ImVec2(centre.x, centre.y - radius), ImVec2(centre.x, centre.y + radius), IM_COL32(55, 55, 65, 255));
  const float w = ImGui::CalcTextSize(label).x;
  list->AddText(ImVec2(centre.x - w * 0.5f, centre.y + radius + 3.0f), IM_COL32(175, 175, 185, 255), label);
}

// The quadtree of the probe point's leaf as a picture of its cells: the map
// (s, t) = ((z + 1) / 2, phi / 2 pi) of the scene's axes, s across and t down,
// each cell coloured by its pdf on the guided map's scale (`top`), the cells
// facing into the surface dimmed, and a ring where the normal points.
void quadtree_view(const ProbeState& s, float side, bool log_scale, double top) {
  ImGui::Text("leaf %d's quadtree: %zu cells", s.guide_leaf, s.guide_cells.size());
  const ImVec2 p0 = ImGui::GetCursorScreenPos();
  ImGui::Dummy(ImVec2(side, side));
  layout::item("probe.quadtree");
  ImDrawList* list = ImGui::GetWindowDrawList();
  if (top <= 0.0) top = 1.0;
  for (const GuidingDistribution::Cell& c : s.guide_cells) {
    const ImVec2 a(p0.x + side * c.s, p0.y + side * c.t), b(p0.x + side * (c.s + c.size), p0.y + side * (c.t + c.size));
    list->AddRectFilled(a, b, draw::colormap(map_shade(c.pdf, top, log_scale)));
    const Vec3 d = direction_from_square(c.s + 0.5f * c.size, c.t + 0.5f * c.size);
    if (dot(d, s.point.normal) < 0.0f) list->AddRectFilled(a, b, IM_COL32(0, 0, 0, 140));
    if (b.x - a.x >= 3.0f) list->AddRect(a, b, IM_COL32(20, 20, 26, 200));
  }
  const SquarePoint n = square_from_direction(s.point.normal);
  const ImVec2 at(p0.x + side * n.s, p0.y + side * n.t);
  list->AddCircle(at, 5.0f, IM_COL32(255, 255, 255, 230), 16, 2.0f);
  list->AddRect(p0, ImVec2(p0.x + side, p0.y + side), IM_COL32(110, 110, 120, 255));
}

bool is_light_technique(int t) {
  return t == static_cast<int>(Technique::Light) || t == static_cast<int>(Technique::LightSolidAngle);
}

ImU32 sample_colour(const ProbeState& s, std::size_t i) {
  const ProbeSample& sample = s.samples[i];
  if (i < s.sample_target.size() && s.sample_target[i] >= 0) return target_colour(s.sample_target[i]);
  return draw::technique_colour(sample.technique);
}

void directions_view(const ProbeState& s, float radius) {
  const float line = ImGui::GetTextLineHeight();
  const ImVec2 p0 = ImGui::GetCursorScreenPos();
  ImGui::Dummy(ImVec2(radius * 3.5f + 30.0f, radius * 2.0f + line + 8.0f));
  ImDrawList* list = ImGui::GetWindowDrawList();
  const ImVec2 upper(p0.x + radius + 2.0f, p0.y + radius + 2.0f);
  const ImVec2 lower(upper.x + radius * 2.0f + 24.0f, upper.y);
  draw_disc(list, upper, radius, "above (normal at centre)");
  draw_disc(list, lower, radius * 0.75f, "below the surface");
  for (std::size_t i = 0; i < s.samples.size(); ++i) {
    const ProbeSample& sample = s.samples[i];
    if (sample.technique < 0) continue;
    float u = 0.0f, v = 0.0f;
    direction_to_map(s.point, sample.direction, u, v);
    const DiscPoint d = project_to_disc(u, v);
    const ImVec2 c = d.lower ? lower : upper;
    const float r = d.lower ? radius * 0.75f : radius;
    list->AddCircleFilled(ImVec2(c.x + d.x * r, c.y - d.y * r), 2.2f, sample_colour(s, i), 8);
  }
}

void legend_entry(ImU32 colour, const char* label, int count, float indent) {
  const ImVec2 p = ImGui::GetCursorScreenPos();
  const float line = ImGui::GetTextLineHeight();
  ImGui::GetWindowDrawList()->AddCircleFilled(ImVec2(p.x + indent + line * 0.4f, p.y + line * 0.5f), line * 0.3f,
                                              colour, 12);
  ImGui::Dummy(ImVec2(indent + line, line));
  ImGui::SameLine();
  ImGui::Text("%s  %d", label, count);
}

void legend(const ProbeState& s) {
  for (int t = 0; t <= kTechniqueCount; ++t) {
    const int count = s.technique_counts[static_cast<std::size_t>(t)];
    if (count == 0) continue;
    const bool none = t == kTechniqueCount;
    const std::string name = none ? "no direction" : std::string(technique_name(static_cast<Technique>(t)));
    legend_entry(draw::technique_colour(none ? -1 : t), name.c_str(), count, 0.0f);
    if (none || !is_light_technique(t)) continue;
    // The light technique's samples split by the target they aim at: of many
    // lights, the kShownTargets most aimed at, and the rest in one line.
    constexpr std::size_t kShownTargets = 8;
    std::vector<int> counts(s.target_labels.size(), 0);
    for (std::size_t i = 0; i < s.samples.size() && i < s.sample_target.size(); ++i) {
      const int k = s.sample_target[i];
      if (s.samples[i].technique == t && k >= 0 && static_cast<std::size_t>(k) < counts.size())
        ++counts[static_cast<std::size_t>(k)];
    }
    std::vector<std::size_t> order;
    for (std::size_t k = 0; k < counts.size(); ++k)
      if (counts[k] > 0) order.push_back(k);
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return counts[a] > counts[b]; });
    const float indent = ImGui::GetTextLineHeight();
    int rest = 0;
    for (std::size_t n = 0; n < order.size(); ++n) {
      const std::size_t k = order[n];
      if (n < kShownTargets) legend_entry(target_colour(static_cast<int>(k)), ("to " + s.target_labels[k]).c_str(), counts[k], indent);
      else rest += counts[k];
    }
    if (order.size() > kShownTargets) {
      ImGui::Dummy(ImVec2(indent + ImGui::GetTextLineHeight(), 0.0f));
      ImGui::SameLine();
      ImGui::TextColored(kDim, "to %zu other targets  %d", order.size() - kShownTargets, rest);
    }
  }
}

void chi_square_section(ProbeState& s, double now) {
  if (s.plan && s.plan->nee_mis) {
    ImGui::TextColored(kDim, "nee-mis takes two directions per vertex, not one\nsample/pdf pair: "
                             "check its two techniques alone.");
    return;
  }
  ImGui::BeginDisabled(s.chi_running());
  if (ImGui::Button(s.chi_running() ? "running..." : "Chi-square check (C)")) start_probe_chi_square(s, now);
  ImGui::EndDisabled();
  ImGui::SameLine();
  if (s.chi_running()) {
    ImGui::TextColored(kAmber, "running... %.1f s", now - s.chi_started);
    return;
  }
  if (!s.chi) {
    ImGui::TextColored(kDim, "%d samples from each sampler vs the pdf integrated per cell", kChiSamples);
    return;
  }
  const ProbeChiSquare& c = *s.chi;
  ImGui::TextColored(c.passed ? kGreen : kRed, "%s", c.passed ? "PASS" : "FAIL");
  ImGui::SameLine();
  ImGui::Text("packet p = %.3g, one-path p = %.3g  (alpha %.2g)   %.2f s", c.result.p_value,
              c.one_path_result.p_value, c.alpha, s.chi_seconds);
  ImGui::TextColored(kDim, "packet sampler (what renders): chi2 %.1f, dof %d", c.result.statistic, c.result.dof);
  const std::uint64_t zero_hits = c.result.zero_cell_hits + c.one_path_result.zero_cell_hits;
  if (zero_hits > 0)
    ImGui::TextColored(kRed, "%llu samples where the pdf is zero", static_cast<unsigned long long>(zero_hits));
  const BandHistogram bands = cos_theta_bands(c);
  const int n = static_cast<int>(bands.observed.size());
  std::vector<double> all = bands.observed;
  all.insert(all.end(), bands.expected.begin(), bands.expected.end());
  all.push_back(0.0);
  const float width = ImGui::GetContentRegionAvail().x;
  const draw::Plot plot("samples per cos(theta) band vs the pdf integrated over the band",
                        ImVec2(width, 150.0f), {1.0, -1.0}, draw::fit_axis(all, false),
                        "cos(theta): +1 along the normal ... -1 straight into the surface");
  // Bars from cos = +1 at the left, bands of equal width 2 / n in cos(theta).
  plot.bars(1.0, -2.0 / n, bands.observed, IM_COL32(90, 170, 255, 200));
  std::vector<double> xs, ys;
  for (int i = 0; i < n; ++i) {
    const double a = 1.0 - 2.0 * i / n, b = 1.0 - 2.0 * (i + 1) / n;
    xs.insert(xs.end(), {a, b});
    ys.insert(ys.end(), {bands.expected[static_cast<std::size_t>(i)], bands.expected[static_cast<std::size_t>(i)]});
  }
  plot.line(xs, ys, IM_COL32(255, 190, 60, 255), 2.0f);
  plot.legend({{"observed", IM_COL32(90, 170, 255, 200)}, {"expected", IM_COL32(255, 190, 60, 255)}});
}

// Each light's probability of being chosen at the point, beside its share by
// power; of many lights, the kShownLights most likely here.
void light_choice_section(const ProbeState& s) {
  constexpr std::size_t kShownLights = 12;
  const ProbeLightChoice& c = s.light_choice;
  if (c.rows.size() < 2) return;
  ImGui::Separator();
  ImGui::Text("Light choice here (%s, by %s)", c.set.c_str(), c.choice.c_str());
  std::vector<std::size_t> order(c.rows.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return c.rows[a].probability > c.rows[b].probability; });
  const std::size_t shown = std::min(order.size(), kShownLights);
  if (!ImGui::BeginTable("light choice", 3, ImGuiTableFlags_SizingFixedFit | ImGuiTableFlags_RowBg)) return;
  ImGui::TableSetupColumn("light");
  ImGui::TableSetupColumn("by power");
  ImGui::TableSetupColumn("at this point");
  ImGui::TableHeadersRow();
  double rest = 1.0;
  for (std::size_t k = 0; k < shown; ++k) {
    const ProbeLightChoice::Row& r = c.rows[order[k]];
    rest -= r.probability;
    ImGui::TableNextRow();
    ImGui::TableNextColumn();
    ImGui::TextUnformatted(r.label.c_str());
    ImGui::TableNextColumn();
    ImGui::TextColored(kDim, "%.3g", r.share);
    ImGui::TableNextColumn();
    if (r.receives) ImGui::Text("%.3g", r.probability);
    else ImGui::TextColored(kAmber, "%.3g  (behind it)", r.probability);
  }
  ImGui::EndTable();
  if (shown < order.size())
    ImGui::TextColored(kDim, "the %zu lights most likely here of %zu; the other %zu take %.3g%% of the choices", shown,
                       order.size(), order.size() - shown, 100.0 * std::max(rest, 0.0));
  if (c.choice == "tree")
    ImGui::TextColored(kDim, "by the light tree (power, distance, orientation, the normal), %g%% of the choices uniform",
                       100.0 * kLightChoiceFloor);
  else
    ImGui::TextColored(kDim, "by what the point receives, %g%% of the choices uniform", 100.0 * kLightChoiceFloor);
}

}  // namespace

DiscPoint project_to_disc(float u, float v) {
  const float cos_theta = std::clamp(1.0f - 2.0f * v, -1.0f, 1.0f);
  const float phi = 2.0f * std::numbers::pi_v<float> * u;
  DiscPoint d;
  d.lower = cos_theta < 0.0f;
  // 1 - |cos| is the solid angle from the disc's centre over 2 pi: r^2 keeps areas equal.
  const float r = std::sqrt(std::max(0.0f, 1.0f - std::abs(cos_theta)));
  d.x = r * std::cos(phi);
  d.y = r * std::sin(phi);
  return d;
}

std::optional<PixelHit> pixel_at(float px, float py, float rect_x, float rect_y, float rect_w, float rect_h,
                                 int image_width, int image_height) {
  if (!(rect_w > 0.0f) || !(rect_h > 0.0f) || image_width <= 0 || image_height <= 0) return std::nullopt;
  const float fx = (px - rect_x) / rect_w, fy = (py - rect_y) / rect_h;
  if (!(fx >= 0.0f && fx < 1.0f && fy >= 0.0f && fy < 1.0f)) return std::nullopt;
  PixelHit hit;
  hit.x = std::min(image_width - 1, static_cast<int>(fx * static_cast<float>(image_width)));
  hit.y = std::min(image_height - 1, static_cast<int>(fy * static_cast<float>(image_height)));
  return hit;
}

int light_target_of(const SamplingPlan& plan, const Vec3& origin, const Vec3& direction) {
  // Each target alone as a set of one: its pdf is positive exactly where it is
  // seen. Of several in line, the nearest (what the ray reaches first).
  const TargetSet& all = plan.book_targets;
  int best = -1;
  float best_distance = kInf;
  const auto consider = [&](TargetSet one, int index, float distance) {
    one.set_probabilities({1.0});
    if (one.pdf(origin, direction) > 0.0f && distance < best_distance) {
      best_distance = distance;
      best = index;
    }
  };
  int index = 0;
  for (const auto& q : all.quads) {
    TargetSet one;
    one.quads.push_back(q);
    const float t = quad_hit_distance(*q.quad, origin, direction);
    consider(std::move(one), index++, t >= 0.0f ? t : 1e30f);
  }
  for (const auto& sp : all.spheres) {
    TargetSet one;
    one.spheres.push_back(sp);
    consider(std::move(one), index++, length(sp.sphere->center - origin) - sp.sphere->radius);
  }
  return best;
}

std::uint32_t target_colour(int target) {
  static constexpr ImU32 kColours[] = {IM_COL32(255, 215, 70, 255), IM_COL32(80, 235, 235, 255),
                                       IM_COL32(255, 120, 200, 255), IM_COL32(170, 255, 120, 255),
                                       IM_COL32(255, 150, 90, 255)};
  return kColours[static_cast<std::size_t>(std::max(0, target)) % std::size(kColours)];
}

BandHistogram cos_theta_bands(const ProbeChiSquare& chi) {
  BandHistogram b;
  b.observed.assign(static_cast<std::size_t>(std::max(0, chi.z_cells)), 0.0);
  b.expected.assign(b.observed.size(), 0.0);
  for (int row = 0; row < chi.z_cells; ++row)
    for (int col = 0; col < chi.phi_cells; ++col) {
      const std::size_t i = static_cast<std::size_t>(row) * chi.phi_cells + col;
      if (i < chi.observed.size()) b.observed[static_cast<std::size_t>(row)] += static_cast<double>(chi.observed[i]);
      if (i < chi.expected.size()) b.expected[static_cast<std::size_t>(row)] += chi.expected[i];
    }
  return b;
}

void probe_pixel(ProbeState& s, std::shared_ptr<const Scene> scene, const Strategy& strategy, std::uint64_t seed,
                 int x, int y, std::shared_ptr<const GuidingDistribution> guide) {
  // A running check reads the old plan and scene through its own copies of the pointers.
  s.has_point = true;
  s.open = true;
  ++s.serial;
  s.pixel_x = x;
  s.pixel_y = y;
  s.strategy_text = strategy.to_string();
  s.chi.reset();
  s.scene = std::move(scene);
  s.point = first_diffuse_hit(*s.scene, x, y, seed);
  s.samples.clear();
  s.light_choice = {};
  s.sample_target.clear();
  s.target_labels.clear();
  std::fill(s.technique_counts.begin(), s.technique_counts.end(), 0);
  s.guide = std::move(guide);
  try {
    SamplingPlan plan = SamplingPlan::make(strategy, *s.scene);
    plan.guiding = s.guide.get();
    s.plan = std::make_shared<const SamplingPlan>(plan);
  } catch (const InputError&) {
    s.plan.reset();
  }
  if (s.point.found && s.plan) {
    s.samples = probe_directions(*s.plan, s.point, kProbeDirections, seed);
    for (const ProbeSample& p : s.samples) {
      ++s.technique_counts[static_cast<std::size_t>(p.technique < 0 ? kTechniqueCount : p.technique)];
      s.sample_target.push_back(is_light_technique(p.technique) ? light_target_of(*s.plan, s.point.point, p.direction)
                                                                : -1);
    }
    const Scene& sc = *s.scene;
    s.light_choice = probe_light_choice(sc, *s.plan, s.point);
    s.target_labels = target_labels(sc, s.plan->book_targets);
  }
  s.strategy_map = make_map("pdf of the strategy over the sphere", *s.scene, strategy,
                            s.point, kMapWidth, kMapHeight, s.guide.get());
  s.light_map = make_map("light alone (the light lobe)", *s.scene, Strategy::single(Technique::Light), s.point,
                         kLobeWidth, kLobeHeight);
  s.bsdf_map = make_bsdf_map(*s.scene, s.point, kLobeWidth, kLobeHeight);
  s.guided_map = s.guide && strategy.uses(Technique::Guided)
                     ? make_map("guided alone: what the SD-tree learned here", *s.scene,
                                Strategy::single(Technique::Guided), s.point, kMapWidth, kMapHeight, s.guide.get())
                     : ProbeMap{};
  s.guide_leaf = -1;
  s.guide_cells.clear();
  if (!s.guided_map.values.empty() && s.point.found) {
    s.guide_leaf = s.guide->leaf_at(s.point.point, s.point.normal);
    s.guide->leaf_box(s.point.point, s.point.normal, s.guide_box_lo, s.guide_box_hi);
    s.guide_cells = s.guide->cells(s.guide_leaf);
  }
  // The brute-force incident light, for comparison with what guiding learned
  // (a job still running for an earlier probe is waited for: a few tenths of a second).
  s.incident_map = ProbeMap{};
  if (s.incident_job.valid()) s.incident_job.wait();
  s.incident_job = {};
  if (!s.guided_map.values.empty() && s.point.found) {
    s.incident_serial = s.serial;
    s.incident_job = std::async(std::launch::async, [scene = s.scene, at = s.point, seed] {
      return incident_light_map(*scene, at, kMapWidth, kMapHeight, kIncidentPaths, seed);
    });
  }
  s.bsdf_lobe = bsdf_lobe_name(*s.scene, s.point);
  s.delta_note = delta_lobe_note(*s.scene, s.point);
}

void start_probe_chi_square(ProbeState& s, double now) {
  if (s.chi_running() || !s.plan || !s.point.found || s.plan->nee_mis) return;
  s.chi.reset();
  s.chi_started = now;
  s.chi_serial = s.serial;
  s.chi_job = std::async(std::launch::async, [plan = s.plan, scene = s.scene, at = s.point] {
    (void)scene;  // the plan points into it
    return probe_chi_square(*plan, at, kChiSamples, 1);
  });
}

// Collects the brute-force incident light when its job has finished.
void poll_probe_incident(ProbeState& s) {
  if (!s.incident_job.valid() || s.incident_job.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return;
  std::vector<float> values = s.incident_job.get();
  if (s.incident_serial != s.serial) return;
  s.incident_map.title = "the light taken in here (L cos), traced by brute force";
  s.incident_map.width = kMapWidth;
  s.incident_map.height = kMapHeight;
  for (float v : values) s.incident_map.max_value = std::max(s.incident_map.max_value, v);
  s.incident_map.values = std::move(values);
}

bool poll_probe_chi_square(ProbeState& s, double now) {
  if (!s.chi_job.valid() || s.chi_job.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return false;
  ProbeChiSquare result = s.chi_job.get();
  if (s.chi_serial != s.serial) return false;  // for a probe since replaced
  s.chi = std::move(result);
  s.chi_seconds = now - s.chi_started;
  return true;
}

void draw_probe_panel(ProbeState& s, double now, float area_width, float area_height) {
  if (!s.open || !s.has_point) return;
  poll_probe_chi_square(s, now);
  poll_probe_incident(s);
  // Over the side panel, reaching into the image area only as far as it must:
  // the image stays clickable for the next probe. Movable.
  (void)area_width, (void)area_height;
  const ImVec2 display = ImGui::GetIO().DisplaySize;
  const float w = std::min(display.x - 20.0f, 600.0f), h = std::min(display.y - 20.0f, 760.0f);
  ImGui::SetNextWindowPos(ImVec2(display.x - w - 10.0f, 10.0f), ImGuiCond_Appearing);
  ImGui::SetNextWindowSize(ImVec2(w, h), ImGuiCond_Appearing);
  // Opaque: the panel's text beneath must not show through.
  ImGui::SetNextWindowBgAlpha(1.0f);
  if (!ImGui::Begin("Pixel probe (P)", &s.open, ImGuiWindowFlags_NoSavedSettings)) {
    ImGui::End();
    return;
  }
  ImGui::Text("pixel (%d, %d)   %s", s.pixel_x, s.pixel_y, s.strategy_text.c_str());
  if (!s.point.found) {
    ImGui::TextColored(kAmber, "This pixel's ray leaves the scene or reaches a light before a diffuse surface.");
    ImGui::End();
    return;
  }
  // In the scene file's coordinates (the rendering space may be the camera's).
  const auto hit = file_point(*s.scene, s.point.point);
  ImGui::TextColored(kDim, "hit (%.6g, %.6g, %.6g)  normal (%.2f, %.2f, %.2f)%s", hit[0], hit[1], hit[2],
                     s.point.normal.x, s.point.normal.y, s.point.normal.z,
                     s.point.specular_bounces ? "  after mirror/glass" : "");

  const float line = ImGui::GetTextLineHeight();
  const float spacing = ImGui::GetStyle().ItemSpacing.x;
  const float avail = ImGui::GetContentRegionAvail().x;
  const float radius = std::clamp((avail - 210.0f) / 3.6f, 55.0f, 90.0f);
  ImGui::TextColored(kDim, "%d directions drawn here, by technique (equal-area view)",
                     static_cast<int>(s.samples.size()));
  ImGui::BeginGroup();
  directions_view(s, radius);
  ImGui::EndGroup();
  ImGui::SameLine();
  ImGui::BeginGroup();
  ImGui::Dummy(ImVec2(1.0f, line * 0.5f));
  legend(s);
  ImGui::EndGroup();

  light_choice_section(s);

  ImGui::Separator();
  // The strategy's map with its colour bar.
  const float bar_w = ImGui::CalcTextSize("1e+04").x + 22.0f;
  const float map_w = std::max(160.0f, avail - bar_w - spacing);
  const float map_h = std::min(map_w * 0.5f, 150.0f);
  ImGui::BeginGroup();
  draw_map(s.strategy_map, ImVec2(map_h * 2.0f, map_h), s.log_scale);
  ImGui::EndGroup();
  ImGui::SameLine();
  ImGui::BeginGroup();
  const double top = s.strategy_map.max_value;
  draw::colour_bar(ImVec2(bar_w, map_h + line + 4.0f), s.log_scale ? top * 1e-4 : 0.0, top, s.log_scale, "pdf");
  ImGui::EndGroup();
  ImGui::SameLine();
  ImGui::BeginGroup();
  ImGui::Checkbox("log colour scale\n(4 decades)", &s.log_scale);
  ImGui::EndGroup();
  // The two lobes a strategy can mix at this point, side by side on one
  // colour scale and in the same projection: where the light is, and where
  // the material sends light.
  ImGui::TextColored(kDim, "The light lobe and the material's own lobe here, on one colour scale:");
  const double lobes_top = std::max(s.light_map.max_value, s.bsdf_map.max_value);
  const float lobe_w = std::max(120.0f, (avail - bar_w - 2.0f * spacing) * 0.5f);
  const float lobe_h = std::min(lobe_w * 0.5f, 130.0f);
  ImGui::BeginGroup();
  draw_map(s.light_map, ImVec2(lobe_h * 2.0f, lobe_h), s.log_scale, lobes_top);
  ImGui::EndGroup();
  ImGui::SameLine();
  ImGui::BeginGroup();
  draw_map(s.bsdf_map, ImVec2(lobe_h * 2.0f, lobe_h), s.log_scale, lobes_top);
  ImGui::EndGroup();
  ImGui::SameLine();
  ImGui::BeginGroup();
  draw::colour_bar(ImVec2(bar_w, lobe_h + line + 4.0f), s.log_scale ? lobes_top * 1e-4 : 0.0, lobes_top, s.log_scale,
                   "pdf");
  ImGui::EndGroup();
  ImGui::TextWrapped("bsdf here: %s", s.bsdf_lobe.c_str());
  if (!s.guided_map.values.empty()) {
    // Path guiding's distribution at this point's leaf, as the render draws from it.
    // Beside it the light taken in here (L cos), traced by brute force: what
    // the learning aims at, on one colour scale.
    const double guided_top = std::max(s.guided_map.max_value, s.incident_map.max_value);
    ImGui::BeginGroup();
    draw_map(s.guided_map, ImVec2(map_h * 2.0f, map_h), s.log_scale, guided_top);
    ImGui::EndGroup();
    ImGui::SameLine();
    draw::colour_bar(ImVec2(bar_w, map_h + line + 4.0f), s.log_scale ? guided_top * 1e-4 : 0.0, guided_top,
                     s.log_scale, "pdf");
    if (!s.incident_map.values.empty()) {
      draw_map(s.incident_map, ImVec2(map_h * 2.0f, map_h), s.log_scale, guided_top);
    } else if (s.incident_running()) {
      ImGui::TextColored(kDim, "tracing the light that arrives here (%d paths a cell)...", kIncidentPaths);
    }
    if (s.guide_leaf >= 0) {
      // The tree itself: the leaf's cells in the map the SD-tree keeps, on the same colour scale.
      ImGui::BeginGroup();
      quadtree_view(s, map_h * 1.4f, s.log_scale, guided_top);
      ImGui::EndGroup();
      ImGui::SameLine();
      ImGui::BeginGroup();
      const ImVec2 q = ImGui::GetCursorScreenPos();
      const float sw = ImGui::GetFontSize();
      ImGui::GetWindowDrawList()->AddRectFilled(ImVec2(q.x, q.y + 2.0f), ImVec2(q.x + sw, q.y + sw - 2.0f),
                                                to_u32(guiding_leaf_colour(s.guide_leaf)));
      ImGui::Dummy(ImVec2(sw, sw));
      ImGui::SameLine();
      ImGui::Text("leaf %d of %d", s.guide_leaf, s.guide->leaves());
      const auto lo = file_point(*s.scene, s.guide_box_lo), hi = file_point(*s.scene, s.guide_box_hi);
      float smallest = 1.0f;
      for (const GuidingDistribution::Cell& c : s.guide_cells) smallest = std::min(smallest, c.size);
      const int depth = -std::ilogb(smallest);  // cells are halves of halves
      static constexpr const char* kFacing[kGuidingNormalBins] = {"+x", "-x", "+y", "-y", "+z", "-z"};
      ImGui::PushStyleColor(ImGuiCol_Text, kDim);
      ImGui::PushTextWrapPos(ImGui::GetCursorPosX() + std::max(120.0f, avail - map_h * 1.4f - spacing));
      ImGui::TextWrapped("its box: x %.3g..%.3g, y %.3g..%.3g, z %.3g..%.3g, for the surfaces facing %s", lo[0],
                         hi[0], lo[1], hi[1], lo[2], hi[2], kFacing[guiding_normal_bin(s.point.normal)]);
      ImGui::TextWrapped("the smallest cell %d levels down (1/%d of the map's side)", depth, 1 << depth);
      ImGui::TextWrapped("s = (z + 1) / 2 across, t = phi / 2 pi down, in the scene's axes: equal areas are equal "
                         "solid angles. Ring: the normal; dimmed: directions into the surface. The colour bar "
                         "above holds.");
      ImGui::PopTextWrapPos();
      ImGui::PopStyleColor();
      ImGui::EndGroup();
    }
  }
  ImGui::PushStyleColor(ImGuiCol_Text, kDim);
  ImGui::TextWrapped("phi across, cos(theta) from +1 (top) to -1; line: the horizon; each cell the pdf averaged over "
                     "it. Maxima: strategy %.3g, light %.3g, bsdf %.3g",
                     s.strategy_map.max_value, s.light_map.max_value, s.bsdf_map.max_value);
  ImGui::PopStyleColor();
  if (!s.delta_note.empty()) ImGui::TextWrapped("%s", s.delta_note.c_str());
  if (s.point.surface.glossy && s.plan && !s.plan->nee_mis && s.plan->weight[static_cast<int>(Technique::Bsdf)] > 0.0f) {
    ImGui::PushStyleColor(ImGuiCol_Text, kDim);
    ImGui::TextWrapped("The chi-square check below draws bsdf at this point's own lobe (%s).",
                       s.point.surface.transmits ? "GGX visible normals, reflected or refracted"
                                                 : "GGX visible normals, reflected");
    ImGui::PopStyleColor();
  }

  ImGui::Separator();
  chi_square_section(s, now);
  ImGui::End();
}

}  // namespace pdflab::ui
