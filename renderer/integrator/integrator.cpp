#include "renderer/integrator/integrator.h"

#include "renderer/sampling/sobol.h"

namespace pdflab {

std::string_view drop_reason_name(DropReason r) {
  switch (r) {
    case DropReason::PdfZero: return "pdf_zero";
    case DropReason::PdfNotFinite: return "pdf_not_finite";
    case DropReason::RadianceNotFinite: return "radiance_not_finite";
    default: return "unknown";
  }
}

SampleSeed::SampleSeed(std::uint64_t seed_value)
    : rng_key(Rng::seed_key(seed_value)), scramble_key(mix64(seed_value ^ 0x5bd1e995u)) {}

#include "renderer/integrator/pixel_sample.inc"

namespace {
// pixel_sample_numbers for one sample.
struct OneSample {
  using U64 = std::uint64_t;
  using U32 = std::uint32_t;
  using F = float;
  static U32 low32(U64 x) { return static_cast<U32>(x); }
  static U64 wide(U32 x) { return x; }
  static F unit(U32 x) { return Rng::to_unit(x); }
};
}  // namespace

PixelSampleStart begin_pixel_sample(const Scene& scene, const SampleSeed& seed, int x, int y,
                                    std::uint32_t sample_index) {
  const std::uint64_t pixel = static_cast<std::uint64_t>(y) * static_cast<std::uint64_t>(scene.camera.width) +
                              static_cast<std::uint64_t>(x);
  const PixelSampleNumbers<OneSample> n =
      pixel_sample_numbers<OneSample>(seed, pixel, static_cast<float>(x), static_cast<float>(y), sample_index);
  PixelSampleStart start{scene.camera.generate_ray(n.px, n.py), Rng::from_parts(n.rng_state, n.rng_increment)};
  start.rng.qmc_index = sample_index;
  start.rng.qmc_seed = n.qmc_seed;
  return start;
}

Vec3 render_pixel_sample(const Scene& scene, const SamplingPlan& plan, std::uint64_t seed, int x, int y,
                         std::uint32_t sample_index, DropCounts& drops) {
  PixelSampleStart start = begin_pixel_sample(scene, SampleSeed(seed), x, y, sample_index);
  return trace_path(scene, plan, start.ray, start.rng, drops);
}

}  // namespace pdflab
