#pragma once
// The targets a light technique aims at: which quads and spheres, with the
// probability of choosing each, and the three sets a sampling plan keeps.
#include "renderer/math.h"
#include "renderer/sampling/discrete.h"
#include "renderer/sampling/light_tree.h"
#include "renderer/sampling/techniques.h"
#include "renderer/scene/scene.h"

#include <cstdint>
#include <memory>
#include <vector>

namespace pdflab {


// Importance targets with the probability of choosing each, split by kind so
// that evaluating their pdf needs no per-target switch.
struct TargetSet {
  struct QuadEntry {
    const Quad* quad;
    float probability;  // its share of the choice (by_point: of the choice before the point's reweighting)
    std::int32_t index;  // in Scene::quads (DirectionSample::aimed_quad)
    RectangleAxes axes;  // for solid-angle sampling (leaf::spherical_rectangle)
  };
  struct SphereEntry {
    const Sphere* sphere;
    float probability;
    // Its row among the scene's objects, Scene::quads.size() + its index in
    // Scene::spheres: the id a ray aimed at it carries (Sampled::aimed_quad).
    std::int32_t index;
  };
  std::vector<QuadEntry> quads;
  std::vector<SphereEntry> spheres;
  // Which target a 32-bit number chooses (over quads, then spheres); each
  // entry's `probability` is exactly its realised share.
  DiscreteDistribution choice;
  bool solid_angle = false;  // quads by spherical rectangle instead of by area
  // Light choice by what the point receives (set_probabilities, on a set by
  // solid angle of two or more targets): from a point behind a one-sided
  // emitter that emitter's share goes to the lights in front, and a fraction
  // kLightChoiceFloor of the choices is uniform, a defensive floor: no target
  // is chosen with less than kLightChoiceFloor / size() (a dim light beside a
  // 1e9 times brighter one keeps 5% of the choices, not 1e-9). The choice's
  // probabilities at a point are quantised to multiples of 2^-24, which is how
  // a 32-bit number's top 24 bits choose (leaf::TargetChoice): each target's
  // probability is exactly its realised share.
  bool by_point = false;
  // by_point: each target's probability from a point that receives from every
  // target (the choice's usual case, fixed), and the one-sided quads (indices
  // in `quads`), whose sides decide whether a point does.
  std::vector<float> everywhere;
  std::vector<std::uint32_t> everywhere_threshold;  // C_j 2^32 for all but the last target
  // Empty where the choice cannot depend on the point (fewer than two lights:
  // a share has nowhere to go).
  std::vector<int> one_sided;
  bool lit_everywhere = false;  // some light is not one-sided: every point receives from it
  // Whether each target emits (light-sa's glass sphere does not: it keeps its
  // share wherever the point is; empty: all do), and the emitters' total share.
  std::vector<unsigned char> emits;
  float emitter_share = 1.0f;
  // The light tree that chooses the target from each point (LightChoice::Tree;
  // null: `choice`, or by_point). With it the integrator weighs a light sample
  // by the density of the emitter it reaches alone (probability of choosing
  // that emitter times its own density), so that neither the sample nor the
  // density of a continuation that finds an emitter visits the others; `pdf`
  // and `sample` still give the set's whole density (the sum), for the tests.
  std::shared_ptr<const LightTree> tree;
  // With a tree: each scene object's index in the set (Scene::quads, then
  // Scene::spheres, the ids a hit carries), -1 for those not in it.
  std::vector<std::int32_t> target_of;

  bool empty() const { return quads.empty() && spheres.empty(); }
  int size() const { return static_cast<int>(quads.size() + spheres.size()); }
  // Probabilities proportional to `weights` (same order: quads, then spheres),
  // realised in multiples of 2^-32; a target with a positive weight below that
  // keeps a share of 2^-32, so that it is still reached (a light 1e-12 as
  // bright as another is still sampled, with the pdf saying how rarely).
  void set_probabilities(const std::vector<double>& weights);

  // A direction towards one target (chosen by the 32-bit number u_choice), its
  // pdf being the set's: sum over targets of probability * per-target pdf. The
  // chosen target's density comes from its sampler, the others' from evaluation.
  DirectionSample sample(const Vec3& origin, std::uint32_t u_choice, float u1, float u2) const;
  // `aimed_quad` (an index in Scene::quads, -1: none): the direction is known to
  // reach that quad at distance aimed_t (DirectionSample::aimed_quad), so its
  // term holds even for a sliver float's intersection test would miss.
  float pdf(const Vec3& origin, const Vec3& direction, int aimed_quad = -1, float aimed_t = 0.0f) const;
  // The probability of choosing each target (quads, then spheres) from `origin`:
  // `probability` itself unless by_point or by a tree (whose choice also reads
  // the point's normal, facing where light arrives from; zero: none).
  std::vector<float> probabilities_at(const Vec3& origin, const Vec3& normal = Vec3(0.0f)) const;
  // The smallest 32-bit u_choice that chooses target j from `origin` (its
  // probability there must be positive).
  std::uint32_t first_choice_of(const Vec3& origin, int j) const;
  // Whether `origin` receives light from target j: false only behind a
  // one-sided emitter (in front: its plane's side that u x v points to).
  bool receives(const Vec3& origin, int j) const;

 private:
  float pdf_without(const Vec3& origin, const Vec3& direction, const void* skip, int aimed_quad = -1,
                    float aimed_t = 0.0f) const;
};

// TargetSet::by_point's defensive floor: the fraction of a point's light
// choices that is uniform over the targets.
inline constexpr float kLightChoiceFloor = 0.02f;

// `light`'s set: the scene's importance targets, chosen uniformly.
TargetSet book_target_set(const Scene& scene);
// `light-sa`'s: the importance targets by solid angle, chosen in proportion to
// their power (a target that emits nothing gets the mean emitter's share) and
// to what the point receives (TargetSet::by_point).
TargetSet power_target_set(const Scene& scene);
// nee-mis's: every emitter of the scene by solid angle, chosen by power and by
// what the point receives (TargetSet::by_point), quads by solid angle except
// where a rectangle looks flat: from a point whose distances to the light's
// points differ by at most kEmitterFlatDistanceRatio it is sampled by area
// (RectangleAxes::flat_distance_ratio), whose density is then within the cube
// of that ratio of uniform in solid angle. Measured (README): on the book's box
// the same error as solid angle everywhere at 28% less time a sample; a small
// light is flat from everywhere, and sampled by area in a third of the time its
// spherical rectangle took (below float's domain, it took the double form); the
// large light loses 8% (its floor sees it flat, where solid angle did better).
inline constexpr float kEmitterFlatDistanceRatio = 2.0f;
// `choice`: how the emitter is chosen (LightChoice; Power is the above).
TargetSet emitter_set(const Scene& scene, LightChoice choice = LightChoice::Power);
// `specular-objects`'s: every quad and sphere of glass or metal, chosen
// uniformly, quads by area (what carries caustics and light seen in mirrors,
// which a light sample cannot reach through).
TargetSet specular_object_set(const Scene& scene);

// nee-mis's light sample in a scene with an environment light: the
// probability that it samples the environment (its own 2D distribution),
// else the area lights (emitter_set). 1 without area lights, 0 without an
// environment that has light; otherwise in proportion to power, the map's
// taken as what it sends through a disc of the scene's bounding radius
// (pi R^2 times its luminance integrated over the sphere), and kept within
// [kEnvironmentShareFloor, 1 - kEnvironmentShareFloor] so that neither light
// is starved where power misjudges what a point receives (a room lit through
// a window). A multiple of 2^-24: the top 24 bits of a 32-bit number choose,
// and the share is exactly the realised probability.
inline constexpr float kEnvironmentShareFloor = 0.1f;
float environment_light_share(const Scene& scene);

// How much light an emitter sends out (luminance of emit * area * pi, doubled
// when two-sided): the weight for choosing it in proportion to its power.
double emitter_power(const Material& m, double area);

}  // namespace pdflab
