// The kernels for the build's own target (plain x86-64: SSE2), which every CPU runs.
#include "kernels/kernels.h"

#define HAMILTONE_TARGET
#define HAMILTONE_KERNEL_NS portable
#define HAMILTONE_KERNEL_ISA Isa::portable
#define HAMILTONE_KERNEL_NAME "portable"
#define HAMILTONE_KERNEL_LANES 2  // doubles in a vector register
#include "kernels/kernel_loops.inl"
