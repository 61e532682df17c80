// The soundboard's products, compiled for x86-64 (SSE2) and x86-64-v3 (AVX2), with contraction
// off as everywhere (-ffp-contract=off): the float φ is widened exactly, so the products are
// those of a double Φ holding the same values and the energy identities hold to double roundoff.
#include "instruments/modal_projection.h"

#include "kernels/kernels.h"

namespace hamiltone {

namespace {

#define HAMILTONE_TARGET
#define HAMILTONE_PROJECTION_NS portable
#include "instruments/modal_projection_loops.inl"
#undef HAMILTONE_TARGET
#undef HAMILTONE_PROJECTION_NS

#if defined(__x86_64__)
#define HAMILTONE_TARGET __attribute__((target("arch=x86-64-v3")))
#define HAMILTONE_PROJECTION_NS avx2
#include "instruments/modal_projection_loops.inl"
#undef HAMILTONE_TARGET
#undef HAMILTONE_PROJECTION_NS
#endif

}  // namespace

const ModalProjection& selectedModalProjection() {
  static const ModalProjection portablePath{portable::gather, portable::project};
#if defined(__x86_64__)
  static const ModalProjection avx2Path{avx2::gather, avx2::project};
  if (selectedKernels().isa != Isa::portable) return avx2Path;
#endif
  return portablePath;
}

}  // namespace hamiltone
