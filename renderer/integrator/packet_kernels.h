#pragma once
// The packet tracer's kernels: kernel.inc compiled once per lane width, each in
// a translation unit and a namespace of its own, so that a build compiles the
// four side by side:
//
//   packet_one.cpp      packet_one       one lane: the one-path tracer (trace_path)
//   packet_generic.cpp  packet_generic   the baseline's vectors (SSE2 or NEON)
//   packet_avx2.cpp     packet_avx2      AVX2, chosen at run time (PDFLAB_PACKET_DISPATCH)
//   packet_avx512.cpp   packet_avx512    AVX-512, chosen at run time
//
// packet.cpp declares nothing else and picks among them. Included first by each
// of those files: what it sets up (the diagnostics, the intrinsics, the leaf
// math's headers) comes before any `#pragma GCC target` region, so that helpers
// from other headers are compiled for the baseline and may be inlined into the
// wider code, never the other way round (an inline function emitted in a wider
// unit could otherwise be the copy the linker keeps for baseline callers).

// Vectors of eight or sixteen lanes are passed between the kernel's inline
// helpers only (and rng.h's, always inlined): the note that their ABI differs
// without AVX does not apply.
#pragma GCC diagnostic ignored "-Wpsabi"

#include "renderer/integrator/packet.h"

#include <array>
#include <bit>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <numbers>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#if defined(__x86_64__) || defined(__i386__)
// GCC 12 warns inside its own AVX-512 header, where _mm512_undefined_ps and
// its kin read a deliberately undefined register (GCC bug 105593): the
// warnings (maybe and definitely uninitialized, by how the call is inlined)
// are about the header's lines, so they are turned off for them only.
#pragma GCC diagnostic push
#if !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wuninitialized"
#endif
#include <immintrin.h>
#pragma GCC diagnostic pop
#define PDFLAB_PACKET_X86 1
#else
#define PDFLAB_PACKET_X86 0
#endif

// With GCC on x86-64 the kernel is compiled twice more, for AVX2 (eight lanes
// in one register, against four with SSE2) and for AVX-512 (sixteen), and the
// widest the machine has is chosen at run time, so a portable build still uses
// the machine it runs on. The arithmetic is the same IEEE operations in the
// same order either way (the build turns off FMA contraction), so all give the
// same bits.
#if PDFLAB_PACKET_X86 && defined(__GNUC__) && !defined(__clang__) && !defined(__AVX2__)
#define PDFLAB_PACKET_DISPATCH 1
#else
#define PDFLAB_PACKET_DISPATCH 0
#endif

#include "renderer/sampling/mixture.h"  // the one-path tracer's leaf math
#include "renderer/sampling/sobol.h"  // its templates run on the kernel's vectors too

#include <glm/gtc/type_ptr.hpp>

namespace pdflab {

// What each kernel's unit defines (schedule.inc, and lane_count there).
#define PDFLAB_PACKET_KERNEL_ENTRIES                                                                         \
  int lane_count();                                                                                          \
  void trace_block_impl(const Scene& scene, const SamplingPlan& plan, std::uint64_t seed,                    \
                        const SampleBlock& block, SampleResult* out, GuidingTrainer* trainer);               \
  void sample_plan_impl(const SamplingPlan& plan, const PlanDraw* draws, std::size_t n, DirectionSample* out); \
  void plan_pdf_impl(const SamplingPlan& plan, const PlanDraw* draws, const Vec3* directions, std::size_t n,  \
                     float* out);                                                                            \
  void sample_emitters_impl(const SamplingPlan& plan, const PlanDraw* draws, std::size_t n,                  \
                            DirectionSample* out);                                                           \
  void nearest_hits_impl(const Scene& scene, const TracedRay* rays, std::size_t n, NearestHit* out);

namespace packet_generic {
PDFLAB_PACKET_KERNEL_ENTRIES
}  // namespace packet_generic

namespace packet_one {
PDFLAB_PACKET_KERNEL_ENTRIES
SampleResult trace_path_impl(const Scene& scene, const SamplingPlan& plan, const Ray& ray, Rng& rng,
                             PathRecord* record);
}  // namespace packet_one

#if PDFLAB_PACKET_DISPATCH
namespace packet_avx2 {
PDFLAB_PACKET_KERNEL_ENTRIES
}  // namespace packet_avx2
namespace packet_avx512 {
PDFLAB_PACKET_KERNEL_ENTRIES
}  // namespace packet_avx512
#endif

#undef PDFLAB_PACKET_KERNEL_ENTRIES

}  // namespace pdflab
