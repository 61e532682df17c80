// The piano body's hot loops, for the instruction set the kernels chose (kernels/kernels.h). The
// soundboard's two dense products per step, g = Φᵀf and w = Φa, on Φ stored in float (half the
// memory) and summed in double, each output a sum in a fixed order; the sympathetic strings' step
// over one row of partials.
#pragma once

#include "kernels/kernels.h"

namespace hamiltone {

// The rows of a body matrix are padded with zeros to a multiple of this many floats, so that the
// products read whole vector registers (kMaxLanes doubles) from any multiple of it.
constexpr long kBodyPad = kMaxLanes;
constexpr long bodyPadded(long columns) { return (columns + kBodyPad - 1) / kBodyPad * kBodyPad; }

struct BodyLoops {
  // out[j] = Σ_i m[i ld + j] x[i] for from <= j < to: a combination of the `count` rows of m (ld
  // floats a row, ld >= bodyPadded(to), zero past its columns; `from` a multiple of kBodyPad),
  // each sum added in the order of i and the rows with x[i] = 0 skipped — the same bits on every
  // path and for any from and to. The outputs are held in registers, up to eight at a time.
  void (*combineRows)(const float* m, long ld, long count, const double* x, long from, long to,
                      double* out);
  // out[k] = Σ_j m[k ld + j] x[j], j < columns, for the `count` rows k = rows[0 … count): each a
  // sum of lanes added as a tree, then the columns past the last whole register — the same bits
  // for a row whichever rows come with it (on one path).
  void (*dotRows)(const float* m, long ld, const int* rows, long count, long columns,
                  const double* x, double* out);
  // Partial n of keys 0 … keys − 1 (sympathetic_strings.h (Y3), (Y4)): f −= c b; next = a1 b −
  // a2 prev − a3 c w into prev; lost += σ (next − prev)².
  void (*partialsRow)(long keys, const double* a1, const double* a2, const double* a3,
                      const double* c, const double* sigma, const double* b, const double* w,
                      double* prev, double* lost, double* f);
};

// The path of selectedKernels(), or that of a given path (tests compare them).
const BodyLoops& selectedBodyLoops();
const BodyLoops& bodyLoopsFor(Isa isa);

}  // namespace hamiltone
