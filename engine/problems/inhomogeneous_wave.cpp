// The inhomogeneous wave's springs, partition, initial data and exact solution, [M §4.3.2].
#include "problems/inhomogeneous_wave.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "util/format_number.h"

namespace hamiltone {

InhomogeneousWave::InhomogeneousWave(double dx) : dx_(dx) {
  const double n = std::round(1.0 / dx);
  if (!std::isfinite(dx) || dx <= 0.0 || n < 4.0 || n > 1e8 || std::abs(n * dx - 1.0) > 1e-9 ||
      std::fmod(n, 2.0) != 0.0)
    throw std::invalid_argument("dx = " + formatNumber(dx) +
                                ": 1/dx must be an even integer >= 4 (the interface x = 0.5 is a "
                                "node), e.g. 5e-4, 1e-3, 4e-3");
  intervals_ = static_cast<int>(n);
  fastStiffness_ = kFastSpeed * kFastSpeed / (dx * dx);
  slowStiffness_ = kSlowSpeed * kSlowSpeed / (dx * dx);
  inverseMass_.setOnes(intervals_ - 1);
  const int half = intervals_ / 2;  // node N/2 is at x = 0.5
  for (int i = 1; i < intervals_; ++i) {
    if (i < half)
      fast_.push_back(i - 1);
    else if (i == half)
      mixed_.push_back(i - 1);
    else
      slow_.push_back(i - 1);
  }
  coupled_.push_back(half);  // node N/2 + 1
}

// Springs s = first … last, node i stored at i − 1, the walls i = 0, N fixed at 0.
double InhomogeneousWave::potential(int first, int last, double stiffness, const Vector& q) const {
  double v = 0.0;
  for (int s = first; s <= last; ++s) {
    const double right = s == intervals_ ? 0.0 : q[s - 1];
    const double left = s == 1 ? 0.0 : q[s - 2];
    v += (right - left) * (right - left);
  }
  return 0.5 * stiffness * v;
}

void InhomogeneousWave::addGradient(int first, int last, double stiffness, const Vector& q,
                                    double w, Vector& out) const {
  const double c = stiffness * w;
  for (int s = first; s <= last; ++s) {
    const double right = s == intervals_ ? 0.0 : q[s - 1];
    const double left = s == 1 ? 0.0 : q[s - 2];
    const double f = c * (right - left);
    if (s < intervals_) out[s - 1] += f;
    if (s > 1) out[s - 2] -= f;
  }
}

double InhomogeneousWave::fastPotential(const Vector& q) const {
  return potential(1, intervals_ / 2, fastStiffness_, q);
}
double InhomogeneousWave::mixedPotential(const Vector& q) const {
  return potential(intervals_ / 2 + 1, intervals_ / 2 + 1, slowStiffness_, q);
}
double InhomogeneousWave::slowPotential(const Vector& q) const {
  return potential(intervals_ / 2 + 2, intervals_, slowStiffness_, q);
}
void InhomogeneousWave::addFastGradient(const Vector& q, double w, Vector& out) const {
  addGradient(1, intervals_ / 2, fastStiffness_, q, w, out);
}
void InhomogeneousWave::addMixedGradient(const Vector& q, double w, Vector& out) const {
  addGradient(intervals_ / 2 + 1, intervals_ / 2 + 1, slowStiffness_, q, w, out);
}
void InhomogeneousWave::addSlowGradient(const Vector& q, double w, Vector& out) const {
  addGradient(intervals_ / 2 + 2, intervals_, slowStiffness_, q, w, out);
}

namespace {

double gaussian(double x) {
  const double a = 20.0 * (x - 0.2);
  return std::exp(-a * a);
}

// The speed β of v⁰ = −β u⁰'.
double velocityScale(WaveStart start) {
  return start == WaveStart::paper ? 1.0 : InhomogeneousWave::kFastSpeed;
}

}  // namespace

double waveInitialDisplacement(double x) { return (x > 0.0 && x < 0.5) ? 1e-2 * gaussian(x) : 0.0; }

double waveInitialVelocity(double x, WaveStart start) {
  // −u⁰'(x) = 8 (x − 0.2) e^{−(20(x−0.2))²} on (0, 0.5)
  return (x > 0.0 && x < 0.5) ? velocityScale(start) * 8.0 * (x - 0.2) * gaussian(x) : 0.0;
}

InitialState waveInitialState(const InhomogeneousWave& wave, WaveStart start) {
  InitialState s{Vector::Zero(wave.size()), Vector::Zero(wave.size())};
  for (Eigen::Index j = 0; j < wave.size(); ++j) {
    s.q[j] = waveInitialDisplacement(wave.position(j));
    s.p[j] = waveInitialVelocity(wave.position(j), start);
  }
  return s;
}

double waveExactDisplacement(double x, double t, WaveStart start) {
  constexpr double c1 = InhomogeneousWave::kFastSpeed, c2 = InhomogeneousWave::kSlowSpeed;
  const double beta = velocityScale(start);
  const double a = 0.5 * (1.0 + beta / c1), b = 0.5 * (1.0 - beta / c1);
  // P(ξ) = F(ξ) − G(−ξ), supported in (−0.5, 0.5).
  auto profile = [&](double xi) {
    return a * waveInitialDisplacement(xi) - b * waveInitialDisplacement(-xi);
  };
  const double r = (c2 - c1) / (c1 + c2);
  // Past k = c₁t + 1 every argument is >= 0.5, outside the support.
  const int last = static_cast<int>(std::ceil(c1 * t)) + 1;
  double u = 0.0, rk = 1.0;
  for (int k = 0; k <= last && std::abs(rk) >= 1e-300; ++k, rk *= r) {
    if (x < 0.5)
      u += rk * (profile(x + k - c1 * t) - profile(k - x - c1 * t));
    else
      u += rk * profile(c1 / c2 * (x - 0.5) + k + 0.5 - c1 * t);
  }
  return x < 0.5 ? u : 2.0 * c1 / (c1 + c2) * u;
}

}  // namespace hamiltone
