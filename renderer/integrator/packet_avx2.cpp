// The packet kernel in AVX2's eight lanes, chosen at run time where the machine
// has it (packet_kernels.h); empty where the build does not dispatch.
#include "renderer/integrator/packet_kernels.h"

#if PDFLAB_PACKET_DISPATCH
#pragma GCC push_options
#pragma GCC target("avx2")
#define PDFLAB_PACKET_ONE 0
#define PDFLAB_PACKET_AVX2 1
#define PDFLAB_PACKET_AVX512 0
namespace pdflab::packet_avx2 {
#include "renderer/integrator/kernel.inc"
}  // namespace pdflab::packet_avx2
#pragma GCC pop_options
#endif
