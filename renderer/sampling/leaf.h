#pragma once
// The leaf math (leaf_math.inc) for one path at a time: Float is float and a
// Mask is a bool. The packet tracer compiles the same file for its SIMD lanes
// (renderer/integrator/kernel.inc); the one-path tracer, the probe and
// the tests call these.
#include "renderer/math.h"
#include "renderer/sampling/guiding.h"
#include "renderer/sampling/light_tree.h"
#include "renderer/scene/scene.h"

#include <bit>
#include <cstdint>
#include <cstring>
#include <type_traits>

namespace pdflab {

enum class MisHeuristic : std::uint8_t { Balance, Power };

// A rectangle's frame for solid-angle sampling (leaf::spherical_rectangle),
// computed once per quad in double (rectangle_axes, techniques.h): the corner
// and the unit axes along u, along v and u x v, and the edge lengths.
struct RectangleAxes {
  double qx = 0, qy = 0, qz = 0;
  double xx = 0, xy = 0, xz = 0;
  double yx = 0, yy = 0, yz = 0;
  double zx = 0, zy = 0, zz = 0;
  Vec3 x{0.0f}, y{0.0f}, z{0.0f};  // the axes in float, to build directions
  float ex = 0.0f, ey = 0.0f;
  bool rectangle = false;  // else a parallelogram: area sampling
  // A one-sided emitter: seen from behind (the side u x v points away from),
  // its light cannot reach the point, so it is sampled there by area, the
  // cheapest valid density (what it aims at is worth nothing from there).
  bool one_sided = false;
  // Sampled by area from a point whose distances to the rectangle's points
  // differ by at most this factor (leaf::area_suffices; 0: never): the area
  // density, in solid angle, then varies by at most its cube, and is within
  // that of uniform, at a fraction of the spherical rectangle's cost.
  float flat_distance_ratio = 0.0f;
  Vec3 corner{0.0f};  // quad.q in float, for that test
};

namespace leaf {

#define PDFLAB_LEAF inline

using Float = float;
using Int = std::int32_t;
using Mask = bool;
using V3 = Vec3;

PDFLAB_LEAF Float splat(float x) { return x; }
PDFLAB_LEAF Int splat_i(std::int32_t x) { return x; }
PDFLAB_LEAF const V3& splat3(const Vec3& v) { return v; }
PDFLAB_LEAF Float lane_sqrt(Float x) { return std::sqrt(x); }
PDFLAB_LEAF Float lane_abs(Float x) { return std::fabs(x); }
PDFLAB_LEAF Float lane_sign(Float x) { return std::copysign(1.0f, x); }
PDFLAB_LEAF Float lane_max(Float a, Float b) { return max_of(a, b); }
PDFLAB_LEAF Int lane_trunc(Float x) { return static_cast<Int>(x); }
PDFLAB_LEAF Float lane_float(Int x) { return static_cast<Float>(x); }
PDFLAB_LEAF Mask lane_not(Mask m) { return !m; }
PDFLAB_LEAF Mask lane_and(Mask a, Mask b) { return a && b; }
PDFLAB_LEAF Mask lane_or(Mask a, Mask b) { return a || b; }
PDFLAB_LEAF Int increment_where(Int x, Mask m) { return m ? x + 1 : x; }
PDFLAB_LEAF bool any(Mask m) { return m; }
PDFLAB_LEAF Float select(Mask m, Float a, Float b) { return m ? a : b; }
PDFLAB_LEAF Int select(Mask m, Int a, Int b) { return m ? a : b; }
PDFLAB_LEAF V3 select(Mask m, const V3& a, const V3& b) { return m ? a : b; }
PDFLAB_LEAF Float lane_pow(Float x, float e) { return std::pow(x, e); }
using Double = double;
PDFLAB_LEAF Double to_double(Float x) { return x; }
PDFLAB_LEAF Float to_float(Double x) { return static_cast<float>(x); }
PDFLAB_LEAF Double lane_sqrt(Double x) { return std::sqrt(x); }
PDFLAB_LEAF Int lane_int_bits(Float x) { return std::bit_cast<Int>(x); }
// The 16 floats of row `index` of a table of 64-byte rows.
PDFLAB_LEAF void lane_rows16(const float* rows, Int index, Float (&field)[16]) {
  std::memcpy(field, rows + 16 * static_cast<std::ptrdiff_t>(index), sizeof field);
}
// One path is one lane: lane 0, there when the mask is.
template <class F>
PDFLAB_LEAF void each_lane(Mask m, F f) {
  if (m) f(0);
}
PDFLAB_LEAF const Vec3& lane_vec3(const V3& v, int) { return v; }
PDFLAB_LEAF float lane_value(Float v, int) { return v; }
PDFLAB_LEAF void set_lane_vec3(V3& v, int, const Vec3& x) { v = x; }
PDFLAB_LEAF void set_lane_value(Float& v, int, float x) { v = x; }
PDFLAB_LEAF void set_lane_mask(Mask& m, int, bool x) { m = x; }
PDFLAB_LEAF void set_lane_int(Int& v, int, std::int32_t x) { v = x; }
PDFLAB_LEAF std::uint32_t lane_bits(Int v, int) { return static_cast<std::uint32_t>(v); }

#include "renderer/sampling/leaf_math.inc"

#undef PDFLAB_LEAF

}  // namespace leaf

using leaf::kInv2Pi;
using leaf::kInv4Pi;
using leaf::mis_weight;
using leaf::Onb;
using leaf::sincos_2pi;
using leaf::quad_hit_distance;

// A new ray leaving a hit in `direction` (leaf::spawn_origin).
inline Ray spawn_ray(const Hit& hit, const Vec3& direction) {
  return Ray{leaf::spawn_origin(hit.point, hit.normal, hit.error, direction), direction};
}
// Where every ray leaving a diffuse hit starts: off the surface on the side of
// `facing`, the normal facing the incoming ray (leaf::offset_origin).
inline Vec3 diffuse_origin(const Hit& hit, const Vec3& facing) { return leaf::offset_origin(hit.point, facing, hit.error); }

}  // namespace pdflab
