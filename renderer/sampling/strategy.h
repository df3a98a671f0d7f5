#pragma once
// A sampling strategy: which techniques draw the scattered direction at a
// diffuse bounce and with which weights, or next-event estimation with MIS.
// A small value decided once per pass; nothing here allocates per ray.
#include "renderer/math.h"
#include "renderer/sampling/discrete.h"
#include "renderer/sampling/rng.h"
#include "renderer/sampling/target_set.h"
#include "renderer/sampling/technique_table.h"
#include "renderer/sampling/techniques.h"
#include "renderer/scene/scene.h"

#include <array>
#include <string>
#include <string_view>
#include <vector>

namespace pdflab {

// The technique table's row for `t`, and its name.
const TechniqueInfo& technique_info(Technique t);

// The strategy grammar and every technique in the table (what it draws, its
// pdf, whether it is biased alone): the text of `--help`.
std::string strategy_help();
std::string_view technique_name(Technique t);

// As typed by the user: `cosine`, `mix:cosine=1,light=3`, `nee-mis`,
// `nee-mis:balance`... Mixture weights are kept as given (normalised by
// SamplingPlan). Parsing validates; see README.md.
struct Strategy {
  std::array<float, kTechniqueCount> weights{};
  // Each technique's parameter (TechniqueInfo::parameter; `cosine-power:8`),
  // its default where the technique has one, else 0.
  std::array<float, kTechniqueCount> parameters = default_parameters();
  // Next-event estimation: at each diffuse vertex one light sample (shadow ray,
  // solid-angle sampling of the emitters chosen by power) and one cosine
  // sample, combined with multiple importance sampling. `weights` is unused.
  bool nee_mis = false;
  MisHeuristic heuristic = MisHeuristic::Power;

  static std::array<float, kTechniqueCount> default_parameters();
  static Strategy parse(std::string_view text);  // throws InputError
  static Strategy single(Technique t);
  static Strategy nee(MisHeuristic h = MisHeuristic::Power);
  std::string to_string() const;  // canonical form, parses back to the same value

  // Unbiased iff some technique with positive weight covers the whole
  // hemisphere above a diffuse surface (TechniqueInfo::covers_hemisphere).
  bool is_unbiased() const;
  bool uses(Technique t) const { return !nee_mis && weights[static_cast<int>(t)] > 0.0f; }
  bool operator==(const Strategy&) const = default;
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
  bool uses_frame = false;  // a technique with weight draws in the shading frame
  const Scene* scene = nullptr;
  bool nee_mis = false;
  MisHeuristic heuristic = MisHeuristic::Power;

  TargetSet book_targets;   // `light`: the importance targets, chosen uniformly
  TargetSet power_targets;  // `light-sa`: the importance targets, emitters by power
  TargetSet emitters;       // `nee-mis`: every emitter, by power
  int target_count = 0;     // importance targets

  // Throws InputError when the strategy needs targets the scene does not have
  // and no other technique has weight, or when a positive weight is below
  // 2^-32 of the total (the sampler could not realise it).
  static SamplingPlan make(const Strategy& strategy, const Scene& scene);

  // Draws a direction from the mixture and returns it with the mixture's pdf
  // sum_i w_i p_i(direction). `normal` faces the incoming ray's side.
  // `technique`, when given, receives which technique drew the direction.
  DirectionSample sample(const Vec3& origin, const Vec3& normal, Rng& rng, int* technique = nullptr) const;
  // The mixture's pdf for any unit direction.
  float pdf(const Vec3& origin, const Vec3& normal, const Vec3& direction) const;

  // The steps of make, once `scene` is set: the target sets; then either
  // nee-mis's one material sample, or the strategy's techniques with their
  // realised shares.
  void bind_targets();
  void use_material_sample_only();
  void set_technique_choice(const Strategy& strategy);
};

}  // namespace pdflab
