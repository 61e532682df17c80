// The kernels for x86-64-v3: AVX2 and FMA (contraction stays off, as everywhere: -ffp-contract).
#include "kernels/kernels.h"

#if defined(__x86_64__)
#define HAMILTONE_TARGET __attribute__((target("arch=x86-64-v3")))
#define HAMILTONE_KERNEL_NS avx2
#define HAMILTONE_KERNEL_ISA Isa::avx2
#define HAMILTONE_KERNEL_NAME "avx2"
#define HAMILTONE_KERNEL_LANES 4  // doubles in a vector register
#include "kernels/kernel_loops.inl"
#endif
