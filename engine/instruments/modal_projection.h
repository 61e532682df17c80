// The soundboard's two dense products per step, w = Φa and g = Φᵀf, on Φ stored in float (half the
// memory traffic: the products are bound by it) and summed in double, for the instruction set the
// kernels chose (kernels/kernels.h): the same path gives the same bits run to run.
#pragma once

namespace hamiltone {

struct ModalProjection {
  // w_k = Σ_m φ[k ld + m] a_m for k < points.
  void (*gather)(const float* phi, long ld, long points, long modes, const double* a, double* w);
  // g_m = Σ_k φ[k ld + m] f_k for m < modes; points with f_k = 0 are skipped (not in use).
  void (*project)(const float* phi, long ld, long points, long modes, const double* f, double* g);
};

// The path of selectedKernels(): AVX2 where it runs (AVX-512 included), else SSE2.
const ModalProjection& selectedModalProjection();

}  // namespace hamiltone
