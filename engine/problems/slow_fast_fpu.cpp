// The slow/fast FPU chain's three potentials V_F, V_M, V_S and their gradients, [M §4.3.1].
#include "problems/slow_fast_fpu.h"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "util/format_number.h"

namespace hamiltone {

namespace {

double fourth(double e) { return (e * e) * (e * e); }

}  // namespace

SlowFastFermiPastaUlam::SlowFastFermiPastaUlam(int pairs, double omega)
    : pairs_(pairs), omega_(omega) {
  if (pairs < 1)
    throw std::invalid_argument("pairs = " + std::to_string(pairs) + ": must be an integer >= 1");
  if (!std::isfinite(omega) || omega <= 0.0)
    throw std::invalid_argument("omega = " + formatNumber(omega) + ": must be a finite number > 0");
  inverseMass_.setOnes(2 * static_cast<Eigen::Index>(pairs));
  for (Eigen::Index j = 0; j < 2 * pairs; ++j) {
    if (j < pairs - 1)
      fast_.push_back(j);
    else if (j == pairs - 1)
      mixed_.push_back(j);
    else
      slow_.push_back(j);
  }
  coupled_.push_back(pairs);  // q_{m+1}
}

double SlowFastFermiPastaUlam::at(const Vector& q, int i) const {
  return (i == 0 || i == 2 * pairs_ + 1) ? 0.0 : q[i - 1];
}

double SlowFastFermiPastaUlam::fastPotential(const Vector& q) const {
  double v = 0.0;
  for (int i = 1; i <= pairs_; ++i) {
    const double e = at(q, i) - at(q, i - 1);
    v += e * e;
  }
  return 0.25 * omega_ * omega_ * v;
}

double SlowFastFermiPastaUlam::mixedPotential(const Vector& q) const {
  return fourth(q[pairs_] - q[pairs_ - 1]);
}

double SlowFastFermiPastaUlam::slowPotential(const Vector& q) const {
  double v = 0.0;
  for (int i = pairs_ + 1; i <= 2 * pairs_; ++i) v += fourth(at(q, i + 1) - at(q, i));
  return v;
}

// Spring i (q_i − q_{i−1}) pulls q_i by −κ e and q_{i−1} by +κ e, κ = ω²/2: x[i−1] and x[i−2].
void SlowFastFermiPastaUlam::addFastGradient(const Vector& q, double w, Vector& out) const {
  const double c = 0.5 * omega_ * omega_ * w;
  for (int i = 1; i <= pairs_; ++i) {
    const double f = c * (at(q, i) - at(q, i - 1));
    out[i - 1] += f;
    if (i > 1) out[i - 2] -= f;
  }
}

void SlowFastFermiPastaUlam::addMixedGradient(const Vector& q, double w, Vector& out) const {
  const double e = q[pairs_] - q[pairs_ - 1];
  const double f = 4.0 * w * e * e * e;
  out[pairs_] += f;
  out[pairs_ - 1] -= f;
}

// Quartic spring i (q_{i+1} − q_i), i = m+1 … 2m: x[i] and x[i−1], the wall past q_{2m}.
void SlowFastFermiPastaUlam::addSlowGradient(const Vector& q, double w, Vector& out) const {
  for (int i = pairs_ + 1; i <= 2 * pairs_; ++i) {
    const double e = at(q, i + 1) - at(q, i);
    const double f = 4.0 * w * e * e * e;
    if (i < 2 * pairs_) out[i] += f;
    out[i - 1] -= f;
  }
}

double SlowFastFermiPastaUlam::fastEigenvalueMax() const {
  // κ = ω²/2 times the m×m stiffness of wall–q_1–…–q_m with q_m free on the right (the quartic
  // spring has no linear stiffness at rest): tridiag(−1, 2, −1) with a last diagonal entry 1.
  // v_i = sin(iθ) (v_0 = 0 at the wall) solves the rows i < m with λ = 2 − 2cos θ = 4 sin²(θ/2);
  // the last row −v_{m−1} + v_m = λ v_m is that same row with a ghost v_{m+1} = v_m, so
  // sin((m+1)θ) = sin(mθ): θ_j = (2j − 1)π/(2m + 1), j = 1 … m, and
  // λ_j = 4 sin²((2j − 1)π/(2(2m + 1))), the largest at j = m. O(1), no dense solve.
  const double m = static_cast<double>(pairs_);
  const double s = std::sin((2.0 * m - 1.0) * std::numbers::pi / (2.0 * (2.0 * m + 1.0)));
  return 0.5 * omega_ * omega_ * 4.0 * s * s;
}

double SlowFastFermiPastaUlam::potential(const Vector& q) const {
  double linear = 0.0, quartic = 0.0;
  for (int i = 1; i <= pairs_; ++i) linear += std::pow(at(q, i) - at(q, i - 1), 2);
  for (int i = pairs_; i <= 2 * pairs_; ++i) quartic += std::pow(at(q, i + 1) - at(q, i), 4);
  return omega_ * omega_ / 4.0 * linear + quartic;
}

InitialState slowFastInitialState(const SlowFastFermiPastaUlam& chain, double alpha) {
  if (!std::isfinite(alpha))
    throw std::invalid_argument("alpha = " + formatNumber(alpha) + ": must be a finite number");
  InitialState s{Vector::Zero(chain.size()), Vector::Zero(chain.size())};
  s.q[chain.pairs()] = alpha;
  return s;
}

}  // namespace hamiltone
