// The FPU chain's split potential (53) and its gradient, on 0-based storage x[j] = q_{j+1}.
#include "problems/fpu.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "util/format_number.h"

namespace hamiltone {

FermiPastaUlam::FermiPastaUlam(int pairs, double omega) : pairs_(pairs), omega_(omega) {
  if (pairs < 1)
    throw std::invalid_argument("pairs = " + std::to_string(pairs) + ": must be an integer >= 1");
  if (!std::isfinite(omega) || omega <= 0.0)
    throw std::invalid_argument("omega = " + formatNumber(omega) + ": must be a finite number > 0");
  inverseMass_.setOnes(2 * static_cast<Eigen::Index>(pairs));
}

void FermiPastaUlam::applyStiffness(const Vector& q, Vector& out) const {
  const double c = 0.5 * omega_ * omega_;
  for (Eigen::Index m = 0; m < pairs_; ++m) {
    const double d = c * (q[2 * m] - q[2 * m + 1]);
    out[2 * m] = d;
    out[2 * m + 1] = -d;
  }
}

// Quartic spring i joins q_{2i} and q_{2i+1}: x[2i−1] and x[2i], with the walls at both ends.
double FermiPastaUlam::splitPotential(const Vector& q) const {
  const Eigen::Index n = size();
  double v = q[0] * q[0] * q[0] * q[0] + q[n - 1] * q[n - 1] * q[n - 1] * q[n - 1];
  for (Eigen::Index j = 2; j < n; j += 2) {
    const double e = q[j] - q[j - 1];
    v += (e * e) * (e * e);
  }
  return v;
}

double FermiPastaUlam::splitGradient(const Vector& q, Vector& grad) const {
  const Eigen::Index n = size();
  const double first = q[0], last = -q[n - 1];
  grad[0] = 4.0 * first * first * first;
  grad[n - 1] = -4.0 * last * last * last;
  double v = first * first * first * first + last * last * last * last;
  for (Eigen::Index j = 2; j < n; j += 2) {
    const double e = q[j] - q[j - 1];
    const double f = 4.0 * e * e * e;
    grad[j] = f;
    grad[j - 1] = -f;
    v += (e * e) * (e * e);
  }
  return v;
}

double FermiPastaUlam::potential(const Vector& q) const {
  // (52) with the 1-based q_i of the paper: q(i) = q_i, q(0) = q(2M+1) = 0.
  const int m = pairs_;
  auto at = [&](int i) { return (i == 0 || i == 2 * m + 1) ? 0.0 : q[i - 1]; };
  double linear = 0.0, quartic = 0.0;
  for (int i = 1; i <= m; ++i) linear += std::pow(at(2 * i) - at(2 * i - 1), 2);
  for (int i = 0; i <= m; ++i) quartic += std::pow(at(2 * i + 1) - at(2 * i), 4);
  return omega_ * omega_ / 4.0 * linear + quartic;
}

InitialState fpuInitialState(const FermiPastaUlam& chain, double alpha) {
  if (chain.size() < 4)
    throw std::invalid_argument(
        "pairs = " + std::to_string(chain.pairs()) +
        ": the initial condition displaces coordinate 4, so pairs must be >= 2");
  if (!std::isfinite(alpha))
    throw std::invalid_argument("alpha = " + formatNumber(alpha) + ": must be a finite number");
  InitialState s{Vector::Zero(chain.size()), Vector::Zero(chain.size())};
  s.q[3] = alpha;
  return s;
}

}  // namespace hamiltone
