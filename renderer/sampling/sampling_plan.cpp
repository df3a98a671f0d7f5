#include "renderer/sampling/strategy.h"

#include "renderer/sampling/mixture.h"
#include "renderer/sampling/sobol.h"

#include "renderer/error.h"

#include <cstdio>

namespace pdflab {

namespace {

// Whether technique T aims at targets of which the plan's scene has none.
template <class T>
bool aims_at_nothing(const SamplingPlan& plan) {
  if constexpr (requires { T::targets(plan); }) return T::targets(plan).empty();
  else return false;
}

// The strategy's weights, less those of techniques that aim at targets the
// scene does not have (their weight goes to the others, renormalised by the
// choice). Throws when no weight is left.
std::array<double, kTechniqueCount> usable_weights(const Strategy& strategy, const SamplingPlan& plan) {
  std::array<double, kTechniqueCount> w{};
  double total = 0.0;
  std::string missing;  // the techniques with weight that have nothing to aim at
#define PDFLAB_ROW(T)                                                                  \
  {                                                                                    \
    const int i = static_cast<int>(Technique::T);                                      \
    const bool nothing = aims_at_nothing<leaf::T>(plan);                               \
    if (nothing && strategy.weights[i] > 0.0f)                                         \
      missing.append(missing.empty() ? "" : ", ").append(technique_info(Technique::T).name); \
    w[i] = nothing ? 0.0 : strategy.weights[i];                                        \
    total += w[i];                                                                     \
  }
  PDFLAB_TECHNIQUES(PDFLAB_ROW)
#undef PDFLAB_ROW
  if (!(total > 0.0))
    throw InputError("strategy '" + strategy.to_string() + "' samples only targets (" + missing + "), but scene '" +
                     plan.scene->name + "' has none");
  return w;
}

// The choice is made by a 32-bit number against thresholds fixed here, and
// the mixture's pdf uses the shares those thresholds realise: the sampler and
// the pdf agree exactly, for any weight down to 2^-32 of the total. A float
// compared with a float CDF realised 1e-9 as 0 or 2^-24 while the pdf divided
// by 1e-9 (an image 45 times too bright); below 2^-32 there is no share to give.
DiscreteDistribution technique_choice(const Strategy& strategy, const std::array<double, kTechniqueCount>& w) {
  DiscreteDistribution choice(w, DiscreteDistribution::Tiny::Zero);
  double total = 0.0;
  for (double x : w) total += x;
  // A share below 2^-32 that rounds up to one count (2^-33 and above) would
  // be realised larger than asked: refused like one that rounds to none.
  int tiny = choice.zero_positive().empty() ? -1 : choice.zero_positive().front();
  for (int i = 0; i < kTechniqueCount && tiny < 0; ++i)
    if (w[static_cast<std::size_t>(i)] > 0.0 && w[static_cast<std::size_t>(i)] / total < DiscreteDistribution::kResolution)
      tiny = i;
  if (tiny >= 0) {
    const int i = tiny;
    char share[32];
    std::snprintf(share, sizeof share, "%.3g", w[i] / total);
    throw InputError("strategy '" + strategy.to_string() + "': " +
                     std::string(technique_info(static_cast<Technique>(i)).name) + "'s share " + share +
                     " of the weights is below 2^-32 (2.3e-10), the smallest probability the sampler can give a "
                     "technique; use 0 or a larger weight");
  }
  return choice;
}

}  // namespace

void SamplingPlan::bind_targets() {
  book_targets = book_target_set(*scene);
  power_targets = power_target_set(*scene);
  emitters = emitter_set(*scene, light_choice);
  specular_objects = specular_object_set(*scene);
  environment = scene->environment && scene->environment->sampleable() ? scene->environment.get() : nullptr;
  environment_share = environment_light_share(*scene);
}

// Technique T's constants for parameter p, where it derives any.
template <class T>
TechniqueConstants derived_constants(float p) {
  if constexpr (requires { T::constants(p); }) return T::constants(p);
  else return {};
}

void SamplingPlan::set_technique_choice(const Strategy& strategy) {
  parameter = strategy.parameters;
#define PDFLAB_ROW(T) \
  constants[static_cast<int>(Technique::T)] = derived_constants<leaf::T>(parameter[static_cast<int>(Technique::T)]);
  PDFLAB_TECHNIQUES(PDFLAB_ROW)
#undef PDFLAB_ROW
  const DiscreteDistribution choice = technique_choice(strategy, usable_weights(strategy, *this));
  for (int i = 0; i < kTechniqueCount; ++i) {
    weight[i] = choice.pmf(i);
    choice_threshold[i] = choice.thresholds()[static_cast<std::size_t>(i)];
  }
  last_technique = choice.last_positive();
  int techniques = 0;
  for (int i = 0; i < kTechniqueCount; ++i) techniques += weight[i] > 0.0f ? 1 : 0;
  continuation_mixes = techniques > 1;
  // nee-mis's continuation is cosine alone when that is all the weight the
  // scene leaves it (fastest's specular-objects in a scene without glass or metal).
  cosine_continuation = nee_mis && techniques == 1 && weight[static_cast<int>(Technique::Cosine)] > 0.0f;
#define PDFLAB_ROW(T) \
  uses_frame = uses_frame || (leaf::uses_frame<leaf::T>() && weight[static_cast<int>(Technique::T)] > 0.0f);
  PDFLAB_TECHNIQUES(PDFLAB_ROW)
#undef PDFLAB_ROW
}

Strategy for_scene(const Strategy& strategy, const Scene& scene) {
  if (!strategy.fastest || !scene.fastest_uses_guiding) return strategy;
  static const Strategy general = Strategy::parse(kFastestStrategy);
  Strategy out = Strategy::parse(kFastestGuidedStrategy);
  out.fastest = true;
  out.sobol = strategy.sobol;
  out.light_choice = strategy.light_choice;
  // A roulette depth given to fastest (+rr:D, --rr) is the guided roulette's
  // fallback; none at all, none.
  if (strategy.roulette_depth != general.roulette_depth) out.roulette_depth = strategy.roulette_depth;
  out.guided_roulette = out.roulette_depth > 0;
  return out;
}

SamplingPlan SamplingPlan::make(const Strategy& strategy, const Scene& scene) {
  SamplingPlan plan;
  plan.scene = &scene;
  plan.nee_mis = strategy.nee_mis;
  plan.heuristic = strategy.heuristic;
  plan.roulette_depth = strategy.roulette_depth;
  plan.guided_roulette = strategy.guided_roulette;
  plan.sobol = strategy.sobol;
  plan.light_choice = strategy.light_choice.value_or(scene.light_choice);
  plan.bind_targets();
  plan.set_technique_choice(strategy);
  return plan;
}

float SamplingPlan::pdf(const Vec3& origin, const Vec3& normal, const Vec3& direction, int aimed_quad,
                        float aimed_t) const {
  leaf::Shading at(*this, origin, normal, 0.0f, 0.0f, 0);
  at.aimed_quad = aimed_quad;
  at.aimed_t = aimed_t;
  return leaf::mixture_pdf(*this, at, direction, true);
}

namespace {
void set_surface(leaf::Shading& at, const SurfaceLobe& surface) {
  at.glossy = surface.glossy;
  at.alpha = surface.alpha;
  at.outgoing = surface.outgoing;
  at.transmits = surface.glossy && surface.transmits;
  at.eta = surface.eta;
}
}  // namespace

float SamplingPlan::pdf(const SurfaceLobe& surface, const Vec3& origin, const Vec3& normal,
                        const Vec3& direction) const {
  leaf::Shading at(*this, origin, normal, 0.0f, 0.0f, 0);
  set_surface(at, surface);
  return leaf::mixture_pdf(*this, at, direction, true);
}

DirectionSample SamplingPlan::sample_at(const SurfaceLobe& surface, const Vec3& origin, const Vec3& normal, float u1,
                                        float u2, std::uint32_t u_technique, std::uint32_t u_target,
                                        int* technique, float top_log2, float u_lobe) const {
  const int chosen = leaf::choose_technique(*this, static_cast<std::int32_t>(u_technique));
  if (technique) *technique = chosen;
  const auto u_choice = leaf::draws_target(*this, chosen) ? static_cast<std::int32_t>(u_target) : 0;
  leaf::Shading at(*this, origin, normal, u1, u2, u_choice);
  set_surface(at, surface);
  at.top_log2 = top_log2;
  at.u_lobe = u_lobe;
  return to_direction_sample(leaf::sample_mixture(*this, at, chosen, true));
}

bool SamplingPlan::stratifies(int depth) const { return sobol && depth >= 0 && depth < qmc::kDepths; }

DirectionSample SamplingPlan::sample(const Vec3& origin, const Vec3& normal, Rng& rng, int* technique,
                                     int depth, const SurfaceLobe* surface) const {
  // nee-mis's continuation draws the technique's bits only when it mixes several.
  const bool draws_technique = !nee_mis || continuation_mixes;
  auto u0 = draws_technique ? static_cast<std::int32_t>(rng.next_u32()) : 0;
  float u1 = rng.uniform();
  float u2 = rng.uniform();
  if (stratifies(depth)) {
    // The stream stepped as above; the group's stratified point in its place.
    const qmc::Point<std::uint32_t> p = qmc::group_point(rng.qmc_index, rng.qmc_seed, static_cast<std::uint32_t>(depth),
                                                         qmc::Group::Continuation, 3);
    u1 = Rng::to_unit(p.dim[0]);
    u2 = Rng::to_unit(p.dim[1]);
    if (draws_technique) u0 = static_cast<std::int32_t>(p.dim[2]);
  }
  const int chosen = leaf::choose_technique(*this, u0);
  if (technique) *technique = chosen;
  const std::uint32_t u_target = leaf::draws_target(*this, chosen) ? rng.next_u32() : 0;
  // A rough dielectric's choice of reflection or refraction (path.inc's order).
  const float u_lobe = surface && surface->glossy && surface->transmits ? rng.uniform() : 0.0f;
  // u1's last cell drawn further where the technique needs it (path.inc's order).
  const float top_log2 = leaf::draws_tail(*this, chosen, u1) ? uniform_tail_log2([&] { return rng.next_u32(); }) : -24.0f;
  if (surface)
    return sample_at(*surface, origin, normal, u1, u2, static_cast<std::uint32_t>(u0), u_target, nullptr, top_log2,
                     u_lobe);
  return sample_at(origin, normal, u1, u2, static_cast<std::uint32_t>(u0), u_target, nullptr, top_log2);
}

DirectionSample SamplingPlan::sample_at(const Vec3& origin, const Vec3& normal, float u1, float u2,
                                        std::uint32_t u_technique, std::uint32_t u_target, int* technique,
                                        float top_log2) const {
  const int chosen = leaf::choose_technique(*this, static_cast<std::int32_t>(u_technique));
  if (technique) *technique = chosen;
  const auto u_choice = leaf::draws_target(*this, chosen) ? static_cast<std::int32_t>(u_target) : 0;
  leaf::Shading at(*this, origin, normal, u1, u2, u_choice);
  at.top_log2 = top_log2;
  return to_direction_sample(leaf::sample_mixture(*this, at, chosen, true));
}

}  // namespace pdflab

