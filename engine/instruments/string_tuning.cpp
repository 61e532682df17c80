// Bisection on the closed-form fundamental, alternated with the grid rule until both agree.
#include "instruments/string_tuning.h"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "util/format_number.h"

namespace hamiltone {

double schemePartial(const NonlinearString& string, double k, int m) {
  const double x = 0.5 * k * std::sqrt(string.transverseEigenvalue(m));
  if (x >= 1.0) return INFINITY;  // beyond the bound (44): no oscillation
  return std::asin(x) / (std::numbers::pi * k);
}

namespace {

// On u's grid alone: the fundamental does not depend on v's.
double fundamental(StringPhysics p, TuneBy by, double value, int segments, double k) {
  (by == TuneBy::tension ? p.tension : p.length) = value;
  return schemePartial(NonlinearString(p, segments), k, 1);
}

// The fundamental rises with T0 and falls with L: bisection in log space between bounds.
double solve(const StringPhysics& p, TuneBy by, int segments, double k, double target) {
  double lo, hi;
  if (by == TuneBy::tension) {
    lo = 1e-9 * p.young * p.area;
    hi = (1.0 - 1e-9) * p.young * p.area;  // V' >= 0 needs E A > T0
  } else {
    lo = 1e-4 * p.length;
    hi = 1e4 * p.length;
  }
  const bool rising = by == TuneBy::tension;
  auto below = [&](double x) { return (fundamental(p, by, x, segments, k) < target) == rising; };
  if (!below(lo) || below(hi))
    throw std::invalid_argument(std::string(by == TuneBy::tension ? "tension" : "length") +
                                ": no value puts the fundamental on " + formatNumber(target) +
                                " Hz with " + std::to_string(segments) +
                                " segments at k = " + formatApprox(k) + " s (the tension " +
                                "must stay below E*A = " + formatApprox(p.young * p.area) + " N)");
  for (int i = 0; i < 200 && hi / lo - 1.0 > 1e-15; ++i) {
    const double mid = std::sqrt(lo * hi);
    (below(mid) ? lo : hi) = mid;
  }
  return std::sqrt(lo * hi);
}

}  // namespace

TunedString tuneString(const StringPhysics& guess, TuneBy by, GridRule rule, double k,
                       double sigma1, double gridFactor, double targetHz, double tensionMargin) {
  if (!std::isfinite(targetHz) || targetHz <= 0.0 || targetHz >= 0.5 / k)
    throw std::invalid_argument("target pitch = " + formatNumber(targetHz) +
                                " Hz: must be between 0 and the Nyquist frequency " +
                                formatApprox(0.5 / k) + " Hz");
  auto grids = [&](const StringPhysics& p) {
    return stringGrid(p, rule, k, sigma1, gridFactor, tensionMargin);
  };
  TunedString tuned{guess, grids(guess)};
  for (int iteration = 0; iteration < 20; ++iteration) {
    double& value = by == TuneBy::tension ? tuned.physics.tension : tuned.physics.length;
    value = solve(tuned.physics, by, tuned.grid.transverse, k, targetHz);
    const StringGrid grid = grids(tuned.physics);
    if (grid == tuned.grid) return tuned;
    // A grid coarser than the one tuned on would leave the pitch off: retune on the new grid.
    // Alternating between two grids is settled by keeping the coarser (always stable) one.
    if (iteration >= 10 && grid.transverse > tuned.grid.transverse) return tuned;
    tuned.grid = grid;
  }
  throw std::invalid_argument("target pitch = " + formatNumber(targetHz) +
                              " Hz: the tuning and the grid rule did not settle");
}

}  // namespace hamiltone
