#pragma once
// A sampling strategy: which techniques draw the scattered direction at a
// diffuse bounce and with which weights, or next-event estimation with MIS.
// A small value decided once per pass; nothing here allocates per ray.
#include "renderer/math.h"
#include "renderer/sampling/discrete.h"
#include "renderer/sampling/guiding.h"
#include "renderer/sampling/rng.h"
#include "renderer/sampling/target_set.h"
#include "renderer/sampling/technique_table.h"
#include "renderer/sampling/techniques.h"
#include "renderer/scene/environment.h"
#include "renderer/scene/scene.h"

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace pdflab {

// The technique table's row for `t`, and its name.
const TechniqueInfo& technique_info(Technique t);

// The strategy grammar and every technique in the table (what it draws, its
// pdf, whether it is biased alone): the text of `--help`.
std::string strategy_help();
// The TECHNIQUE := line of the grammar, and the technique table as Markdown
// (name, what it draws, its pdf, whether it is biased or heavy-tailed alone):
// README.md holds both, and a test checks them against these.
std::string technique_grammar();
std::string technique_table_markdown();
// Which vertices the `+sobol` sampler stratifies, in words ("the first
// vertex's", from qmc::kDepths), for the help and the panel.
std::string stratified_vertices();
std::string_view technique_name(Technique t);

// What `fastest` expands to: pdflab's most efficient unbiased strategy for
// general scenes, by measurement on the shipped scenes (docs/convergence.md,
// scripts/fastest_report.sh). Next-event estimation (its light sample by area
// where a light looks flat, emitter_set) with the Sobol sampler (the stratified
// light sample at the first vertices is the lever wherever light comes straight
// from the emitters). Its continuation gives a fifth of its samples to the
// scene's glass and metal objects (specular-objects): the light they carry (the
// book's caustic and the light its glass sphere throws on the ceiling, a metal
// box's reflections) is what a light sample cannot reach; in a scene without
// glass or metal that share has no weight and the continuation is cosine alone.
// Russian roulette from the tenth segment: it cuts the long paths of the closed
// boxes, where nee-mis pays two rays a bounce, but a survivor's throughput is
// divided by its chance, so a caustic that a survivor finds late (through the
// book's glass sphere) comes back as a rare heavy sample: from the fifth segment
// the book's box lost 40% of the eighth's efficiency while the metal boxes
// gained 9-11%; from the tenth the book's box (the default scene) gains 4-5%
// over the eighth and the six other scenes lose 0-6%.
inline constexpr std::string_view kFastestStrategy = "nee-mis+mix:cosine=0.8,specular-objects=0.2+sobol+rr:10";

// What `fastest` is instead where a scene says its light is hard to find
// (Scene::fastest_uses_guiding, the scene file's `fastest_uses_guiding`:
// door_ajar.json, its lamp behind a partition): path guiding's mixture with
// the roulette by the learned light, 2.23x kFastestStrategy's efficiency there
// at equal time with its training (docs/guiding.md, "Measured"). Not for
// general scenes: where nee-mis finds the light from everywhere, guiding adds
// its training and its cost per sample for nothing.
inline constexpr std::string_view kFastestGuidedStrategy = "nee-mis+mix:cosine=0.3,guided=0.7+sobol+rr:guided";

// Russian roulette's default first depth, and the largest one accepted.
inline constexpr int kDefaultRouletteDepth = 3;
inline constexpr int kMaxRouletteDepth = 10000;
// `+rr:guided`'s rule (Strategy::guided_roulette): a path goes on with
// probability min(1, max(kGuidedRouletteScale r, the throughput rule's q)).
// The scale sets how far below its share of the pixel's light a path may
// fall before it is cut (docs/guiding.md: 3 to 30 measured, 5 to 10 alike).
inline constexpr float kGuidedRouletteScale = 5.0f;

// As typed by the user: `cosine`, `mix:cosine=1,light=3`, `nee-mis`,
// `nee-mis:balance`, `nee-mis+mix:cosine=0.5,light=0.5`, any of them with
// `+sobol` and `+rr` or `+rr:D`, or `fastest`... Mixture weights are kept as given
// (normalised by SamplingPlan). Parsing validates; see README.md.
struct Strategy {
  // The techniques that draw the direction at a diffuse bounce; for nee-mis,
  // the continuation's (cosine alone for plain `nee-mis`).
  std::array<float, kTechniqueCount> weights{};
  // Each technique's parameter (TechniqueInfo::parameter; `cosine-power:8`),
  // its default where the technique has one, else 0.
  std::array<float, kTechniqueCount> parameters = default_parameters();
  // Next-event estimation: at each diffuse vertex one light sample (shadow ray;
  // the emitters chosen by power, each sampled in solid angle or, where it
  // looks flat, by area: emitter_set) and one sample of
  // `weights` that continues the path, combined with multiple importance
  // sampling.
  bool nee_mis = false;
  MisHeuristic heuristic = MisHeuristic::Power;
  // Russian roulette from path depth D = roulette_depth on (0: off, the book's
  // estimator): at a diffuse vertex whose continuation would be segment D or
  // later (the camera ray is segment 0), before the continuation is drawn, the
  // path goes on with probability min(1, largest component of throughput *
  // albedo), its throughput divided by that (leaf::roulette_survives).
  int roulette_depth = 0;
  // `+rr:guided` (a strategy with the guided technique): Russian roulette by
  // the light the guide learned (after Vorba and Krivanek's adjoint-driven
  // roulette): at every diffuse vertex after the path's first, it goes on with
  // probability min(1, max(kGuidedRouletteScale r, the throughput rule's q)),
  // r the light it is expected to bring from there (throughput x albedo x the
  // learned light at the vertex) over what it was expected to bring at its
  // first diffuse vertex. Where the guide has learned nothing, the throughput
  // rule from roulette_depth. docs/guiding.md, "The roulette by the learned light".
  bool guided_roulette = false;
  // `+sobol`: the first diffuse and specular vertices' draws (the continuation's
  // technique and direction, the light sample's emitter and point, a specular
  // bounce's numbers) at path depths below qmc::kDepths come from Owen-scrambled
  // Sobol points across a pixel's samples (renderer/sampling/sobol.h), every
  // other draw from the sample's pcg stream as before (off: the independent
  // sampler, every draw from the stream). Unbiased either way.
  bool sobol = false;
  // `+lights:NAME` (nee-mis only): how the light sample's emitter is chosen
  // (LightChoice: power, uniform or tree); none: the scene's (Scene::light_choice).
  std::optional<LightChoice> light_choice;
  // Parsed from `fastest`: the fields above are what it expanded to
  // (kFastestStrategy), which to_string gives; sidecars record both.
  bool fastest = false;

  static std::array<float, kTechniqueCount> default_parameters();
  static Strategy parse(std::string_view text);  // throws InputError
  static Strategy single(Technique t);
  static Strategy nee(MisHeuristic h = MisHeuristic::Power);
  std::string to_string() const;  // canonical form, parses back to the same value
  // The continuation of a nee-mis strategy is cosine alone (plain `nee-mis`).
  bool cosine_continuation() const;

  // Unbiased iff some technique with positive weight covers the whole
  // hemisphere above a diffuse surface with its parameter (TechniqueInfo::bias
  // is empty); for nee-mis, the continuation's. Russian roulette changes
  // nothing here.
  bool is_unbiased() const;
  // Why the strategy is biased, naming each technique and what it misses
  // ("light sees only its targets"); empty when it is unbiased.
  std::string bias_reason() const;
  bool uses(Technique t) const { return weights[static_cast<int>(t)] > 0.0f; }
  bool operator==(const Strategy&) const = default;

 private:
  std::string mixture_string() const;  // the techniques and weights alone
};

// `strategy` as it runs on `scene`: `fastest` there is kFastestGuidedStrategy
// where the scene says so (Scene::fastest_uses_guiding), with the sampler,
// the light choice and a roulette depth given to `fastest` kept; every other
// strategy as it is. Wherever a strategy meets its scene (a render, the
// viewer, bench, a reference), so that what is reported is what ran.
Strategy for_scene(const Strategy& strategy, const Scene& scene);

// Whether +rr:guided holds in `strategy` where it is `wanted`: it needs a
// roulette and the guided technique (a sweep's member at w = 1 has none, and
// the viewer's box outlives a change of technique).
inline bool guided_roulette_holds(const Strategy& strategy, bool wanted) {
  return wanted && strategy.roulette_depth > 0 && strategy.uses(Technique::Guided);
}

// `strategy` with Russian roulette from `depth` on (the command lines' --rr);
// depth 0 leaves it as it is.
inline Strategy with_roulette(Strategy strategy, int depth) {
  if (depth > 0) strategy.roulette_depth = depth;
  return strategy;
}

// The surface a continuation is drawn at, for the `bsdf` technique: lambertian
// (its lobe is the cosine lobe), or a microfacet conductor of GGX roughness
// `alpha` seen from `outgoing` (unit, on the normal's side); where
// `transmits`, a rough dielectric of relative index `eta` (the index beyond
// the surface over the index on the normal's side).
struct SurfaceLobe {
  bool glossy = false;
  float alpha = 1.0f;
  Vec3 outgoing{0.0f, 0.0f, 1.0f};
  bool transmits = false;
  float eta = 1.0f;
};

// A strategy bound to a scene: normalised weights, the techniques' cumulative
// distribution, and the target sets. Built once per render; it points into the
// scene, which must outlive it and stay where it is.
struct SamplingPlan {
  // The realised probability of each technique (normalised weights in
  // multiples of 2^-32): exactly how often the sampler chooses it.
  std::array<float, kTechniqueCount> weight{};
  // The choice by a 32-bit number (DiscreteDistribution::sample's form):
  // technique = min(number of thresholds <= u, last_technique).
  std::array<std::uint32_t, kTechniqueCount> choice_threshold{};
  int last_technique = 0;
  std::array<float, kTechniqueCount> parameter{};  // Strategy::parameters
  // What each technique derives from its parameter, once per plan
  // (TechniqueConstants; zero for a technique that derives nothing).
  std::array<TechniqueConstants, kTechniqueCount> constants{};
  bool uses_frame = false;  // a technique with weight draws in the shading frame
  const Scene* scene = nullptr;
  bool nee_mis = false;
  MisHeuristic heuristic = MisHeuristic::Power;
  // nee-mis: the continuation is cosine alone, whose f cos / p is exactly the
  // albedo; with several techniques in it the continuation draws u0 to choose.
  bool cosine_continuation = false;
  bool continuation_mixes = false;
  int roulette_depth = 0;  // Strategy::roulette_depth
  bool guided_roulette = false;  // Strategy::guided_roulette
  bool sobol = false;      // Strategy::sobol
  // Whether the vertex reached by segment `depth` takes its draws from the
  // `+sobol` sampler's stratified points (depth -1: never).
  bool stratifies(int depth) const;

  TargetSet book_targets;   // `light`: the importance targets, chosen uniformly
  TargetSet power_targets;  // `light-sa`: the importance targets, emitters by power
  TargetSet emitters;       // `nee-mis`: every emitter, chosen by light_choice
  LightChoice light_choice = LightChoice::Power;  // the strategy's, else the scene's
  TargetSet specular_objects;  // `specular-objects`: the glass and metal objects, chosen uniformly
  // The scene's environment light where it has light (`environment`'s map;
  // null: none), and the probability that nee-mis's light sample samples it
  // rather than the area lights (environment_light_share).
  const Environment* environment = nullptr;
  float environment_share = 0.0f;
  // `guided`'s learned distribution (null: untrained, the uniform sphere);
  // set by whoever trains it (RenderSession), which keeps it alive.
  const GuidingDistribution* guiding = nullptr;

  // Throws InputError when the strategy needs targets the scene does not have
  // and no other technique has weight, or when a positive weight is below
  // 2^-32 of the total (the sampler could not realise it).
  static SamplingPlan make(const Strategy& strategy, const Scene& scene);

  // Draws a direction from the mixture and returns it with the mixture's pdf
  // sum_i w_i p_i(direction). `normal` faces the incoming ray's side.
  // `technique`, when given, receives which technique drew the direction.
  // `depth`: the path depth of the vertex (the camera ray is segment 0), for
  // the `+sobol` sampler's stratified draws; -1: every draw from `rng`.
  // `surface`: the surface drawn at (the `bsdf` technique's lobe there;
  // nullptr: lambertian).
  DirectionSample sample(const Vec3& origin, const Vec3& normal, Rng& rng, int* technique = nullptr,
                         int depth = -1, const SurfaceLobe* surface = nullptr) const;
  // The same draw from given numbers instead of a stream: u1, u2 in [0, 1)
  // for the direction, 32 bits for the choice of the technique and 32 for the
  // target (used only where the chosen technique draws one). For checking a
  // technique against one's own inverse CDF at the very same numbers.
  // `top_log2`: log2(1 - u1) where u1 is its largest value (kLargestUniform)
  // and the technique draws the tail (leaf::Shading::top_log2; -24: undrawn).
  DirectionSample sample_at(const Vec3& origin, const Vec3& normal, float u1, float u2, std::uint32_t u_technique,
                            std::uint32_t u_target, int* technique = nullptr, float top_log2 = -24.0f) const;
  // The same at a given surface (the `bsdf` technique's lobe there); `u_lobe`
  // in [0, 1) chooses reflection or refraction at a rough dielectric.
  DirectionSample sample_at(const SurfaceLobe& surface, const Vec3& origin, const Vec3& normal, float u1, float u2,
                            std::uint32_t u_technique, std::uint32_t u_target, int* technique = nullptr,
                            float top_log2 = -24.0f, float u_lobe = 0.0f) const;
  // The mixture's pdf for any unit direction (aimed_quad: as TargetSet::pdf).
  float pdf(const Vec3& origin, const Vec3& normal, const Vec3& direction, int aimed_quad = -1,
            float aimed_t = 0.0f) const;
  // The mixture's pdf at a given surface.
  float pdf(const SurfaceLobe& surface, const Vec3& origin, const Vec3& normal, const Vec3& direction) const;

  // The steps of make, once `scene` is set: the target sets; then the
  // strategy's techniques (for nee-mis, its continuation's) with their
  // realised shares.
  void bind_targets();
  void set_technique_choice(const Strategy& strategy);
};

}  // namespace pdflab
