#include "renderer/sampling/strategy.h"

#include "renderer/sampling/mixture.h"

#include "renderer/error.h"

#include <charconv>
#include <numbers>
#include <cstdio>

namespace pdflab {

namespace {

constexpr std::array<TechniqueInfo, kTechniqueCount> kTable = {
#define PDFLAB_ROW(T) leaf::T::info,
    PDFLAB_TECHNIQUES(PDFLAB_ROW)
#undef PDFLAB_ROW
};

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

std::string known_list() {
  std::string out;
  for (const TechniqueInfo& t : kTable) {
    if (!out.empty()) out += ", ";
    out.append(t.name);
    if (!t.parameter.empty()) out.append("[:").append(t.parameter).append("]");
  }
  return out + ", mix:TECHNIQUE=W,..., nee-mis, nee-mis:balance";
}

std::string format_number(float x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", static_cast<double>(x));
  return buf;
}

float parse_parameter(const TechniqueInfo& t, std::string_view text, std::string_view whole) {
  float value = 0.0f;
  const auto* end = text.data() + text.size();
  auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (text.empty() || ec != std::errc() || ptr != end || !(value >= t.parameter_min && value <= t.parameter_max))
    throw InputError("strategy '" + std::string(whole) + "': " + std::string(t.name) + "'s " +
                     std::string(t.parameter) + " '" + std::string(text) + "' is not a number in [" +
                     format_number(t.parameter_min) + ", " + format_number(t.parameter_max) + "]");
  return value;
}

struct ParsedTechnique {
  Technique technique;
  float parameter;
};

// NAME or NAME:PARAMETER, for a technique whose row has a parameter.
ParsedTechnique parse_technique(std::string_view text, std::string_view whole) {
  const size_t colon = text.find(':');
  const std::string_view name = text.substr(0, colon);
  for (int i = 0; i < kTechniqueCount; ++i) {
    const TechniqueInfo& t = kTable[i];
    if (t.name != name) continue;
    if (colon == std::string_view::npos) return {static_cast<Technique>(i), t.parameter_default};
    if (t.parameter.empty())
      throw InputError("strategy '" + std::string(whole) + "': technique '" + std::string(name) +
                       "' takes no parameter");
    return {static_cast<Technique>(i), parse_parameter(t, text.substr(colon + 1), whole)};
  }
  if (name.substr(0, 7) == "nee-mis")
    throw InputError("strategy '" + std::string(whole) + "': nee-mis is a strategy of its own and cannot be mixed");
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

const TechniqueInfo& technique_info(Technique t) { return kTable[static_cast<int>(t)]; }
std::string_view technique_name(Technique t) { return kTable[static_cast<int>(t)].name; }

std::string strategy_help() {
  std::string out =
      "Strategies: TECHNIQUE | mix:TECHNIQUE=W,TECHNIQUE=W[,...] | nee-mis | nee-mis:balance\nTechniques:\n";
  for (const TechniqueInfo& t : kTable) {
    std::string name(t.name);
    if (!t.parameter.empty())
      name.append("[:").append(t.parameter).append("]");
    out.append("  ").append(name).append(name.size() < 20 ? 20 - name.size() : 1, ' ');
    out.append(t.draws).append("; pdf ").append(t.pdf);
    if (!t.parameter.empty())
      out.append("; ").append(t.parameter).append(" in [").append(format_number(t.parameter_min)).append(", ")
          .append(format_number(t.parameter_max)).append("], default ").append(format_number(t.parameter_default));
    if (!t.covers_hemisphere) out.append(" (biased alone: sees only its targets)");
    out.append("\n");
  }
  return out;
}

std::array<float, kTechniqueCount> Strategy::default_parameters() {
  std::array<float, kTechniqueCount> p{};
  for (int i = 0; i < kTechniqueCount; ++i) p[i] = kTable[i].parameter_default;
  return p;
}

Strategy Strategy::single(Technique t) {
  Strategy s;
  s.weights[static_cast<int>(t)] = 1.0f;
  return s;
}

Strategy Strategy::nee(MisHeuristic h) {
  Strategy s;
  s.nee_mis = true;
  s.heuristic = h;
  return s;
}

Strategy Strategy::parse(std::string_view text) {
  const std::string_view whole = trim(text);
  if (whole.empty()) throw InputError("empty strategy; expected one of: " + known_list());
  if (whole == "nee-mis" || whole == "nee-mis:power") return nee(MisHeuristic::Power);
  if (whole == "nee-mis:balance") return nee(MisHeuristic::Balance);
  if (whole.substr(0, 8) == "nee-mis:")
    throw InputError("strategy '" + std::string(whole) + "': the heuristic must be 'power' or 'balance'");
  constexpr std::string_view kMix = "mix:";
  if (whole.substr(0, kMix.size()) != kMix) {
    const ParsedTechnique p = parse_technique(whole, whole);
    Strategy s = single(p.technique);
    s.parameters[static_cast<int>(p.technique)] = p.parameter;
    return s;
  }

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
    const ParsedTechnique p = parse_technique(trim(term.substr(0, eq)), whole);
    const Technique t = p.technique;
    const int i = static_cast<int>(t);
    s.parameters[i] = p.parameter;
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
  if (nee_mis) return heuristic == MisHeuristic::Power ? "nee-mis" : "nee-mis:balance";
  int used = 0, last = 0;
  for (int i = 0; i < kTechniqueCount; ++i)
    if (weights[i] > 0.0f) ++used, last = i;
  double total = 0.0;  // in double: weights near FLT_MAX would overflow a float sum
  for (float w : weights) total += w;
  // NAME, or NAME:PARAMETER for a technique with one.
  auto spelled = [&](int i) {
    std::string name(kTable[i].name);
    if (!kTable[i].parameter.empty()) name.append(":").append(format_number(parameters[i]));
    return name;
  };
  if (used == 1) return spelled(last);
  std::string out = "mix:";
  bool first = true;
  for (int i = 0; i < kTechniqueCount; ++i) {
    if (weights[i] <= 0.0f) continue;
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", static_cast<double>(weights[i]) / total);
    if (!first) out += ',';
    out.append(spelled(i)).append("=").append(buf);
    first = false;
  }
  return out;
}

bool Strategy::is_unbiased() const {
  if (nee_mis) return true;
  for (int i = 0; i < kTechniqueCount; ++i)
    if (kTable[i].covers_hemisphere && uses(static_cast<Technique>(i))) return true;
  return false;
}

double emitter_power(const Material& m, double area) {
  if (m.type != MaterialType::DiffuseLight) return 0.0;
  const double luminance = 0.2126 * m.emit.x + 0.7152 * m.emit.y + 0.0722 * m.emit.z;
  return luminance * area * std::numbers::pi * (m.two_sided ? 2.0 : 1.0);
}

void TargetSet::set_probabilities(const std::vector<double>& weights) {
  if (weights.empty()) {
    choice = DiscreteDistribution();
    return;
  }
  choice = DiscreteDistribution(weights, DiscreteDistribution::Tiny::AtLeastOne);
  int i = 0;
  for (auto& q : quads) q.probability = choice.pmf(i++);
  for (auto& sp : spheres) sp.probability = choice.pmf(i++);
}

float TargetSet::pdf_without(const Vec3& origin, const Vec3& direction, const void* skip) const {
  float sum = 0.0f;
  if (solid_angle) {
    for (const QuadEntry& e : quads)
      if (e.quad != skip) sum += e.probability * quad_solid_angle_pdf(*e.quad, origin, direction);
  } else {
    for (const QuadEntry& e : quads)
      if (e.quad != skip) sum += e.probability * quad_area_pdf(*e.quad, origin, direction);
  }
  for (const SphereEntry& e : spheres)
    if (e.sphere != skip) sum += e.probability * sphere_cone_pdf(*e.sphere, origin, direction);
  return sum;
}

float TargetSet::pdf(const Vec3& origin, const Vec3& direction) const { return pdf_without(origin, direction, nullptr); }

DirectionSample TargetSet::sample(const Vec3& origin, std::uint32_t u_choice, float u1, float u2) const {
  if (empty()) return {Vec3(0.0f, 0.0f, 1.0f), 0.0f, true};  // nothing to aim at
  const int chosen = choice.sample(u_choice);
  DirectionSample ds;
  const int nq = static_cast<int>(quads.size());
  if (chosen < nq) {
    const QuadEntry& e = quads[chosen];
    ds = solid_angle ? sample_quad_solid_angle(*e.quad, origin, u1, u2) : sample_quad_area(*e.quad, origin, u1, u2);
    if (ds.none) return ds;
    ds.aimed_quad = e.index;
    ds.pdf = e.probability * ds.pdf + pdf_without(origin, ds.direction, e.quad);
  } else {
    const SphereEntry& e = spheres[chosen - nq];
    ds = sample_sphere_cone(*e.sphere, origin, u1, u2);
    ds.pdf = e.probability * ds.pdf + pdf_without(origin, ds.direction, e.sphere);
  }
  return ds;
}

namespace {

// Fills a set with the scene's objects that `pick` accepts; returns their powers.
template <class Pick>
std::vector<double> collect_targets(const Scene& scene, TargetSet& set, Pick pick) {
  std::vector<double> quad_power, sphere_power;
  for (std::size_t i = 0; i < scene.quads.size(); ++i) {
    const Quad& q = scene.quads[i];
    if (!pick(Target{Target::Kind::Quad, static_cast<std::uint32_t>(i)})) continue;
    set.quads.push_back({&q, 0.0f, static_cast<std::int32_t>(i)});
    quad_power.push_back(emitter_power(scene.materials[q.material], q.area));
  }
  for (std::size_t i = 0; i < scene.spheres.size(); ++i) {
    const Sphere& sp = scene.spheres[i];
    if (!pick(Target{Target::Kind::Sphere, static_cast<std::uint32_t>(i)})) continue;
    set.spheres.push_back({&sp, 0.0f});
    const double area = 4.0 * std::numbers::pi * static_cast<double>(sp.radius) * sp.radius;
    sphere_power.push_back(emitter_power(scene.materials[sp.material], area));
  }
  quad_power.insert(quad_power.end(), sphere_power.begin(), sphere_power.end());
  return quad_power;
}

// Power-proportional choice; a target that emits nothing (the book's glass
// sphere) gets the mean emitter's share, so it is still aimed at as often as
// an average light. All-zero powers fall back to uniform.
std::vector<double> power_weights(std::vector<double> power) {
  double sum = 0.0;
  int emitting = 0;
  for (double p : power)
    if (p > 0.0) sum += p, ++emitting;
  const double stand_in = emitting ? sum / emitting : 1.0;
  for (double& p : power)
    if (!(p > 0.0)) p = stand_in;
  return power;
}

}  // namespace

SamplingPlan SamplingPlan::make(const Strategy& strategy, const Scene& scene) {
  SamplingPlan plan;
  plan.scene = &scene;
  plan.nee_mis = strategy.nee_mis;
  plan.heuristic = strategy.heuristic;

  auto is_target = [&](const Target& t) {
    for (const Target& x : scene.targets)
      if (x.kind == t.kind && x.index == t.index) return true;
    return false;
  };
  auto is_emitter = [&](const Target& t) {
    const std::uint32_t m = t.kind == Target::Kind::Quad ? scene.quads[t.index].material : scene.spheres[t.index].material;
    return scene.materials[m].type == MaterialType::DiffuseLight;
  };
  const std::vector<double> book_power = collect_targets(scene, plan.book_targets, is_target);
  plan.book_targets.set_probabilities(std::vector<double>(book_power.size(), 1.0));
  plan.target_count = plan.book_targets.size();
  (void)collect_targets(scene, plan.power_targets, is_target);
  plan.power_targets.solid_angle = true;
  plan.power_targets.set_probabilities(power_weights(book_power));
  const std::vector<double> emitter_powers = collect_targets(scene, plan.emitters, is_emitter);
  plan.emitters.solid_angle = true;
  plan.emitters.set_probabilities(power_weights(emitter_powers));

  if (strategy.nee_mis) {
    plan.weight[static_cast<int>(Technique::Cosine)] = 1.0f;  // the material sample
    plan.last_technique = static_cast<int>(Technique::Cosine);
    plan.uses_frame = true;
    return plan;
  }

  plan.parameter = strategy.parameters;
  std::array<float, kTechniqueCount> w = strategy.weights;
  // A technique that aims at targets has nothing to aim at: its weight goes to
  // the other techniques (renormalised below).
  if (plan.target_count == 0)
    for (int i = 0; i < kTechniqueCount; ++i)
      if (kTable[i].draws_target) w[i] = 0.0f;
  double total = 0.0;
  for (float x : w) total += x;
  if (!(total > 0.0))
    throw InputError("strategy '" + strategy.to_string() + "' samples only the importance targets, but scene '" +
                     scene.name + "' has none");
  // The choice is made by a 32-bit number against thresholds fixed here, and
  // the mixture's pdf uses the shares those thresholds realise: the sampler and
  // the pdf agree exactly, for any weight down to 2^-32 of the total. A float
  // compared with a float CDF realised 1e-9 as 0 or 2^-24 while the pdf divided
  // by 1e-9 (an image 45 times too bright); below 2^-32 there is no share to give.
  std::array<double, kTechniqueCount> wd{};
  for (int i = 0; i < kTechniqueCount; ++i) wd[i] = w[i];
  const DiscreteDistribution choice(wd, DiscreteDistribution::Tiny::Zero);
  if (!choice.zero_positive().empty()) {
    const int i = choice.zero_positive().front();
    char share[32];
    std::snprintf(share, sizeof share, "%.3g", wd[i] / total);
    throw InputError("strategy '" + strategy.to_string() + "': " + std::string(kTable[i].name) + "'s share " + share +
                     " of the weights is below 2^-32 (2.3e-10), the smallest probability the sampler can give a "
                     "technique; use 0 or a larger weight");
  }
  for (int i = 0; i < kTechniqueCount; ++i) {
    plan.weight[i] = choice.pmf(i);
    plan.choice_threshold[i] = choice.thresholds()[static_cast<std::size_t>(i)];
  }
  plan.last_technique = choice.last_positive();
#define PDFLAB_ROW(T) \
  plan.uses_frame = plan.uses_frame || (leaf::uses_frame<leaf::T>() && plan.weight[static_cast<int>(Technique::T)] > 0.0f);
  PDFLAB_TECHNIQUES(PDFLAB_ROW)
#undef PDFLAB_ROW
  return plan;
}

float SamplingPlan::pdf(const Vec3& origin, const Vec3& normal, const Vec3& direction) const {
  return leaf::mixture_pdf(*this, leaf::Shading(*this, origin, normal, 0.0f, 0.0f, 0), direction, true);
}

DirectionSample SamplingPlan::sample(const Vec3& origin, const Vec3& normal, Rng& rng, int* technique) const {
  const auto u0 = static_cast<std::int32_t>(rng.next_u32());
  const float u1 = rng.uniform();
  const float u2 = rng.uniform();
  const int chosen = leaf::choose_technique(*this, u0);
  if (technique) *technique = chosen;
  const auto u_choice = leaf::draws_target(*this, chosen) ? static_cast<std::int32_t>(rng.next_u32()) : 0;
  return to_direction_sample(leaf::sample_mixture(*this, leaf::Shading(*this, origin, normal, u1, u2, u_choice), chosen, true));
}

}  // namespace pdflab
