// Which of the packet kernels (packet_kernels.h) runs: the widest this
// machine has, or the one PDFLAB_ISA names.
#include "renderer/integrator/packet_kernels.h"

namespace pdflab {

namespace {
// Whether this build has the kernel for `isa` and this machine (with its
// operating system, which must save the wider registers) can run it.
bool runs_here(PacketIsa isa) {
  switch (isa) {
    case PacketIsa::Generic:
      return true;
    case PacketIsa::Avx2:
#if PDFLAB_PACKET_DISPATCH
      return __builtin_cpu_supports("avx2");
#elif defined(__AVX2__) && !defined(__AVX512F__)
      return true;  // the baseline build already targets it
#else
      return false;
#endif
    case PacketIsa::Avx512:
#if PDFLAB_PACKET_DISPATCH
      return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq");
#else
      return false;
#endif
  }
  return false;
}
}  // namespace

std::vector<PacketIsa> available_packet_isas() {
  std::vector<PacketIsa> v;
  for (const PacketIsa isa : {PacketIsa::Generic, PacketIsa::Avx2, PacketIsa::Avx512})
    if (runs_here(isa)) v.push_back(isa);
  return v;
}

PacketIsa choose_packet_isa(const char* requested, const std::vector<PacketIsa>& here, std::string& warning) {
  warning.clear();
  const PacketIsa widest = here.back();
  if (!requested || !*requested) return widest;  // unset, or set empty
  for (const PacketIsa isa : here)
    if (packet_isa_name(isa) == requested) return isa;
  std::string known;
  for (const PacketIsa isa : {PacketIsa::Generic, PacketIsa::Avx2, PacketIsa::Avx512})
    known += std::string(known.empty() ? "" : ", ") + std::string(packet_isa_name(isa));
  const bool named = std::string_view(requested) == "generic" || std::string_view(requested) == "avx2" ||
                     std::string_view(requested) == "avx512";
  warning = "PDFLAB_ISA=" + std::string(requested) +
            (named ? ": this machine (or this build) does not run it"
                   : " is not an instruction set pdflab knows (" + known + ")") +
            "; using " + std::string(packet_isa_name(widest));
  return widest;
}

PacketIsa best_packet_isa() {
  // PDFLAB_ISA=generic, avx2 or avx512 caps the choice (to compare, or to rule the wider code out).
  static const PacketIsa isa = [] {
    std::string warning;
    const PacketIsa chosen = choose_packet_isa(std::getenv("PDFLAB_ISA"), available_packet_isas(), warning);
    if (!warning.empty()) std::fprintf(stderr, "warning: %s\n", warning.c_str());
    return chosen;
  }();
  return isa;
}

std::string_view packet_isa_name(PacketIsa isa) {
  switch (isa) {
    case PacketIsa::Avx2:
      return "avx2";
    case PacketIsa::Avx512:
      return "avx512";
    case PacketIsa::Generic:
      break;
  }
  return "generic";
}

int packet_lanes(PacketIsa isa) {
#if PDFLAB_PACKET_DISPATCH
  if (isa == PacketIsa::Avx512) return packet_avx512::lane_count();
  if (isa == PacketIsa::Avx2) return packet_avx2::lane_count();
#else
  (void)isa;
#endif
  return packet_generic::lane_count();
}

// Calls the kernel compiled for `isa` (AVX2 and AVX-512 only where the build dispatches).
#if PDFLAB_PACKET_DISPATCH
#define PDFLAB_PACKET_CALL(isa, call)                              \
  if ((isa) == PacketIsa::Avx512) return packet_avx512::call;   \
  if ((isa) == PacketIsa::Avx2) return packet_avx2::call;       \
  return packet_generic::call
#else
#define PDFLAB_PACKET_CALL(isa, call) \
  (void)(isa);                        \
  return packet_generic::call
#endif

void trace_block(PacketIsa isa, const Scene& scene, const SamplingPlan& plan, std::uint64_t seed,
                 const SampleBlock& block, SampleResult* out, GuidingTrainer* trainer) {
  PDFLAB_PACKET_CALL(isa, trace_block_impl(scene, plan, seed, block, out, trainer));
}

void sample_plan(PacketIsa isa, const SamplingPlan& plan, const PlanDraw* draws, std::size_t n, DirectionSample* out) {
  PDFLAB_PACKET_CALL(isa, sample_plan_impl(plan, draws, n, out));
}

void plan_pdf(PacketIsa isa, const SamplingPlan& plan, const PlanDraw* draws, const Vec3* directions, std::size_t n,
              float* out) {
  PDFLAB_PACKET_CALL(isa, plan_pdf_impl(plan, draws, directions, n, out));
}

void sample_emitters(PacketIsa isa, const SamplingPlan& plan, const PlanDraw* draws, std::size_t n,
                     DirectionSample* out) {
  PDFLAB_PACKET_CALL(isa, sample_emitters_impl(plan, draws, n, out));
}

void nearest_hits(PacketIsa isa, const Scene& scene, const TracedRay* rays, std::size_t n, NearestHit* out) {
  PDFLAB_PACKET_CALL(isa, nearest_hits_impl(scene, rays, n, out));
}

#undef PDFLAB_PACKET_CALL

void nearest_hits(const Scene& scene, const TracedRay* rays, std::size_t n, NearestHit* out) {
  packet_one::nearest_hits_impl(scene, rays, n, out);
}

void trace_block(const Scene& scene, const SamplingPlan& plan, std::uint64_t seed, const SampleBlock& block,
                 SampleResult* out, GuidingTrainer* trainer) {
  trace_block(best_packet_isa(), scene, plan, seed, block, out, trainer);
}

// The one-path tracer (integrator.h) is the packet tracer's code on one lane.
Vec3 trace_path(const Scene& scene, const SamplingPlan& plan, Ray ray, Rng& rng, DropCounts& drops,
                PathRecord* record) {
  const SampleResult r = packet_one::trace_path_impl(scene, plan, ray, rng, record);
  for (int reason = 0; reason < kDropReasonCount; ++reason)
    if (r.drops & (1u << reason)) drops.add(static_cast<DropReason>(reason));
  return r.radiance;
}

}  // namespace pdflab

