#include "renderer/sampling/techniques.h"

#include <algorithm>

namespace pdflab {

namespace {

using D3 = glm::dvec3;

D3 to_d(const Vec3& v) { return {v.x, v.y, v.z}; }
double ddot(const D3& a, const D3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
D3 dcross(const D3& a, const D3& b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
D3 dnormalize(const D3& a) { return a * (1.0 / std::sqrt(ddot(a, a))); }

// Interior angle between two great-circle edges with unit plane normals a, b.
double interior_angle(const D3& a, const D3& b) { return std::acos(std::clamp(-ddot(a, b), -1.0, 1.0)); }

constexpr double kTwoPi = 2.0 * std::numbers::pi;

}  // namespace

SphericalRectangle spherical_rectangle(const Quad& quad, const Vec3& origin) {
  SphericalRectangle r;
  if (!quad_is_rectangle(quad)) return r;
  const double ex = static_cast<double>(length(quad.u)), ey = static_cast<double>(length(quad.v));
  r.origin = to_d(origin);
  r.x = to_d(quad.u) / ex;
  r.y = to_d(quad.v) / ey;
  r.z = dcross(r.x, r.y);
  const D3 d = to_d(quad.q) - r.origin;
  r.z0 = ddot(d, r.z);
  if (r.z0 > 0.0) {
    r.z = -r.z;
    r.z0 = -r.z0;
  }
  if (!(r.z0 < 0.0)) return r;  // origin in the rectangle's plane: zero solid angle
  r.x0 = ddot(d, r.x);
  r.y0 = ddot(d, r.y);
  r.x1 = r.x0 + ex;
  r.y1 = r.y0 + ey;
  // The four corners seen from the origin, and the normals of the planes
  // through the origin and each edge.
  const D3 v00(r.x0, r.y0, r.z0), v01(r.x0, r.y1, r.z0), v10(r.x1, r.y0, r.z0), v11(r.x1, r.y1, r.z0);
  const D3 n0 = dnormalize(dcross(v00, v10));
  const D3 n1 = dnormalize(dcross(v10, v11));
  const D3 n2 = dnormalize(dcross(v11, v01));
  const D3 n3 = dnormalize(dcross(v01, v00));
  const double g0 = interior_angle(n0, n1), g1 = interior_angle(n1, n2);
  const double g2 = interior_angle(n2, n3), g3 = interior_angle(n3, n0);
  r.solid_angle = g0 + g1 + g2 + g3 - kTwoPi;
  r.b0 = n0.z;
  r.b1 = n2.z;
  r.k = kTwoPi - g2 - g3;
  r.usable = std::isfinite(r.solid_angle) && r.solid_angle >= kMinSphericalRectangleSolidAngle;
  return r;
}

RectangleAxes rectangle_axes(const Quad& quad) {
  RectangleAxes a;
  a.rectangle = quad_is_rectangle(quad);
  const double ex = static_cast<double>(length(quad.u)), ey = static_cast<double>(length(quad.v));
  const D3 x = to_d(quad.u) / ex, y = to_d(quad.v) / ey, z = dcross(x, y);
  a.qx = quad.q.x, a.qy = quad.q.y, a.qz = quad.q.z;
  a.xx = x.x, a.xy = x.y, a.xz = x.z;
  a.yx = y.x, a.yy = y.y, a.yz = y.z;
  a.zx = z.x, a.zy = z.y, a.zz = z.z;
  a.x = Vec3(static_cast<float>(x.x), static_cast<float>(x.y), static_cast<float>(x.z));
  a.y = Vec3(static_cast<float>(y.x), static_cast<float>(y.y), static_cast<float>(y.z));
  a.z = Vec3(static_cast<float>(z.x), static_cast<float>(z.y), static_cast<float>(z.z));
  a.ex = static_cast<float>(ex), a.ey = static_cast<float>(ey);
  a.corner = quad.q;
  return a;
}

DirectionSample sample_quad_solid_angle(const Quad& quad, const Vec3& origin, float u1, float u2) {
  const SphericalRectangle r = spherical_rectangle(quad, origin);
  if (!r.usable) return sample_quad_area(quad, origin, u1, u2);

  // u1 picks the x coordinate through the area below it, u2 the height
  // uniformly in the (projected) y direction: together uniform in solid angle.
  const double au = u1 * r.solid_angle + r.k;
  const double fu = (std::cos(au) * r.b0 - r.b1) / std::sin(au);
  double cu = (fu > 0.0 ? 1.0 : -1.0) / std::sqrt(fu * fu + r.b0 * r.b0);
  cu = std::clamp(cu, -1.0, 1.0);
  double xu = -(cu * r.z0) / std::sqrt(std::max(1e-300, 1.0 - cu * cu));
  xu = std::clamp(xu, r.x0, r.x1);
  const double dist = std::sqrt(xu * xu + r.z0 * r.z0);
  const double h0 = r.y0 / std::sqrt(dist * dist + r.y0 * r.y0);
  const double h1 = r.y1 / std::sqrt(dist * dist + r.y1 * r.y1);
  const double hv = h0 + u2 * (h1 - h0);
  const double hv2 = hv * hv;
  const double yv = hv2 < 1.0 - 1e-12 ? (hv * dist) / std::sqrt(1.0 - hv2) : r.y1;
  const D3 local_dir = r.x * xu + r.y * std::clamp(yv, r.y0, r.y1) + r.z * r.z0;  // point - origin
  const D3 dir = dnormalize(local_dir);
  const double distance = std::sqrt(local_dir.x * local_dir.x + local_dir.y * local_dir.y + local_dir.z * local_dir.z);
  return {Vec3(static_cast<float>(dir.x), static_cast<float>(dir.y), static_cast<float>(dir.z)),
          static_cast<float>(1.0 / r.solid_angle), false, -1, static_cast<float>(distance)};
}

float quad_solid_angle_pdf(const Quad& quad, const Vec3& origin, const Vec3& direction, bool aimed, float aimed_t) {
  // Cheap rejection first: most directions miss the quad.
  const float t = aimed ? aimed_t : quad_hit_distance(quad, origin, direction);
  if (t < 0.0f) return 0.0f;
  const SphericalRectangle r = spherical_rectangle(quad, origin);
  if (!r.usable) return leaf::quad_area_pdf_at(quad, direction, t);
  return static_cast<float>(1.0 / r.solid_angle);
}

}  // namespace pdflab
