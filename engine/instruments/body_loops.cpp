// The body's loops, compiled for x86-64 (SSE2) and x86-64-v3 (AVX2), with contraction off as
// everywhere (-ffp-contract=off): the float φ is widened exactly, so the products are those of a
// double Φ holding the same values and the energy identities hold to double roundoff.
#include "instruments/body_loops.h"

#include "kernels/kernels.h"

namespace hamiltone {

namespace {

#define HAMILTONE_TARGET
#define HAMILTONE_BODY_NS portable
#include "instruments/body_loops.inl"
#undef HAMILTONE_TARGET
#undef HAMILTONE_BODY_NS

#if defined(__x86_64__)
#define HAMILTONE_TARGET __attribute__((target("arch=x86-64-v3")))
#define HAMILTONE_BODY_NS avx2
#include "instruments/body_loops.inl"
#undef HAMILTONE_TARGET
#undef HAMILTONE_BODY_NS
#endif

}  // namespace

const BodyLoops& selectedBodyLoops() {
  static const BodyLoops portablePath{portable::gather, portable::project, portable::partialsRow};
#if defined(__x86_64__)
  static const BodyLoops avx2Path{avx2::gather, avx2::project, avx2::partialsRow};
  if (selectedKernels().isa != Isa::portable) return avx2Path;
#endif
  return portablePath;
}

}  // namespace hamiltone
