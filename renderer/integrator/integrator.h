#pragma once
// The book's estimator, iterative: L = emission + albedo * scattering_pdf * L_i / pdf
// at diffuse hits; metal and dielectric follow their own direction.
#include "renderer/math.h"
#include "renderer/sampling/rng.h"
#include "renderer/sampling/strategy.h"
#include "renderer/scene/scene.h"

#include <array>
#include <cstdint>
#include <string_view>
#include <vector>

namespace pdflab {

// Why a sample was dropped (contributed nothing but still counted as a sample).
enum class DropReason : std::uint8_t {
  PdfZero,           // the strategy's pdf was zero or negative for its own sample
  PdfNotFinite,      // NaN or infinite pdf (a shading point in a light's plane, on the light)
  RadianceNotFinite, // the path's estimate overflowed or became NaN
  Count
};
inline constexpr int kDropReasonCount = static_cast<int>(DropReason::Count);
std::string_view drop_reason_name(DropReason r);

struct DropCounts {
  std::array<std::uint64_t, kDropReasonCount> by_reason{};
  void add(DropReason r) { ++by_reason[static_cast<int>(r)]; }
  std::uint64_t total() const {
    std::uint64_t t = 0;
    for (auto c : by_reason) t += c;
    return t;
  }
  DropCounts& operator+=(const DropCounts& o) {
    for (int i = 0; i < kDropReasonCount; ++i) by_reason[i] += o.by_reason[i];
    return *this;
  }
};

// Bit r set when the count of DropReason r grew from `before` to `after`: the
// reasons a run of samples (one pixel's) dropped, for Film::mark_drops.
inline std::uint8_t drop_reason_bits(const DropCounts& before, const DropCounts& after) {
  std::uint8_t bits = 0;
  for (int r = 0; r < kDropReasonCount; ++r)
    if (after.by_reason[r] != before.by_reason[r]) bits |= static_cast<std::uint8_t>(1u << r);
  return bits;
}

// What the mixture-weight predictor needs of a path (renderer/metrics/weight_paths.h):
// each diffuse vertex's point, normal (facing the arriving ray) and the direction
// the mixture drew there, and how many rays the path traced. With Russian
// roulette, also each survived check's largest throughput * albedo (the
// survival probability before it is cut to 1, which depends on the weights
// the path was drawn with) and where on the path each vertex lies.
struct PathRecord {
  struct Vertex {
    Vec3 point, normal, direction;
    float roulette = 0.0f;  // leaf::roulette_largest at the check before the direction; 0: no check
    int segments = 0;       // segments traced up to this vertex, the one reaching it included
  };
  std::vector<Vertex> vertices;
  int segments = 0;
};

// Radiance along one camera ray. Returns zero (and counts) when the estimate is
// not finite. With `record` (mixtures only), also what the path did; its
// vector keeps its capacity from path to path.
Vec3 trace_path(const Scene& scene, const SamplingPlan& plan, Ray ray, Rng& rng, DropCounts& drops,
                PathRecord* record = nullptr);

// The camera ray and the random stream of one pixel sample.
struct PixelSampleStart {
  Ray ray;
  Rng rng;
};
// The seed's share of every sample's stream and scramble, computed once.
struct SampleSeed {
  explicit SampleSeed(std::uint64_t seed);
  std::uint64_t rng_key, scramble_key;
};
PixelSampleStart begin_pixel_sample(const Scene& scene, const SampleSeed& seed, int x, int y,
                                    std::uint32_t sample_index);

// One pixel sample: position within the pixel from a scrambled (0,2)-sequence
// (stratified at every power of two), then the path.
Vec3 render_pixel_sample(const Scene& scene, const SamplingPlan& plan, std::uint64_t seed, int x, int y,
                         std::uint32_t sample_index, DropCounts& drops);

}  // namespace pdflab
