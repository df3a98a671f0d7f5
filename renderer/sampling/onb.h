#pragma once
// Orthonormal basis around a unit normal, branchless and continuous except at
// n.z = -0 (Duff et al., "Building an Orthonormal Basis, Revisited", JCGT 2017).
// Works for normals along every axis, including exactly -z.
#include "renderer/math.h"

namespace pdflab {

struct Onb {
  Vec3 s, t, n;

  explicit Onb(const Vec3& normal) : n(normal) {
    const float sign = std::copysign(1.0f, n.z);
    const float a = -1.0f / (sign + n.z);
    const float b = n.x * n.y * a;
    s = Vec3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
    t = Vec3(b, sign + n.y * n.y * a, -n.y);
  }

  Vec3 to_world(const Vec3& local) const { return s * local.x + t * local.y + n * local.z; }
  Vec3 to_local(const Vec3& world) const { return {dot(world, s), dot(world, t), dot(world, n)}; }
};

}  // namespace pdflab
