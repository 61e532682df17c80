// The kernels for x86-64-v4: AVX-512, with 512-bit vectors where GCC would otherwise stay at 256.
#include "kernels/kernels.h"

#if defined(__x86_64__)
#if defined(__clang__)
#define HAMILTONE_TARGET __attribute__((target("arch=x86-64-v4")))
#else
#define HAMILTONE_TARGET __attribute__((target("arch=x86-64-v4,prefer-vector-width=512")))
#endif
#define HAMILTONE_KERNEL_NS avx512
#define HAMILTONE_KERNEL_ISA Isa::avx512
#define HAMILTONE_KERNEL_NAME "avx512"
#define HAMILTONE_KERNEL_LANES 8  // doubles in a vector register
#include "kernels/kernel_loops.inl"
#endif
