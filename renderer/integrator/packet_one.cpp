// One lane: the one-path tracer (trace_path), the same code as every packet
// (packet_kernels.h).
#include "renderer/integrator/packet_kernels.h"

#define PDFLAB_PACKET_ONE 1
#define PDFLAB_PACKET_AVX2 0
#define PDFLAB_PACKET_AVX512 0
namespace pdflab::packet_one {
#include "renderer/integrator/kernel.inc"
}  // namespace pdflab::packet_one
