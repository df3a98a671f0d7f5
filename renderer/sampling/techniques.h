#pragma once
// Every sampling technique as a pair of free functions: sample_X(...) returns a
// unit direction with its solid-angle pdf, X_pdf(...) evaluates that pdf for any
// unit direction. The pairs must agree; tests/test_chi_square.cpp checks each.
#include "renderer/math.h"
#include "renderer/sampling/onb.h"
#include "renderer/scene/scene.h"

namespace pdflab {

struct DirectionSample {
  Vec3 direction;
  float pdf;
  // The technique has no direction to offer from here: a light seen exactly
  // edge-on (the shading point in its plane) subtends no solid angle. That is a
  // valid zero estimate, not an invalid sample: the technique's density is zero
  // for every direction at this point, and the mixture or MIS estimator stays
  // unbiased when it contributes nothing.
  bool none = false;
};

// ---- Hemisphere and sphere techniques (relative to a shading normal) -------

inline constexpr float kInv2Pi = 0.5f * kInvPi;
inline constexpr float kInv4Pi = 0.25f * kInvPi;

// Cosine-weighted hemisphere: p(w) = cos(theta) / pi.
inline DirectionSample sample_cosine_hemisphere(const Onb& frame, float u1, float u2) {
  const float r = std::sqrt(u1);
  float sin_phi, cos_phi;
  sincos_2pi(u2, sin_phi, cos_phi);
  const float z = std::sqrt(positive_part(1.0f - u1));
  const Vec3 local(r * cos_phi, r * sin_phi, z);
  return {frame.to_world(local), z * kInvPi};
}
inline float cosine_hemisphere_pdf(const Vec3& normal, const Vec3& direction) {
  const float c = dot(normal, direction);
  return c > 0.0f ? c * kInvPi : 0.0f;
}

// Uniform hemisphere: p(w) = 1 / (2 pi) above the surface.
inline DirectionSample sample_uniform_hemisphere(const Onb& frame, float u1, float u2) {
  const float z = 1.0f - u1;  // (0, 1]: never exactly tangent
  const float r = std::sqrt(positive_part(1.0f - z * z));
  float sin_phi, cos_phi;
  sincos_2pi(u2, sin_phi, cos_phi);
  return {frame.to_world(Vec3(r * cos_phi, r * sin_phi, z)), kInv2Pi};
}
inline float uniform_hemisphere_pdf(const Vec3& normal, const Vec3& direction) {
  return dot(normal, direction) > 0.0f ? kInv2Pi : 0.0f;
}

// Uniform sphere: p(w) = 1 / (4 pi). Half its samples point below the surface.
inline DirectionSample sample_uniform_sphere(float u1, float u2) {
  const float z = 1.0f - 2.0f * u1;
  const float r = std::sqrt(positive_part(1.0f - z * z));
  float sin_phi, cos_phi;
  sincos_2pi(u2, sin_phi, cos_phi);
  return {Vec3(r * cos_phi, r * sin_phi, z), kInv4Pi};
}
inline float uniform_sphere_pdf() { return kInv4Pi; }

// ---- Area sampling of a quad (the book's quad::random / pdf_value) ---------
// A uniform point on the quad, converted to solid angle: p = d^2 / (|cos| A).

inline DirectionSample sample_quad_area(const Quad& quad, const Vec3& origin, float u1, float u2) {
  const Vec3 to_point = quad.q + quad.u * u1 + quad.v * u2 - origin;
  const float dist2 = dot(to_point, to_point);
  const float dist = std::sqrt(dist2);
  const Vec3 direction = to_point * (1.0f / dist);
  const float cosine = std::fabs(dot(direction, quad.normal));
  // dist2 == 0 (origin on the sampled point) or cosine == 0 (origin in the
  // quad's plane): the quad is seen edge-on and offers no direction.
  if (!(dist2 > 0.0f) || !(cosine > 0.0f)) return {quad.normal, 0.0f, true};
  return {direction, dist2 / (cosine * quad.area)};
}

inline float quad_area_pdf(const Quad& quad, const Vec3& origin, const Vec3& direction) {
  const float t = quad_hit_distance(quad, origin, direction);
  if (t < 0.0f) return 0.0f;
  const float cosine = std::fabs(dot(direction, quad.normal));
  return t * t / (cosine * quad.area);
}

// ---- Cone sampling of a sphere (the book's sphere::random / pdf_value) ----

struct SphereCone {
  Vec3 axis;                 // unit, from the origin to the centre
  float cos_max;             // cosine of the cone's half angle
  float one_minus_cos_max;   // computed without cancellation
  bool inside;               // origin inside the sphere: every direction hits it
};

// 1 - cos(theta_max) = sin^2 / (1 + cos): no cancellation for small or far spheres.
inline SphereCone sphere_cone(const Sphere& sphere, const Vec3& origin) {
  const Vec3 to_center = sphere.center - origin;
  const float dist2 = dot(to_center, to_center);
  const float r2 = sphere.radius * sphere.radius;
  SphereCone cone{};
  if (dist2 <= r2) {
    cone.inside = true;
    cone.axis = Vec3(0.0f, 0.0f, 1.0f);
    cone.cos_max = -1.0f;
    cone.one_minus_cos_max = 2.0f;
    return cone;
  }
  cone.axis = to_center * (1.0f / std::sqrt(dist2));
  const float sin2_max = r2 / dist2;
  cone.cos_max = std::sqrt(positive_part(1.0f - sin2_max));
  cone.one_minus_cos_max = sin2_max / (1.0f + cone.cos_max);
  cone.inside = false;
  return cone;
}

// From inside the sphere the whole sphere of directions is the target: pdf 1/(4 pi).
inline DirectionSample sample_sphere_cone(const Sphere& sphere, const Vec3& origin, float u1, float u2) {
  const SphereCone cone = sphere_cone(sphere, origin);
  if (cone.inside) return sample_uniform_sphere(u1, u2);
  const float h = u1 * cone.one_minus_cos_max;  // 1 - cos(theta), uniform in [0, 1 - cos_max)
  const float cos_theta = 1.0f - h;
  const float sin_theta = std::sqrt(positive_part(h * (2.0f - h)));
  float sin_phi, cos_phi;
  sincos_2pi(u2, sin_phi, cos_phi);
  const Onb frame(cone.axis);
  const Vec3 local(sin_theta * cos_phi, sin_theta * sin_phi, cos_theta);
  return {normalize(frame.to_world(local)), 1.0f / (2.0f * kPi * cone.one_minus_cos_max)};
}

inline float sphere_cone_pdf(const Sphere& sphere, const Vec3& origin, const Vec3& direction) {
  const Vec3 to_center = sphere.center - origin;
  const float r2 = sphere.radius * sphere.radius;
  const float dist2 = dot(to_center, to_center);
  if (dist2 <= r2) return kInv4Pi;  // inside: every direction reaches the sphere
  // Most directions miss: decide that first, cheaply and stably, by the squared
  // distance from the centre to the ray's line (no cancellation for far spheres),
  // in one branch (see quad_hit_distance).
  const float along = dot(to_center, direction);
  const Vec3 perpendicular = to_center - direction * along;
  if (!((along > 0.0f) & (dot(perpendicular, perpendicular) <= r2))) return 0.0f;
  const float sin2_max = r2 / dist2;
  const float one_minus_cos_max = sin2_max / (1.0f + std::sqrt(positive_part(1.0f - sin2_max)));
  return 1.0f / (2.0f * kPi * one_minus_cos_max);
}

// ---- Solid-angle sampling of a rectangle (spherical rectangle) -------------
// Ureña, Fajardo and King, "An Area-Preserving Parametrization for Spherical
// Rectangles" (EGSR 2013): directions uniform over the solid angle the
// rectangle subtends, p = 1 / S. The set-up works in double: S is a sum of four
// angles minus 2 pi, which cancels badly in float for small rectangles. Below
// kMinSphericalRectangleSolidAngle (or for a parallelogram that is not a
// rectangle) the techniques fall back to area sampling, whose pdf is exact there.

inline constexpr double kMinSphericalRectangleSolidAngle = 1e-7;

struct SphericalRectangle {
  bool usable = false;  // false: fall back to area sampling
  double solid_angle = 0.0;
  // Local frame: x along u, y along v, z towards the origin's side (flipped so z0 <= 0).
  glm::dvec3 origin, x, y, z;
  double x0, x1, y0, y1, z0;
  double b0, b1, k;
};

inline bool quad_is_rectangle(const Quad& quad) {
  return std::fabs(static_cast<double>(dot(quad.u, quad.v))) <=
         1e-6 * static_cast<double>(length(quad.u)) * static_cast<double>(length(quad.v));
}

SphericalRectangle spherical_rectangle(const Quad& quad, const Vec3& origin);

DirectionSample sample_quad_solid_angle(const Quad& quad, const Vec3& origin, float u1, float u2);
float quad_solid_angle_pdf(const Quad& quad, const Vec3& origin, const Vec3& direction);

}  // namespace pdflab
