// The piano body's hot loops, for the instruction set the kernels chose (kernels/kernels.h): the
// same path gives the same bits run to run. The soundboard's two dense products per step, w = Φa
// and g = Φᵀf, on Φ stored in float (half the memory traffic, which bounds them) and summed in
// double; the sympathetic strings' step over one row of partials.
#pragma once

namespace hamiltone {

struct BodyLoops {
  // w_k = Σ_m φ[k ld + m] a_m for the `count` points k = rows[0 … count).
  void (*gather)(const float* phi, long ld, const int* rows, long count, long modes,
                 const double* a, double* w);
  // g_m = Σ_k φ[k ld + m] f_k for m < modes; points with f_k = 0 (no force) are skipped.
  void (*project)(const float* phi, long ld, long points, long modes, const double* f, double* g);
  // Partial n of keys 0 … keys − 1 (sympathetic_strings.h (Y3), (Y4)): f −= c b; next = a1 b −
  // a2 prev − a3 c w into prev; lost += σ (next − prev)².
  void (*partialsRow)(long keys, const double* a1, const double* a2, const double* a3,
                      const double* c, const double* sigma, const double* b, const double* w,
                      double* prev, double* lost, double* f);
};

// The path of selectedKernels(): AVX2 where it runs (AVX-512 included), else SSE2.
const BodyLoops& selectedBodyLoops();

}  // namespace hamiltone
