// The packet kernel in AVX-512's sixteen lanes (Foundation and DQ: the 64-bit
// multiply of the random streams), chosen at run time where the machine has it
// (packet_kernels.h); empty where the build does not dispatch.
#include "renderer/integrator/packet_kernels.h"

#if PDFLAB_PACKET_DISPATCH
#pragma GCC push_options
#pragma GCC target("avx2,avx512f,avx512dq")
#define PDFLAB_PACKET_ONE 0
#define PDFLAB_PACKET_AVX2 0
#define PDFLAB_PACKET_AVX512 1
namespace pdflab::packet_avx512 {
#include "renderer/integrator/kernel.inc"
}  // namespace pdflab::packet_avx512
#pragma GCC pop_options
#endif
