#pragma once
// Every sampling technique as a pair of free functions: sample_X(...) returns a
// unit direction with its solid-angle pdf, X_pdf(...) evaluates that pdf for any
// unit direction. The pairs must agree; tests/test_chi_square.cpp checks each.
#include "renderer/math.h"
#include "renderer/sampling/leaf.h"
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
  // leaf::Sampled's aimed quad (-1: none) and the distance to the aimed point.
  int aimed_quad = -1;
  float aimed_distance = 0.0f;
};

// The formulas are leaf math (renderer/sampling/leaf_math.inc), shared with
// the packet tracer; these are their one-path forms.

inline DirectionSample to_direction_sample(const leaf::Sampled& s) {
  return {s.direction, s.pdf, s.none, s.aimed_quad, s.aimed_distance};
}

// Cosine-weighted hemisphere: p(w) = cos(theta) / pi.
inline DirectionSample sample_cosine_hemisphere(const Onb& frame, float u1, float u2) {
  float sin_phi, cos_phi;
  sincos_2pi(u2, sin_phi, cos_phi);
  const Vec3 local = leaf::cosine_hemisphere_local(u1, sin_phi, cos_phi);
  return {frame.to_world(local), local.z * kInvPi};
}
inline float cosine_hemisphere_pdf(const Vec3& normal, const Vec3& direction) {
  return leaf::cosine_hemisphere_density(dot(normal, direction));
}

// Uniform hemisphere: p(w) = 1 / (2 pi) above the surface.
inline DirectionSample sample_uniform_hemisphere(const Onb& frame, float u1, float u2) {
  float sin_phi, cos_phi;
  sincos_2pi(u2, sin_phi, cos_phi);
  return {frame.to_world(leaf::uniform_hemisphere_local(u1, sin_phi, cos_phi)), kInv2Pi};
}
inline float uniform_hemisphere_pdf(const Vec3& normal, const Vec3& direction) {
  return leaf::uniform_hemisphere_density(dot(normal, direction));
}

// Uniform sphere: p(w) = 1 / (4 pi). Half its samples point below the surface.
inline DirectionSample sample_uniform_sphere(float u1, float u2) {
  float sin_phi, cos_phi;
  sincos_2pi(u2, sin_phi, cos_phi);
  return {leaf::uniform_sphere_direction(u1, sin_phi, cos_phi), kInv4Pi};
}
inline float uniform_sphere_pdf() { return kInv4Pi; }

// Area sampling of a quad (the book's quad::random / pdf_value).
inline DirectionSample sample_quad_area(const Quad& quad, const Vec3& origin, float u1, float u2) {
  return to_direction_sample(leaf::sample_quad_area(quad, origin, u1, u2));
}
inline float quad_area_pdf(const Quad& quad, const Vec3& origin, const Vec3& direction) {
  return leaf::quad_area_pdf(quad, origin, direction);
}

// Cone sampling of a sphere (the book's sphere::random / pdf_value).
using leaf::SphereCone;
using leaf::sphere_cone;
inline DirectionSample sample_sphere_cone(const Sphere& sphere, const Vec3& origin, float u1, float u2) {
  float sin_phi, cos_phi;
  sincos_2pi(u2, sin_phi, cos_phi);
  return to_direction_sample(leaf::sample_sphere_cone(sphere, origin, u1, sin_phi, cos_phi));
}
inline float sphere_cone_pdf(const Sphere& sphere, const Vec3& origin, const Vec3& direction) {
  return leaf::sphere_cone_pdf(sphere, origin, direction);
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
// The quad's frame for the float set-up (leaf::spherical_rectangle), in double.
RectangleAxes rectangle_axes(const Quad& quad);

DirectionSample sample_quad_solid_angle(const Quad& quad, const Vec3& origin, float u1, float u2);
// `aimed`: the direction is known to reach the quad at distance aimed_t (leaf::quad_area_pdf).
float quad_solid_angle_pdf(const Quad& quad, const Vec3& origin, const Vec3& direction, bool aimed = false,
                           float aimed_t = 0.0f);

}  // namespace pdflab
