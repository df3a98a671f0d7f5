#include "renderer/integrator/packet.h"

#include <array>
#include <cstdlib>
#include <cstring>
#include <numbers>
#include <string_view>
#include <type_traits>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define PDFLAB_PACKET_X86 1
#else
#define PDFLAB_PACKET_X86 0
#endif

// With GCC on x86-64 the kernel is compiled a second time for AVX2 (eight
// lanes in one register, against four with SSE2), chosen at run time, so a
// portable build still uses the machine it runs on. The arithmetic is the same
// IEEE operations in the same order either way (the build turns off FMA
// contraction), so both give the same bits. Helpers from other headers are compiled for the baseline and may
// be inlined into the AVX2 code, never the other way round.
#if PDFLAB_PACKET_X86 && defined(__GNUC__) && !defined(__clang__) && !defined(__AVX2__)
#define PDFLAB_PACKET_DISPATCH 1
#else
#define PDFLAB_PACKET_DISPATCH 0
#endif

// Vectors of eight floats are passed between the kernel's inline helpers only;
// the note that their ABI differs without AVX does not apply.
#pragma GCC diagnostic ignored "-Wpsabi"

#include "renderer/sampling/sobol.h"  // its templates run on the kernel's vectors too

namespace pdflab {

namespace packet_generic {
#define PDFLAB_PACKET_AVX2 0
#include "renderer/integrator/packet_kernel.inc"
#undef PDFLAB_PACKET_AVX2
}  // namespace packet_generic

#if PDFLAB_PACKET_DISPATCH
#pragma GCC push_options
#pragma GCC target("avx2")
namespace packet_avx2 {
#define PDFLAB_PACKET_AVX2 1
#include "renderer/integrator/packet_kernel.inc"
#undef PDFLAB_PACKET_AVX2
}  // namespace packet_avx2
#pragma GCC pop_options
#endif

PacketIsa best_packet_isa() {
  // PDFLAB_ISA=generic keeps the baseline code (to compare, or to rule the wider code out).
  static const PacketIsa isa = [] {
    const char* requested = std::getenv("PDFLAB_ISA");
    if (requested && std::string_view(requested) == "generic") return PacketIsa::Generic;
#if PDFLAB_PACKET_DISPATCH
    return __builtin_cpu_supports("avx2") ? PacketIsa::Avx2 : PacketIsa::Generic;
#elif defined(__AVX2__)
    return PacketIsa::Avx2;  // the baseline build already targets it
#else
    return PacketIsa::Generic;
#endif
  }();
  return isa;
}

std::string_view packet_isa_name(PacketIsa isa) { return isa == PacketIsa::Avx2 ? "avx2" : "generic"; }

int packet_lanes(PacketIsa isa) {
#if PDFLAB_PACKET_DISPATCH
  if (isa == PacketIsa::Avx2) return packet_avx2::W;
#else
  (void)isa;
#endif
  return packet_generic::W;
}

// Calls the kernel compiled for `isa` (AVX2 only where the build dispatches).
#if PDFLAB_PACKET_DISPATCH
#define PDFLAB_PACKET_CALL(isa, call)                          \
  if ((isa) == PacketIsa::Avx2) return packet_avx2::call; \
  return packet_generic::call
#else
#define PDFLAB_PACKET_CALL(isa, call) \
  (void)(isa);                        \
  return packet_generic::call
#endif

void trace_block(PacketIsa isa, const Scene& scene, const SamplingPlan& plan, std::uint64_t seed,
                 const SampleBlock& block, SampleResult* out) {
  PDFLAB_PACKET_CALL(isa, trace_block_impl(scene, plan, seed, block, out));
}

void sample_plan(PacketIsa isa, const SamplingPlan& plan, const PlanDraw* draws, std::size_t n, DirectionSample* out) {
  PDFLAB_PACKET_CALL(isa, sample_plan_impl(plan, draws, n, out));
}

void plan_pdf(PacketIsa isa, const SamplingPlan& plan, const PlanDraw* draws, const Vec3* directions, std::size_t n,
              float* out) {
  PDFLAB_PACKET_CALL(isa, plan_pdf_impl(plan, draws, directions, n, out));
}

#undef PDFLAB_PACKET_CALL

void trace_block(const Scene& scene, const SamplingPlan& plan, std::uint64_t seed, const SampleBlock& block,
                 SampleResult* out) {
  trace_block(best_packet_isa(), scene, plan, seed, block, out);
}

}  // namespace pdflab

