#include "renderer/scene/scene.h"

#include "renderer/sampling/leaf.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>

namespace pdflab {

// The derived plane data in double, rounded once to float at the end: in float,
// |u x v|^2 overflows for edges near 4e9 and underflows for edges near 1e-10,
// while each derived quantity itself fits easily (quad_problem says when not).
namespace {
struct DVec {
  double x, y, z;
};
DVec dvec(const Vec3& v) { return {v.x, v.y, v.z}; }
DVec dcross(const DVec& a, const DVec& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
double ddot(const DVec& a, const DVec& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
DVec dscale(const DVec& a, double s) { return {a.x * s, a.y * s, a.z * s}; }
Vec3 to_float(const DVec& a) { return {static_cast<float>(a.x), static_cast<float>(a.y), static_cast<float>(a.z)}; }
}  // namespace

std::string quad_problem(const Vec3& u, const Vec3& v) {
  const DVec du = dvec(u), dv = dvec(v);
  const double lu = std::sqrt(ddot(du, du)), lv = std::sqrt(ddot(dv, dv));
  const auto show = [](double x) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", x);
    return std::string(buf);
  };
  if (lu == 0.0 && lv == 0.0) return "degenerate quad: u and v are both zero";
  if (lu == 0.0) return "degenerate quad: u is zero";
  if (lv == 0.0) return "degenerate quad: v is zero";
  const DVec n = dcross(du, dv);
  const double area = std::sqrt(ddot(n, n));
  // u and v come from float, so their cross product is exact to double rounding:
  // a sine below 1e-7 means parallel up to the input's own precision.
  const double sine = area / (lu * lv);
  if (!(sine > 1e-7))
    return "degenerate quad: u and v are parallel (the sine of the angle between them is " + show(sine) + ")";
  if (area > static_cast<double>(std::numeric_limits<float>::max()))
    return "the quad's area " + show(area) + " does not fit in single precision (at most " +
           show(std::numeric_limits<float>::max()) + ")";
  // Its reciprocal scales the light pdf d^2 / (cos A) and the plane axes.
  if (area < static_cast<double>(std::numeric_limits<float>::min()) * 1e6)
    return "the quad's area " + show(area) + " is too small for single precision (at least " +
           show(static_cast<double>(std::numeric_limits<float>::min()) * 1e6) + ")";
  return {};
}

Quad make_quad(const Vec3& q, const Vec3& u, const Vec3& v, std::uint32_t material) {
  Quad quad{};
  quad.q = q;
  quad.u = u;
  quad.v = v;
  const DVec dq = dvec(q), du = dvec(u), dv = dvec(v);
  const DVec n = dcross(du, dv);
  const double n2 = ddot(n, n);
  const double area = std::sqrt(n2);
  const DVec unit_normal = dscale(n, 1.0 / area);
  quad.area = static_cast<float>(area);
  quad.normal = to_float(unit_normal);
  quad.plane_d = static_cast<float>(ddot(unit_normal, dq));
  const DVec w = dscale(n, 1.0 / n2);
  // p = q + a u + b v  =>  a = w . (rel x v) = rel . (v x w),  b = rel . (w x u)
  quad.alpha_axis = to_float(dcross(dv, w));
  quad.beta_axis = to_float(dcross(w, du));
  quad.material = material;
  return quad;
}

Vec3 unit_direction(const Vec3& a) {
  const float squared = length_squared(a);
  if (squared >= std::numeric_limits<float>::min() && squared <= std::numeric_limits<float>::max()) return normalize(a);
  const float largest = max_abs_component(a);
  if (!(largest > 0.0f) || !std::isfinite(largest)) return Vec3(0.0f);
  return normalize(a / largest);
}

void Camera::prepare() {
  const float theta = vfov_degrees * (kPi / 180.0f);
  const float viewport_height = 2.0f * std::tan(theta * 0.5f);
  const float viewport_width = viewport_height * (static_cast<float>(width) / static_cast<float>(height));
  const Vec3 w = unit_direction(lookfrom - lookat);
  const Vec3 u = unit_direction(cross(vup, w));
  const Vec3 v = cross(w, u);
  du = u * (viewport_width / static_cast<float>(width));
  dv = -v * (viewport_height / static_cast<float>(height));
  const Vec3 upper_left = -w - u * (viewport_width * 0.5f) + v * (viewport_height * 0.5f);
  pixel00 = upper_left;  // relative to lookfrom; pixel (x, y) spans [x, x+1) x [y, y+1)
}

namespace {

inline bool hit_sphere(const Sphere& sphere, const Ray& ray, float t_max, float& t_out) {
  bool hit;
  const float t = leaf::sphere_hit_distance(sphere, ray.origin, ray.direction, t_max, hit);
  if (hit) t_out = t;
  return hit;
}

// kQuadLanes quads per step in SIMD lanes (GCC/Clang vector extensions: SSE,
// AVX or AVX-512 on x86-64 as the build targets, NEON on ARM), with no branches: which quad is nearest is
// unpredictable, and a mispredicted branch costs more than the arithmetic.
// Each lane keeps its own nearest hit; the lanes are reduced at the end.
constexpr int kLanes = QuadBatch::kQuadLanes;
typedef float FV __attribute__((vector_size(4 * kLanes)));
typedef std::int32_t IV __attribute__((vector_size(4 * kLanes)));

inline FV load(const float* p) {
  FV v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

inline int closest_in_batch(const QuadBatch& b, const Ray& ray, float& closest) {
  const FV ox = ray.origin.x - FV{}, oy = ray.origin.y - FV{}, oz = ray.origin.z - FV{};
  const FV dx = ray.direction.x - FV{}, dy = ray.direction.y - FV{}, dz = ray.direction.z - FV{};
  const FV zero{}, one = 1.0f - FV{};
  FV best_t = closest - FV{};
  IV best_i = -1 - IV{};
  IV index{};
  for (int lane = 0; lane < kLanes; ++lane) index[lane] = lane;
  for (int i = 0; i < b.padded; i += kLanes, index += kLanes) {
    const FV nx = load(&b.nx[i]), ny = load(&b.ny[i]), nz = load(&b.nz[i]);
    const FV denom = nx * dx + ny * dy + nz * dz;
    const FV t = (load(&b.d[i]) - (nx * ox + ny * oy + nz * oz)) / denom;
    const FV rx = ox + dx * t - load(&b.qx[i]);
    const FV ry = oy + dy * t - load(&b.qy[i]);
    const FV rz = oz + dz * t - load(&b.qz[i]);
    const FV a = rx * load(&b.ax[i]) + ry * load(&b.ay[i]) + rz * load(&b.az[i]);
    const FV c = rx * load(&b.bx[i]) + ry * load(&b.by[i]) + rz * load(&b.bz[i]);
    const IV hit = (t > zero) & (t < best_t) & (a >= zero) & (a <= one) & (c >= zero) & (c <= one);
    best_t = hit ? t : best_t;
    best_i = hit ? index : best_i;
  }
  // The nearest, the first of equals (a lane without a hit keeps best_t at
  // `closest`'s start and index -1, below every lane's index).
  int best = -1;
  for (int lane = 0; lane < kLanes; ++lane) {
    const bool nearer = best_t[lane] < closest || (best_t[lane] == closest && best_i[lane] < best);
    best = nearer ? best_i[lane] : best;
    closest = nearer ? best_t[lane] : closest;
  }
  return best;
}

}  // namespace

void QuadBatch::build(const std::vector<Quad>& quads) {
  count = static_cast<int>(quads.size());
  padded = (count + kQuadLanes - 1) / kQuadLanes * kQuadLanes;
  for (auto* v : {&nx, &ny, &nz, &d, &qx, &qy, &qz, &ax, &ay, &az, &bx, &by, &bz}) v->assign(padded, 0.0f);
  for (int i = 0; i < count; ++i) {
    const Quad& q = quads[i];
    nx[i] = q.normal.x; ny[i] = q.normal.y; nz[i] = q.normal.z; d[i] = q.plane_d;
    qx[i] = q.q.x; qy[i] = q.q.y; qz[i] = q.q.z;
    ax[i] = q.alpha_axis.x; ay[i] = q.alpha_axis.y; az[i] = q.alpha_axis.z;
    bx[i] = q.beta_axis.x; by[i] = q.beta_axis.y; bz[i] = q.beta_axis.z;
  }
  // Padding lanes: zero normal gives denom 0 and t = +-inf or NaN, and an
  // alpha axis of NaN makes `a >= 0` false: never a hit.
  for (int i = count; i < padded; ++i) ax[i] = std::numeric_limits<float>::quiet_NaN();
}

void Scene::prepare() {
  camera.prepare();
  quad_batch.build(quads);
  float s = max_abs_component(camera.lookfrom);
  for (const Quad& q : quads) s = max_of(s, max_of(max_abs_component(q.q), max_abs_component(q.q + q.u + q.v)));
  for (const Sphere& sp : spheres) s = max_of(s, max_abs_component(sp.center) + sp.radius);
  scale = s;
  // A sphere is intersected in float (leaf::sphere_hit_distance) where float
  // loses little against double:
  //  - it is at least 1/16 of the scene's extent: with every origin and centre
  //    within `scale`, |f| <= 2 sqrt(3) scale <= 56 r, and float's error in
  //    r^2 - |closest|^2 is below 2^-24 (12 * 56 + 7) r^2 < 2^-14 r^2;
  //  - its radius is at most twice the smallest coordinate magnitude m of its
  //    points (|p|_inf >= | |c| - r | / sqrt(3)): float's share of the hit
  //    error, 64 eps (t + r), is then at most 16 times the rest of it,
  //    4 eps t + 8 eps m. A ground sphere through the scene's origin (m = 0),
  //    whose float error is a fixed fraction of its radius where everything
  //    else is small, keeps the double test.
  //  - its radius is at most 2^57: the test squares |f| <= 56 r, which stays
  //    below FLT_MAX (2^128) only up to r = 2^58; above, r^2 overflowed to inf
  //    and every ray missed (a dome of radius 1.84e19 or more was invisible).
  //    The double test holds every radius the loader accepts (r^2 <= 1e77).
  for (Sphere& sp : spheres) {
    const double centre = std::sqrt(static_cast<double>(dot(sp.center, sp.center)));
    const double smallest = std::fabs(centre - static_cast<double>(sp.radius)) / std::sqrt(3.0);
    sp.float_test = s <= 16.0f * sp.radius && static_cast<double>(sp.radius) <= 2.0 * smallest &&
                    sp.radius <= kLargestFloatTestRadius;
  }
  const auto objects = quads.size() + spheres.size();
  const bool tree = bvh_use == BvhUse::Always ||
                    (bvh_use == BvhUse::Auto && objects >= static_cast<std::size_t>(kBvhObjectThreshold));
  bvh = tree ? Bvh::build(quads, spheres, scale) : Bvh{};
}

namespace {
// The hit on quad q at distance t along the ray.
Hit quad_hit(const Quad& q, const Ray& ray, float t) {
  return {t, ray.origin + ray.direction * t, q.normal, q.material, leaf::quad_hit_error(ray.origin, q.plane_d, t)};
}
// The hit on sphere s at distance t; its normal faces the ray where the sphere
// is tiny beside the distance (kFarSphere, as PathTracer::gather).
Hit sphere_hit(const Sphere& s, const Ray& ray, float t) {
  const Vec3 point = ray.origin + ray.direction * t;
  const Vec3 normal = t > kFarSphere * s.radius ? -ray.direction : (point - s.center) * (1.0f / s.radius);
  return {t, point, normal, s.material, leaf::sphere_hit_error(ray.origin, t, point, s.float_radius())};
}
}  // namespace

namespace {
// The nearest hit among the objects whose boxes the ray reaches in the scene's
// tree: each by the flat loop's arithmetic, the nearest winning and the first
// of equals by object number, so it is the flat loop's hit.
bool intersect_tree(const Scene& scene, const Ray& ray, float t_max, Hit& hit) {
  const auto nq = static_cast<std::int32_t>(scene.quads.size());
  float closest = t_max;
  std::int32_t best = -1;
  scene.bvh.walk(ray.origin, ray.direction, closest, [&](std::int32_t object) {
    bool found;
    float t;
    if (object < nq) {
      t = quad_hit_distance(scene.quads[static_cast<std::size_t>(object)], ray.origin, ray.direction);
      found = t > 0.0f;
    } else {
      t = leaf::sphere_hit_distance(scene.spheres[static_cast<std::size_t>(object - nq)], ray.origin, ray.direction,
                                    t_max, found);
    }
    if (found && (t < closest || (t == closest && object < best))) closest = t, best = object;
  });
  if (best < 0) return false;
  hit = best < nq ? quad_hit(scene.quads[static_cast<std::size_t>(best)], ray, closest)
                  : sphere_hit(scene.spheres[static_cast<std::size_t>(best - nq)], ray, closest);
  return true;
}
}  // namespace

bool intersect(const Scene& scene, const Ray& ray, float t_max, Hit& hit) {
  if (scene.bvh.covers(scene.quads.size(), scene.spheres.size())) return intersect_tree(scene, ray, t_max, hit);
  int best_quad = -1, best_sphere = -1;
  float closest = t_max;
  if (scene.quad_batch.count == static_cast<int>(scene.quads.size())) {
    best_quad = closest_in_batch(scene.quad_batch, ray, closest);
  } else {
    const int nq = static_cast<int>(scene.quads.size());
    for (int i = 0; i < nq; ++i) {
      const float t = quad_hit_distance(scene.quads[i], ray.origin, ray.direction);
      if (t > 0.0f && t < closest) {
        closest = t;
        best_quad = i;
      }
    }
  }
  const int ns = static_cast<int>(scene.spheres.size());
  for (int i = 0; i < ns; ++i) {
    float t;
    if (hit_sphere(scene.spheres[i], ray, closest, t)) {
      closest = t;
      best_sphere = i;
    }
  }
  if (best_sphere >= 0) {
    hit = sphere_hit(scene.spheres[best_sphere], ray, closest);
    return true;
  }
  if (best_quad >= 0) {
    hit = quad_hit(scene.quads[best_quad], ray, closest);
    return true;
  }
  return false;
}

bool intersect_aimed(const Scene& scene, const Ray& ray, int aimed_quad, float distance, Hit& hit) {
  if (aimed_quad < 0) return intersect(scene, ray, kInf, hit);
  if (intersect(scene, ray, distance * kAimedReach, hit)) return true;
  const auto nq = static_cast<int>(scene.quads.size());
  hit = aimed_quad < nq ? quad_hit(scene.quads[static_cast<std::size_t>(aimed_quad)], ray, distance)
                        : sphere_hit(scene.spheres[static_cast<std::size_t>(aimed_quad - nq)], ray, distance);
  return true;
}

}  // namespace pdflab
