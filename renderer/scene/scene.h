#pragma once
// The scene as flat arrays of plain structs. Boxes are already six quads and
// rotations/translations are baked into the geometry by the loader.
#include "renderer/math.h"

#include <cstdint>
#include <string>
#include <vector>

namespace pdflab {

enum class MaterialType : std::uint8_t { Lambertian, Metal, Dielectric, DiffuseLight };

struct Material {
  MaterialType type = MaterialType::Lambertian;
  Vec3 albedo{0.0f};
  Vec3 emit{0.0f};
  float fuzz = 0.0f;
  float ior = 1.0f;
  bool two_sided = false;  // diffuse_light only
};

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

struct Sphere {
  Vec3 center;
  float radius;
  std::uint32_t material;
};

// Builds a quad with its derived plane data. Throws nothing: callers validate u x v != 0.
Quad make_quad(const Vec3& q, const Vec3& u, const Vec3& v, std::uint32_t material);

// Distance along a unit ray to the quad, or a negative value when it misses.
// The tests are combined with `&` into one branch: whether a direction reaches
// a target is unpredictable, and one mispredicted branch costs more than the math.
inline float quad_hit_distance(const Quad& quad, const Vec3& origin, const Vec3& direction) {
  const float denom = dot(quad.normal, direction);
  const float t = (quad.plane_d - dot(quad.normal, origin)) / denom;  // +-inf or NaN when parallel
  const Vec3 rel = origin + direction * t - quad.q;
  const float a = dot(rel, quad.alpha_axis);
  const float b = dot(rel, quad.beta_axis);
  const bool hit = (t > 0.0f) & (t < kInf) & (a >= 0.0f) & (a <= 1.0f) & (b >= 0.0f) & (b <= 1.0f);
  return hit ? t : -1.0f;
}

// An object that the `light` techniques aim at (the book's `lights` list).
struct Target {
  enum class Kind : std::uint8_t { Quad, Sphere } kind;
  std::uint32_t index;  // into Scene::quads or Scene::spheres
};

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

struct Scene {
  std::string name;
  // Of the scene file's content without the image size, the depth and the
  // description (scene_loader.cpp): what a reference image depends on besides
  // those. Empty for a scene built in code.
  std::string content_hash;
  Camera camera;
  int max_depth = 50;
  Vec3 background{0.0f};
  std::vector<Material> materials;
  std::vector<std::string> material_names;
  std::vector<Quad> quads;
  std::vector<Sphere> spheres;
  std::vector<Target> targets;
  float scale = 1.0f;  // largest coordinate magnitude
  QuadBatch quad_batch;  // derived from quads by prepare()

  // Builds derived data (camera basis, quad batch). Call after editing the
  // scene; intersect() falls back to a scalar loop while the batch is stale.
  void prepare();
};

struct Hit {
  float t;
  Vec3 point;
  Vec3 normal;  // geometric, outward (quads: u x v)
  std::uint32_t material;
};

// Closest intersection along the ray with t in (0, t_max). Origins are offset by
// the caller (spawn_ray), so no t_min epsilon is needed here.
bool intersect(const Scene& scene, const Ray& ray, float t_max, Hit& hit);

// A new ray leaving `point` in `direction`, moved off the surface along the
// normal on the side the direction goes, by an offset that scales with the
// coordinates' magnitude (float spacing grows with it).
inline Ray spawn_ray(const Vec3& point, const Vec3& geometric_normal, const Vec3& direction) {
  // About 8 float ulps of the largest coordinate (2^-20 relative): the hit
  // point's rounding error is a few ulps (tests/test_extremes.cpp shows rays
  // re-hitting their own surface at 1e5 with no offset), plus an absolute floor
  // for points near the origin. Small enough not to skip walls 0.25 units thick at 1e5.
  const float offset = 1e-4f + 1e-6f * max_abs_component(point);
  const float side = dot(direction, geometric_normal) >= 0.0f ? offset : -offset;
  return Ray{point + geometric_normal * side, direction};
}

}  // namespace pdflab
