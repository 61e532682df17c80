// How many grid segments fit a length at a spacing — shared by the string and the plate grids.
#pragma once

#include <cmath>
#include <stdexcept>
#include <string>

#include "util/format_number.h"

namespace hamiltone {

// floor(length / h), refused below 2 or above `maximum` with a message naming `what` (the
// length's parameter) and `rule` (where h came from); `refinable`: h is above its bound (a grid
// factor over 1), which a smaller factor brings closer.
inline int segmentsAlong(double length, double h, double k, double maximum, const std::string& what,
                         const std::string& rule, bool refinable) {
  if (!(h > 0.0) || !std::isfinite(h))
    throw std::invalid_argument(
        what + " = " + formatNumber(length) + " m: the grid spacing h (" + rule +
        ") at k = " + formatApprox(k) + " s is " + formatApprox(h) +
        ": a material parameter or the step is beyond what double precision holds; expected "
        "values of physical size");
  const double segments = std::floor(length / h);
  if (!(segments >= 2.0))
    throw std::invalid_argument(
        what + " = " + formatNumber(length) + " m: shorter than two grid spacings h = " +
        formatApprox(h) + " m at k = " + formatApprox(k) + " s (" + rule +
        "); use a smaller time step (a higher sample rate, or scheme.oversampling)" +
        (refinable ? " or a smaller grid factor" : ""));
  if (segments > maximum)
    throw std::invalid_argument("the grid would have " + formatApprox(segments) +
                                " segments along " + what + "; expected at most " +
                                formatNumber(maximum) + " (use a larger time step)");
  return static_cast<int>(segments);
}

}  // namespace hamiltone
