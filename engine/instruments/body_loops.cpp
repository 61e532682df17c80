// The body's loops, compiled for x86-64 (SSE2), x86-64-v3 (AVX2) and x86-64-v4 (AVX-512), with
// contraction off as everywhere (-ffp-contract=off): the float φ is widened exactly, so the
// products are those of a double Φ holding the same values and the energy identities hold to
// double roundoff.
#include "instruments/body_loops.h"

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace hamiltone {
namespace {

#define HAMILTONE_TARGET
#define HAMILTONE_BODY_NS portable
#define HAMILTONE_BODY_LANES 2
#include "instruments/body_loops.inl"
#undef HAMILTONE_TARGET
#undef HAMILTONE_BODY_NS
#undef HAMILTONE_BODY_LANES
#if defined(__x86_64__)
#define HAMILTONE_TARGET __attribute__((target("arch=x86-64-v3")))
#define HAMILTONE_BODY_NS avx2
#define HAMILTONE_BODY_LANES 4
#include "instruments/body_loops.inl"
#undef HAMILTONE_TARGET
#undef HAMILTONE_BODY_NS
#undef HAMILTONE_BODY_LANES
#if defined(__clang__)
#define HAMILTONE_TARGET __attribute__((target("arch=x86-64-v4")))
#else
#define HAMILTONE_TARGET __attribute__((target("arch=x86-64-v4,prefer-vector-width=512")))
#endif
#define HAMILTONE_BODY_NS avx512
#define HAMILTONE_BODY_LANES 8
#include "instruments/body_loops.inl"
#undef HAMILTONE_TARGET
#undef HAMILTONE_BODY_NS
#undef HAMILTONE_BODY_LANES
#endif

}  // namespace

const BodyLoops& bodyLoopsFor(Isa isa) {
  static const BodyLoops portablePath{portable::combineRows, portable::dotRows,
                                      portable::partialsRow};
#if defined(__x86_64__)
  static const BodyLoops avx2Path{avx2::combineRows, avx2::dotRows, avx2::partialsRow};
  static const BodyLoops avx512Path{avx512::combineRows, avx512::dotRows, avx512::partialsRow};
  if (isa == Isa::avx2) return avx2Path;
  if (isa == Isa::avx512) return avx512Path;
#endif
  (void)isa;
  return portablePath;
}

const BodyLoops& selectedBodyLoops() { return bodyLoopsFor(selectedKernels().isa); }

}  // namespace hamiltone
