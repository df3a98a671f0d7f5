#pragma once
// The scene as flat arrays of plain structs. Boxes are already six quads and
// rotations/translations are baked into the geometry by the loader.
#include "renderer/math.h"
#include "renderer/scene/bvh.h"

#include <array>
#include <memory>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace pdflab {

class Environment;  // renderer/scene/environment.h

// Microfacet: a rough surface of GGX / Trowbridge-Reitz normals of roughness
// `alpha` with height-correlated Smith masking-shadowing: a conductor (the
// exact conductor Fresnel of the complex index eta + i k per channel),
// reflecting only, or where `transmits` a rough dielectric of index `ior`
// (Walter et al. 2007: reflection and refraction through one microfacet,
// chosen by the exact dielectric Fresnel term).
enum class MaterialType : std::uint8_t { Lambertian, Metal, Dielectric, DiffuseLight, Microfacet };

struct Material {
  MaterialType type = MaterialType::Lambertian;
  Vec3 albedo{0.0f};
  Vec3 emit{0.0f};
  float fuzz = 0.0f;
  float ior = 1.0f;
  bool exact_fresnel = false;  // dielectric only: the exact Fresnel reflectance, not Schlick's
  bool two_sided = false;  // diffuse_light only
  // microfacet only: GGX roughness and the conductor's complex index of
  // refraction (relative to the air outside), per channel.
  float alpha = 1.0f;
  Vec3 eta{1.0f};
  Vec3 k{0.0f};
  // microfacet only: a rough dielectric (frosted glass) of index `ior`
  // (relative to the air outside; the front side is outside), not a conductor.
  bool transmits = false;
};

// The microfacet roughness range the loader accepts: below 1e-3 the lobe is
// narrower than float resolves around the mirror direction.
inline constexpr float kMinMicrofacetAlpha = 1e-3f;

// A parallelogram: corner q, edges u and v. Front face normal is u x v.
struct Quad {
  Vec3 q, u, v;
  Vec3 normal;      // unit u x v
  float plane_d;    // dot(normal, q)
  Vec3 alpha_axis;  // dot(p - q, alpha_axis) is the coordinate along u in [0, 1]
  Vec3 beta_axis;   // likewise along v
  float area;
  std::uint32_t material;
};

// The largest radius a sphere is intersected in float at (Scene::prepare):
// the float test squares lengths up to 56 radii, which overflow above 2^58.
inline constexpr float kLargestFloatTestRadius = 0x1.0p57f;

struct Sphere {
  Vec3 center;
  float radius;
  std::uint32_t material;
  // Intersected in float rather than double (leaf::sphere_hit_distance); set
  // by Scene::prepare for a sphere large against the scene.
  bool float_test = false;
  // leaf::sphere_hit_error's `float_radius`: the radius where tested in float, else 0.
  float float_radius() const { return float_test ? radius : 0.0f; }
};

// Builds a quad with its derived plane data (computed in double). Throws
// nothing: callers check quad_problem first.
Quad make_quad(const Vec3& q, const Vec3& u, const Vec3& v, std::uint32_t material);
// Empty when edges u and v make a quad whose plane data single precision can
// hold; otherwise the true reason (an edge is zero, the edges are parallel, the
// area overflows or underflows float).
std::string quad_problem(const Vec3& u, const Vec3& v);

// An object that the `light` techniques aim at (the book's `lights` list).
struct Target {
  enum class Kind : std::uint8_t { Quad, Sphere } kind;
  std::uint32_t index;  // into Scene::quads or Scene::spheres
};

// `a` over its length, also where the length's square leaves float's range
// (a camera 1e19 from its target, a vup of 1e-30): then `a` is first divided
// by its largest component. Elsewhere exactly normalize(a). A zero vector
// gives zero.
Vec3 unit_direction(const Vec3& a);

struct Camera {
  int width = 600;
  int height = 600;
  float vfov_degrees = 40.0f;
  Vec3 lookfrom{278.0f, 278.0f, -800.0f};
  Vec3 lookat{278.0f, 278.0f, 0.0f};
  Vec3 vup{0.0f, 1.0f, 0.0f};

  // Derived by prepare(): a ray through pixel (x + dx, y + dy) has direction
  // pixel00 + (x + dx) * du + (y + dy) * dv (then normalised).
  Vec3 pixel00, du, dv;
  void prepare();
  // px, py in pixel units from the top-left corner
  Ray generate_ray(float px, float py) const { return Ray{lookfrom, normalize(pixel00 + du * px + dv * py)}; }
};

// The quads again as structure-of-arrays, padded to a multiple of kQuadLanes
// with quads that can never be hit, so the intersection loop vectorises.
struct QuadBatch {
#if defined(__AVX512F__)
  static constexpr int kQuadLanes = 16;
#elif defined(__AVX__)
  static constexpr int kQuadLanes = 8;
#else
  static constexpr int kQuadLanes = 4;
#endif
  int count = 0;   // real quads
  int padded = 0;  // multiple of kQuadLanes
  std::vector<float> nx, ny, nz, d, qx, qy, qz, ax, ay, az, bx, by, bz;
  void build(const std::vector<struct Quad>& quads);
};

// The rendering space moves to the camera where the camera is more than this
// many times further from the scene file's origin than from what it sees (the
// nearest object, or lookat if nearer): float's steps grow with the
// coordinates, 0.06 at 1e6, so a room 1 across placed 1e6 from the origin
// would be rendered with the precision of a room 1e-6 across. The book's
// scenes, their cameras a few times their own size from the origin, keep the
// file's coordinates and their bits.
inline constexpr double kCameraCentredRatio = 64.0;
// A box is refused where float cannot place its faces: its smallest side
// spans fewer than this many float steps of its coordinates in the rendering
// space (its faces, each rounded on its own, would then miss each other by
// more than 1/64 of the box).
inline constexpr double kSmallestBoxSteps = 64.0;

// How nee-mis chooses the emitter of its light sample: in proportion to power
// (and to what the point receives: TargetSet::by_point), uniformly (with the
// same reweighting), or by the light tree (LightTree: power, distance and
// orientation, in time logarithmic in the emitters). Written as in a scene
// file's `light_choice` and a strategy's `+lights:NAME`.
enum class LightChoice : std::uint8_t { Power, Uniform, Tree };
inline constexpr std::string_view kLightChoiceNames[] = {"power", "uniform", "tree"};
inline std::string_view light_choice_name(LightChoice c) { return kLightChoiceNames[static_cast<int>(c)]; }
// The choice a name gives; false where it names none.
inline bool parse_light_choice(std::string_view name, LightChoice& out) {
  for (int i = 0; i < 3; ++i)
    if (name == kLightChoiceNames[i]) {
      out = static_cast<LightChoice>(i);
      return true;
    }
  return false;
}

struct Scene {
  std::string name;
  // Of the scene file's content without the image size, the depth and the
  // description (scene_loader.cpp): what a reference image depends on besides
  // those. Empty for a scene built in code.
  std::string content_hash;
  Camera camera;
  int max_depth = 50;
  Vec3 background{0.0f};
  // How nee-mis chooses its light sample's emitter where the strategy does not
  // say (the scene file's `light_choice`).
  LightChoice light_choice = LightChoice::Power;
  // The scene file's `fastest_uses_guiding`: its light is hard to find (behind
  // a door ajar), and `fastest` there is kFastestGuidedStrategy (for_scene).
  bool fastest_uses_guiding = false;
  // The environment light (scene file's `environment`): the radiance of a ray
  // that leaves the scene, in place of `background`; null: none.
  std::shared_ptr<const Environment> environment;
  std::vector<Material> materials;
  std::vector<std::string> material_names;
  std::vector<Quad> quads;
  std::vector<Sphere> spheres;
  std::vector<Target> targets;
  // Where the rendering space's origin is, in the scene file's coordinates:
  // every position here is the file's minus `origin`, taken in double and
  // rounded once to float. The loader puts it at the camera where the camera
  // is far from the file's origin beside what it sees (kCameraCentredRatio),
  // else at 0. Positions shown to a person (the probe's point, a
  // screenshot's camera) are turned back with file_point.
  std::array<double, 3> origin{};
  float scale = 1.0f;  // largest coordinate magnitude (in the rendering space)
  QuadBatch quad_batch;  // derived from quads by prepare()
  // The tree over the objects (renderer/scene/bvh.h), built by prepare() where
  // `bvh_use` asks for it: by default from kBvhObjectThreshold objects on.
  // Both tracers and intersect() walk it where it covers the scene's objects;
  // an image is the same bits with it as without.
  Bvh bvh;
  BvhUse bvh_use = BvhUse::Auto;

  // Builds derived data (camera basis, quad batch, the tree). Call after editing the
  // scene; intersect() falls back to a scalar loop while the batch is stale.
  void prepare();
};

// A rendering-space position in the scene file's coordinates (+ origin, in double).
inline std::array<double, 3> file_point(const Scene& scene, const Vec3& p) {
  return {static_cast<double>(p.x) + scene.origin[0], static_cast<double>(p.y) + scene.origin[1],
          static_cast<double>(p.z) + scene.origin[2]};
}

struct Hit {
  float t;
  Vec3 point;
  Vec3 normal;  // geometric, outward (quads: u x v)
  std::uint32_t material;
  // A bound on the distance between `point` (rounded) and the true surface,
  // along the normal (leaf::quad_hit_error, leaf::sphere_hit_error): rays
  // leaving the hit start this far off the surface.
  float error;
};

// Closest intersection along the ray with t in (0, t_max). Origins are offset by
// the caller (spawn_ray, renderer/sampling/leaf.h), so no t_min epsilon is needed here.
bool intersect(const Scene& scene, const Ray& ray, float t_max, Hit& hit);
// For a ray aimed at a point of quad `aimed_quad` (an index into Scene::quads,
// or -1 for an ordinary ray) at `distance`: the nearest hit before a little
// beyond that point, else the quad there. A sampled point of a quad is on it
// even where float cannot aim a ray at it (a sliver, a quad nearly edge-on).
bool intersect_aimed(const Scene& scene, const Ray& ray, int aimed_quad, float distance, Hit& hit);
// How far beyond the aimed point the search goes, relative to the distance.
inline constexpr float kAimedReach = 1.0f + 0x1.0p-12f;
// A sphere hit from more than this many radii away: the hit point's rounding
// (a few 2^-24 of the distance) may exceed the radius, so (point - centre) / r
// is no normal; the hit faces the ray (the origin is far outside), and its
// normal is taken as -direction (a light 1e-9 of its distance across).
inline constexpr float kFarSphere = 65536.0f;

}  // namespace pdflab
