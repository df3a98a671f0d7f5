#pragma once
// Small vector helpers on top of GLM. Everything in the renderer is float;
// accumulation (film, statistics) is double.
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>

namespace pdflab {

using Vec3 = glm::vec3;

inline constexpr float kPi = std::numbers::pi_v<float>;
inline constexpr float kInvPi = std::numbers::inv_pi_v<float>;
inline constexpr float kInf = std::numeric_limits<float>::infinity();

inline float dot(const Vec3& a, const Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline float length_squared(const Vec3& a) { return dot(a, a); }
inline float length(const Vec3& a) { return std::sqrt(dot(a, a)); }
inline Vec3 normalize(const Vec3& a) { return a * (1.0f / length(a)); }
// Plain comparisons: they compile to single instructions, where std::fmax's
// NaN rules become a library call in the hot path.
inline float max_of(float a, float b) { return a > b ? a : b; }
inline float min_of(float a, float b) { return a < b ? a : b; }
// x if positive, else 0 (also for NaN): the argument of a sqrt that rounding may push below 0.
inline float positive_part(float x) { return x > 0.0f ? x : 0.0f; }
inline float max_abs_component(const Vec3& a) {
  return max_of(std::fabs(a.x), max_of(std::fabs(a.y), std::fabs(a.z)));
}
// Rec. 709 luminance, in double: the brightness a viewer sees. The noise and
// error measures, the viewer's readouts and an emitter's power all use it.
inline constexpr double kLuminanceR = 0.2126, kLuminanceG = 0.7152, kLuminanceB = 0.0722;
inline constexpr double luminance(double r, double g, double b) {
  return kLuminanceR * r + kLuminanceG * g + kLuminanceB * b;
}
template <class T>
constexpr double luminance(const T* rgb) {
  return luminance(rgb[0], rgb[1], rgb[2]);
}
inline bool is_finite(const Vec3& a) {
  return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z);
}

struct Ray {
  Vec3 origin;
  Vec3 direction;  // unit length everywhere in the renderer
};

}  // namespace pdflab
