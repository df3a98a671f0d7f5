#pragma once
// A sampling strategy: which techniques draw the scattered direction at a
// diffuse bounce and with which weights. A small value decided once per pass;
// nothing here allocates per ray.
#include "renderer/math.h"
#include "renderer/sampling/rng.h"
#include "renderer/sampling/techniques.h"
#include "renderer/scene/scene.h"

#include <array>
#include <string>
#include <string_view>
#include <vector>

namespace pdflab {

enum class Technique : std::uint8_t { Cosine, UniformHemisphere, UniformSphere, Light, Count };
inline constexpr int kTechniqueCount = static_cast<int>(Technique::Count);

std::string_view technique_name(Technique t);

// As typed by the user: `cosine`, `mix:cosine=1,light=3`, ... Weights are kept as
// given (normalised by SamplingPlan). Parsing validates; see INTERFACE.md.
struct Strategy {
  std::array<float, kTechniqueCount> weights{};

  static Strategy parse(std::string_view text);  // throws InputError
  static Strategy single(Technique t);
  std::string to_string() const;  // canonical form, parses back to the same value

  // Unbiased iff some technique with positive weight covers the whole
  // hemisphere above a diffuse surface (light techniques cover only the targets).
  bool is_unbiased() const;
  bool uses(Technique t) const { return weights[static_cast<int>(t)] > 0.0f; }
};

// A strategy bound to a scene: normalised weights, the techniques' cumulative
// distribution, and the importance targets. Built once per render/pass; it
// points into the scene, which must outlive it and stay where it is.
struct SamplingPlan {
  std::array<float, kTechniqueCount> weight{};  // normalised, sum to 1
  std::array<float, kTechniqueCount> cdf{};     // cdf[i] = weight[0] + ... + weight[i]
  const Scene* scene = nullptr;
  int target_count = 0;
  float inv_target_count = 0.0f;
  // The targets split by kind, so evaluating the light pdf needs no per-target switch.
  std::vector<const Quad*> quad_targets;
  std::vector<const Sphere*> sphere_targets;

  // Throws InputError when the strategy needs targets the scene does not have
  // and no other technique has weight.
  static SamplingPlan make(const Strategy& strategy, const Scene& scene);

  // Draws a direction from the mixture and returns it with the mixture's pdf
  // sum_i w_i p_i(direction). `normal` faces the incoming ray's side.
  DirectionSample sample(const Vec3& origin, const Vec3& normal, Rng& rng) const;
  // The mixture's pdf for any unit direction.
  float pdf(const Vec3& origin, const Vec3& normal, const Vec3& direction) const;

  // The `light` technique alone: uniform choice among targets, then area/cone sampling.
  DirectionSample sample_light(const Vec3& origin, float u_target, float u1, float u2) const;
  float light_pdf(const Vec3& origin, const Vec3& direction) const;

 private:
  // Sum of the per-target pdfs, leaving out the target at `skip` (or none).
  float light_pdf_sum(const Vec3& origin, const Vec3& direction, const void* skip) const;
};

}  // namespace pdflab
