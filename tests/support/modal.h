// Measuring a simulated string: modal amplitudes and frequencies from zero crossings.
#pragma once

#include <cmath>
#include <numbers>
#include <vector>

#include "schemes/hamiltonian.h"

namespace hamiltone::testing {

// Projection of u (the first segments − 1 coordinates) onto sin(mπx/L), an exact eigenvector of
// the string's K with simply supported ends.
inline double modalAmplitude(const Vector& q, int segments, int m) {
  double s = 0.0;
  for (int j = 1; j < segments; ++j) s += q[j - 1] * std::sin(m * std::numbers::pi * j / segments);
  return 2.0 * s / segments;
}

// u_m(x) = a sin(mπx/L) at the grid points.
inline Vector modeShape(Eigen::Index size, int segments, int m, double a) {
  Vector q = Vector::Zero(size);
  for (int j = 1; j < segments; ++j) q[j - 1] = a * std::sin(m * std::numbers::pi * j / segments);
  return q;
}

// Frequency of a sampled oscillation from its first and last upward zero crossings, each placed by
// linear interpolation: the count of whole periods between them over the time they span.
inline double zeroCrossingFrequency(const std::vector<double>& x, double dt) {
  double first = NAN, last = NAN;
  int crossings = 0;
  for (size_t n = 1; n < x.size(); ++n) {
    if (x[n - 1] < 0.0 && x[n] >= 0.0) {
      const double t = dt * (static_cast<double>(n - 1) + x[n - 1] / (x[n - 1] - x[n]));
      if (crossings++ == 0) first = t;
      last = t;
    }
  }
  return (crossings - 1) / (last - first);
}

inline double cents(double f, double reference) { return 1200.0 * std::log2(f / reference); }

}  // namespace hamiltone::testing
