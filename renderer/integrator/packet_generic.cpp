// The packet kernel in the baseline's vectors (packet_kernels.h).
#include "renderer/integrator/packet_kernels.h"

#define PDFLAB_PACKET_ONE 0
#define PDFLAB_PACKET_AVX2 0
#define PDFLAB_PACKET_AVX512 0
namespace pdflab::packet_generic {
#include "renderer/integrator/kernel.inc"
}  // namespace pdflab::packet_generic
