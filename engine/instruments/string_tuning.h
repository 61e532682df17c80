// Exact tuning of the simulated string: the linear scheme's partials in closed form (SCHEMES §3),
// and the tension (or length) that puts the simulated fundamental on a target pitch.
#pragma once

#include "instruments/string.h"

namespace hamiltone {

// f_m = (1/πk) arcsin(k sqrt(λ_m)/2), λ_m the m-th transverse eigenvalue of M⁻¹K: the frequency of
// mode m of Störmer–Verlet — and of (38) at small amplitude, where V' has no quadratic term in u.
double schemePartial(const NonlinearString& string, double k, int m);

enum class TuneBy { tension, length };

struct TunedString {
  StringPhysics physics;  // with the solved tension or length
  StringGrid grid;        // the grids of `rule` at the solved values
};

// Solves T0 (or L) so that schemePartial(…, 1) = targetHz on the grids `rule` gives for it
// (stringGrid(), with `tensionMargin` for the two grids); the grids depend on the solution, so
// the two are iterated to a fixed point. The fundamental depends on u's grid alone (V' has no
// quadratic term in u). Throws std::invalid_argument naming the note's parameter when no solution
// keeps E A > T0, the bound (44) and two segments.
TunedString tuneString(const StringPhysics& guess, TuneBy by, GridRule rule, double k,
                       double sigma1, double gridFactor, double targetHz,
                       double tensionMargin = 1.0);

}  // namespace hamiltone
