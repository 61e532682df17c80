// Checks several tests make: random states, gradients against finite differences, and the loss
// balance (50) over a run.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "schemes/hamiltonian.h"

namespace hamiltone::testing {

inline Vector randomVector(Eigen::Index n, double scale, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-scale, scale);
  Vector q(n);
  for (auto& x : q) x = u(rng);
  return q;
}

// Each entry of `grad` (the gradient at q) against the central difference of `potential` with
// step delta(j), to `relative` of the entry — plus `floor`, the roundoff of a difference of
// potentials, for entries near zero.
template <class Potential, class Delta>
void expectGradientIsDerivative(Potential potential, const Vector& grad, Vector q, Delta delta,
                                double relative, double floor) {
  for (Eigen::Index j = 0; j < q.size(); ++j) {
    const double d = delta(j), saved = q[j];
    q[j] = saved + d;
    const double up = potential(q);
    q[j] = saved - d;
    const double down = potential(q);
    q[j] = saved;
    EXPECT_NEAR(grad[j], (up - down) / (2.0 * d), relative * std::abs(grad[j]) + floor)
        << "coordinate " << j;
  }
}

// Least-squares slope of y against x: a convergence order, or a decay rate.
inline double leastSquaresSlope(const std::vector<double>& x, const std::vector<double>& y) {
  const double n = static_cast<double>(x.size());
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    sx += x[i];
    sy += y[i];
    sxx += x[i] * x[i];
    sxy += x[i] * y[i];
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

struct Balance {
  double initial = 0.0;        // H at the start
  double final = 0.0;          // H at the end
  double worstIncrease = 0.0;  // largest step-to-step rise of H, relative to the start
  double worstBalance = 0.0;   // largest |H + dissipated − H(0)|, relative to the start
};

// Steps a lossy scheme and measures how (50) holds.
template <class Scheme>
Balance runBalance(Scheme& scheme, long steps) {
  Balance b;
  b.initial = b.final = scheme.energy().total();
  for (long n = 0; n < steps; ++n) {
    scheme.step();
    const double h = scheme.energy().total();
    b.worstIncrease = std::max(b.worstIncrease, (h - b.final) / b.initial);
    b.worstBalance =
        std::max(b.worstBalance, std::abs(h + scheme.dissipated() - b.initial) / b.initial);
    b.final = h;
  }
  return b;
}

}  // namespace hamiltone::testing
