#include "ui/camera_control.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace pdflab::ui {

namespace {

glm::dvec3 d(const Vec3& v) { return {v.x, v.y, v.z}; }
Vec3 f(const glm::dvec3& v) { return Vec3(static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)); }

}  // namespace

Camera orbit(const Camera& camera, double yaw, double pitch) {
  Camera c = camera;
  const glm::dvec3 up = glm::normalize(d(camera.vup));
  const glm::dvec3 target = d(camera.lookat);
  const glm::dvec3 offset = d(camera.lookfrom) - target;
  const double r = glm::length(offset);
  if (!(r > 0.0)) return c;
  // Spherical coordinates about vup: the angle from it, and the azimuth in a
  // frame of the plane normal to it.
  const glm::dvec3 dir = offset / r;
  const double polar = std::acos(std::clamp(glm::dot(dir, up), -1.0, 1.0));
  glm::dvec3 side = dir - up * glm::dot(dir, up);
  if (glm::length(side) < 1e-12) side = std::abs(up.x) < 0.9 ? glm::cross(up, glm::dvec3(1, 0, 0)) : glm::cross(up, glm::dvec3(0, 0, 1));
  side = glm::normalize(side);
  const glm::dvec3 third = glm::cross(up, side);
  constexpr double kMargin = 0.02;  // radians short of straight above or below
  const double new_polar = std::clamp(polar - pitch, kMargin, std::numbers::pi - kMargin);
  const glm::dvec3 around = side * std::cos(yaw) + third * std::sin(yaw);
  const glm::dvec3 new_dir = up * std::cos(new_polar) + around * std::sin(new_polar);
  c.lookfrom = f(target + new_dir * r);
  return c;
}

Camera dolly(const Camera& camera, double factor) {
  Camera c = camera;
  const glm::dvec3 target = d(camera.lookat);
  const glm::dvec3 offset = d(camera.lookfrom) - target;
  const double r = glm::length(offset);
  if (!(r > 0.0) || !(factor > 0.0)) return c;
  const double to = std::max(r * factor, 1e-3 * r + 1e-3);
  c.lookfrom = f(target + offset * (to / r));
  return c;
}

Camera pan(const Camera& camera, double dx, double dy) {
  Camera c = camera;
  const glm::dvec3 from = d(camera.lookfrom), target = d(camera.lookat);
  const glm::dvec3 forward = target - from;
  const double r = glm::length(forward);
  if (!(r > 0.0)) return c;
  const glm::dvec3 w = forward / r;
  glm::dvec3 right = glm::cross(w, glm::normalize(d(camera.vup)));
  if (glm::length(right) < 1e-12) return c;
  right = glm::normalize(right);
  const glm::dvec3 up = glm::cross(right, w);
  const double height = 2.0 * r * std::tan(camera.vfov_degrees * std::numbers::pi / 360.0);
  const glm::dvec3 shift = (right * dx + up * dy) * height;
  c.lookfrom = f(from + shift);
  c.lookat = f(target + shift);
  return c;
}

bool same_placement(const Camera& a, const Camera& b) {
  return a.lookfrom == b.lookfrom && a.lookat == b.lookat && a.vup == b.vup && a.vfov_degrees == b.vfov_degrees;
}

}  // namespace pdflab::ui
