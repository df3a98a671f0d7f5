#pragma once
// The book's estimator for several paths at once: sixteen with AVX-512, eight
// with AVX2, four with SSE2 or NEON. Each SIMD lane carries one path; a lane
// whose path ends takes the next pixel sample at once, so the lanes stay full
// (the next samples' camera rays and streams are set up W at a time).
// Intersection (every primitive against all the lanes' rays), hits, emission,
// the diffuse bounce's sampling and mixture pdf, glass, metal and the spawned
// rays run for all lanes at once, as do nee-mis's shadow rays; each path's
// random numbers come from its own stream (stepped for all lanes at once with
// AVX2 or AVX-512), and the spherical rectangles of light-sa and nee-mis are
// set up for all lanes in float (a lane outside the float form's domain takes
// the double form alone).
//
// Every operation mirrors trace_path's, in the same order and precision, and
// a sample's random numbers come from its own stream as before, so a sample's
// radiance is the same, bit for bit, as render_pixel_sample's (up to which of
// two primitives at exactly the same distance counts as hit). The result
// depends only on (seed, pixel, sample): it is identical for any thread count.
#include "renderer/integrator/integrator.h"

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace pdflab {

// The samples first_sample .. first_sample + spp - 1 of every pixel in
// [x0, x1) x [y0, y1).
struct SampleBlock {
  int x0, y0, x1, y1;
  std::uint32_t first_sample, spp;
  std::size_t size() const {
    return static_cast<std::size_t>(x1 - x0) * static_cast<std::size_t>(y1 - y0) * spp;
  }
};

struct SampleResult {
  Vec3 radiance;
  std::uint8_t drops;  // bit r: the sample was dropped for DropReason r
};

enum class PacketIsa : std::uint8_t { Generic, Avx2, Avx512 };
// Every instruction set this build has a kernel for and this machine runs,
// narrowest first (Generic always).
std::vector<PacketIsa> available_packet_isas();
// The instruction set trace_block uses: the widest this machine has, or the
// one the environment names in PDFLAB_ISA (generic, avx2 or avx512) where it is
// available.
PacketIsa best_packet_isa();
// best_packet_isa's choice among `here` (available_packet_isas) for the
// PDFLAB_ISA value `requested` (null or empty: not set): the one named, or the widest
// where the name is unknown or this machine lacks it, and then `warning` says
// so (best_packet_isa prints it once, on stderr); otherwise `warning` is empty.
PacketIsa choose_packet_isa(const char* requested, const std::vector<PacketIsa>& here, std::string& warning);
std::string_view packet_isa_name(PacketIsa isa);
int packet_lanes(PacketIsa isa);  // paths traced together

// Renders every sample of the block; out[(pixel row-major within the block) * spp + k]
// receives sample first_sample + k. With `trainer`, every diffuse vertex's
// incident light is recorded into it as the paths end (guiding.h): the
// samples are the same.
void trace_block(const Scene& scene, const SamplingPlan& plan, std::uint64_t seed, const SampleBlock& block,
                 SampleResult* out, GuidingTrainer* trainer = nullptr);
// The same with a given instruction set (tests compare them); it must be available.
void trace_block(PacketIsa isa, const Scene& scene, const SamplingPlan& plan, std::uint64_t seed,
                 const SampleBlock& block, SampleResult* out, GuidingTrainer* trainer = nullptr);

// The sampling plan's draw at diffuse shading points, `packet_lanes` at a
// time through the very code the packet tracer renders with (for the
// chi-square suite and the tests that compare it with the one-path draw).
// Each draw gives its random numbers: u0 picks the technique, u1 and u2 the
// direction, u_choice the target (used only by the techniques that draw one).
struct PlanDraw {
  Vec3 point, normal;  // normal faces the incoming ray
  std::uint32_t u0;  // the technique's 32 random bits
  float u1, u2;
  std::uint32_t u_choice;  // the target's
  // log2(1 - u1) where u1 is its largest value (kLargestUniform) and the
  // technique draws the tail (leaf::Shading::top_log2); -24: undrawn.
  float top_log2 = -24.0f;
  // The surface drawn at (the `bsdf` technique's lobe: lambertian unless
  // glossy) and, at a rough dielectric, the number choosing reflection or refraction.
  SurfaceLobe surface{};
  float u_lobe = 0.0f;
};
void sample_plan(PacketIsa isa, const SamplingPlan& plan, const PlanDraw* draws, std::size_t n, DirectionSample* out);
// The mixture's density for `directions[i]` at draws[i]'s point (its random numbers unused).
void plan_pdf(PacketIsa isa, const SamplingPlan& plan, const PlanDraw* draws, const Vec3* directions, std::size_t n,
              float* out);

// nee-mis's light sample from the plan's emitter set (SamplingPlan::emitters,
// drawn by solid angle: TargetSet::solid_angle), `packet_lanes` at a time
// through the code the packet tracer renders with, as TargetSet::sample draws
// it (each draw's point, u_choice, u1 and u2; no normal).
void sample_emitters(PacketIsa isa, const SamplingPlan& plan, const PlanDraw* draws, std::size_t n,
                     DirectionSample* out);

// A ray as a path follows it, for nearest_hits: aimed at object `aimed` (a
// quad's number, or a sphere's: quads, then spheres; -1: none) at distance
// `aimed_t` (leaf::Sampled::aimed_quad and aimed_distance).
struct TracedRay {
  Vec3 origin, direction;
  std::int32_t aimed = -1;
  float aimed_t = 0.0f;
};
struct NearestHit {
  float t;
  std::int32_t object;  // -1: none
};
// The nearest hits that the paths find along `rays` (the tracer's intersection,
// with the scene's tree where it has one), packet_lanes(isa) rays at a time,
// for the tests that compare them with and without the tree.
void nearest_hits(PacketIsa isa, const Scene& scene, const TracedRay* rays, std::size_t n, NearestHit* out);
// The same through the one-path tracer, a ray at a time.
void nearest_hits(const Scene& scene, const TracedRay* rays, std::size_t n, NearestHit* out);

}  // namespace pdflab
