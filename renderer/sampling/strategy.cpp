#include "renderer/sampling/strategy.h"

#include "renderer/error.h"

#include <charconv>
#include <cstdio>

namespace pdflab {

namespace {

constexpr std::array<std::string_view, kTechniqueCount> kNames = {
    "cosine", "uniform-hemisphere", "uniform-sphere", "light"};

// Names INTERFACE.md reserves for techniques that this build does not provide yet.
constexpr std::array<std::string_view, 2> kReserved = {"light-sa", "nee-mis"};

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

std::string known_list() {
  std::string out;
  for (auto n : kNames) {
    if (!out.empty()) out += ", ";
    out.append(n);
  }
  return out + ", mix:TECHNIQUE=W,...";
}

Technique parse_technique(std::string_view name, std::string_view whole) {
  for (int i = 0; i < kTechniqueCount; ++i)
    if (kNames[i] == name) return static_cast<Technique>(i);
  for (auto r : kReserved)
    if (r == name)
      throw InputError("strategy '" + std::string(whole) + "': '" + std::string(name) +
                       "' is not available in this version of pdflab");
  throw InputError("unknown strategy '" + std::string(whole) + "'" +
                   (name != whole ? " (unknown technique '" + std::string(name) + "')" : "") +
                   "; expected one of: " + known_list());
}

float parse_weight(std::string_view text, std::string_view whole) {
  // std::from_chars for float is available in GCC 12's libstdc++.
  float value = 0.0f;
  const auto* begin = text.data();
  const auto* end = text.data() + text.size();
  auto [ptr, ec] = std::from_chars(begin, end, value);
  if (text.empty() || ec != std::errc() || ptr != end || !std::isfinite(value) || value < 0.0f)
    throw InputError("strategy '" + std::string(whole) + "': weight '" + std::string(text) +
                     "' is not a finite number >= 0");
  return value;
}

}  // namespace

std::string_view technique_name(Technique t) { return kNames[static_cast<int>(t)]; }

Strategy Strategy::single(Technique t) {
  Strategy s;
  s.weights[static_cast<int>(t)] = 1.0f;
  return s;
}

Strategy Strategy::parse(std::string_view text) {
  const std::string_view whole = trim(text);
  if (whole.empty()) throw InputError("empty strategy; expected one of: " + known_list());
  constexpr std::string_view kMix = "mix:";
  if (whole.substr(0, kMix.size()) != kMix) return single(parse_technique(whole, whole));

  Strategy s;
  std::array<bool, kTechniqueCount> seen{};
  std::string_view rest = whole.substr(kMix.size());
  if (trim(rest).empty()) throw InputError("strategy '" + std::string(whole) + "': the mixture lists no technique");
  while (true) {
    const size_t comma = rest.find(',');
    const std::string_view term = trim(rest.substr(0, comma));
    const size_t eq = term.find('=');
    if (eq == std::string_view::npos)
      throw InputError("strategy '" + std::string(whole) + "': term '" + std::string(term) +
                       "' is not TECHNIQUE=WEIGHT");
    const Technique t = parse_technique(trim(term.substr(0, eq)), whole);
    const int i = static_cast<int>(t);
    if (seen[i])
      throw InputError("strategy '" + std::string(whole) + "': technique '" +
                       std::string(technique_name(t)) + "' appears twice");
    seen[i] = true;
    s.weights[i] = parse_weight(trim(term.substr(eq + 1)), whole);
    if (comma == std::string_view::npos) break;
    rest = rest.substr(comma + 1);
  }
  float total = 0.0f;
  for (float w : s.weights) total += w;
  if (!(total > 0.0f)) throw InputError("strategy '" + std::string(whole) + "': all weights are zero");
  return s;
}

std::string Strategy::to_string() const {
  int used = 0, last = 0;
  for (int i = 0; i < kTechniqueCount; ++i)
    if (weights[i] > 0.0f) ++used, last = i;
  double total = 0.0;  // in double: weights near FLT_MAX would overflow a float sum
  for (float w : weights) total += w;
  if (used == 1) return std::string(kNames[last]);
  std::string out = "mix:";
  bool first = true;
  for (int i = 0; i < kTechniqueCount; ++i) {
    if (weights[i] <= 0.0f) continue;
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", static_cast<double>(weights[i]) / total);
    if (!first) out += ',';
    out.append(kNames[i]).append("=").append(buf);
    first = false;
  }
  return out;
}

bool Strategy::is_unbiased() const {
  return uses(Technique::Cosine) || uses(Technique::UniformHemisphere) || uses(Technique::UniformSphere);
}

SamplingPlan SamplingPlan::make(const Strategy& strategy, const Scene& scene) {
  SamplingPlan plan;
  plan.scene = &scene;
  plan.target_count = static_cast<int>(scene.targets.size());
  plan.inv_target_count = plan.target_count > 0 ? 1.0f / static_cast<float>(plan.target_count) : 0.0f;
  for (const Target& t : scene.targets) {
    if (t.kind == Target::Kind::Quad) plan.quad_targets.push_back(&scene.quads[t.index]);
    else plan.sphere_targets.push_back(&scene.spheres[t.index]);
  }
  std::array<float, kTechniqueCount> w = strategy.weights;
  // A light technique with nothing to aim at has no distribution: its weight
  // goes to the other techniques (renormalised below).
  if (plan.target_count == 0) w[static_cast<int>(Technique::Light)] = 0.0f;
  double total = 0.0;
  for (float x : w) total += x;
  if (!(total > 0.0))
    throw InputError("strategy '" + strategy.to_string() + "' samples only the importance targets, but scene '" +
                     scene.name + "' has none");
  double running = 0.0;
  int last_positive = 0;
  for (int i = 0; i < kTechniqueCount; ++i) {
    plan.weight[i] = static_cast<float>(w[i] / total);
    running += w[i] / total;
    plan.cdf[i] = static_cast<float>(running);
    if (w[i] > 0.0f) last_positive = i;
  }
  // u < cdf[last_positive] must hold for every u in [0, 1); techniques after it
  // have weight zero and must never be chosen.
  for (int i = last_positive; i < kTechniqueCount; ++i) plan.cdf[i] = 1.0f;
  return plan;
}

float SamplingPlan::light_pdf_sum(const Vec3& origin, const Vec3& direction, const void* skip) const {
  float sum = 0.0f;
  for (const Quad* q : quad_targets)
    if (q != skip) sum += quad_area_pdf(*q, origin, direction);
  for (const Sphere* sp : sphere_targets)
    if (sp != skip) sum += sphere_cone_pdf(*sp, origin, direction);
  return sum;
}

float SamplingPlan::light_pdf(const Vec3& origin, const Vec3& direction) const {
  return inv_target_count * light_pdf_sum(origin, direction, nullptr);
}

DirectionSample SamplingPlan::sample_light(const Vec3& origin, float u_target, float u1, float u2) const {
  const int chosen = std::min(static_cast<int>(u_target * static_cast<float>(target_count)), target_count - 1);
  const Target& t = scene->targets[chosen];
  // The chosen target's pdf comes from the sampler itself (an edge sample that a
  // re-intersection might round off the target still gets its true density).
  DirectionSample ds;
  if (t.kind == Target::Kind::Quad) {
    const Quad& q = scene->quads[t.index];
    ds = sample_quad_area(q, origin, u1, u2);
    ds.pdf = inv_target_count * (ds.pdf + light_pdf_sum(origin, ds.direction, &q));
  } else {
    const Sphere& sp = scene->spheres[t.index];
    ds = sample_sphere_cone(sp, origin, u1, u2);
    ds.pdf = inv_target_count * (ds.pdf + light_pdf_sum(origin, ds.direction, &sp));
  }
  return ds;
}

float SamplingPlan::pdf(const Vec3& origin, const Vec3& normal, const Vec3& direction) const {
  float p = 0.0f;
  if (weight[0] > 0.0f) p += weight[0] * cosine_hemisphere_pdf(normal, direction);
  if (weight[1] > 0.0f) p += weight[1] * uniform_hemisphere_pdf(normal, direction);
  if (weight[2] > 0.0f) p += weight[2] * uniform_sphere_pdf();
  if (weight[3] > 0.0f) p += weight[3] * light_pdf(origin, direction);
  return p;
}

DirectionSample SamplingPlan::sample(const Vec3& origin, const Vec3& normal, Rng& rng) const {
  const float u0 = rng.uniform();
  const float u1 = rng.uniform();
  const float u2 = rng.uniform();
  int chosen = 0;
  while (u0 >= cdf[chosen]) ++chosen;

  DirectionSample ds;
  switch (static_cast<Technique>(chosen)) {
    case Technique::Cosine: ds = sample_cosine_hemisphere(Onb(normal), u1, u2); break;
    case Technique::UniformHemisphere: ds = sample_uniform_hemisphere(Onb(normal), u1, u2); break;
    case Technique::UniformSphere: ds = sample_uniform_sphere(u1, u2); break;
    default: ds = sample_light(origin, rng.uniform(), u1, u2); break;
  }
  if (weight[chosen] == 1.0f) return ds;  // a single technique: its own pdf is the mixture's

  // One-sample mixture: the density of the direction under every technique.
  // The hemisphere terms are cheap and branch-free (a zero weight adds zero).
  // The chosen technique keeps its sampler's own value, so a direction that
  // rounding puts exactly on the horizon cannot get a zero mixture pdf.
  const float c = dot(normal, ds.direction);
  const float above = c > 0.0f ? 1.0f : 0.0f;
  const int light = static_cast<int>(Technique::Light);
  const float light_term =
      chosen == light ? ds.pdf : (weight[light] > 0.0f ? light_pdf(origin, ds.direction) : 0.0f);
  ds.pdf = weight[0] * (chosen == 0 ? ds.pdf : above * c * kInvPi) +
           weight[1] * (chosen == 1 ? ds.pdf : above * kInv2Pi) +
           weight[2] * (chosen == 2 ? ds.pdf : kInv4Pi) + weight[light] * light_term;
  return ds;
}

}  // namespace pdflab
