// The [M §3.3] string's potential, force and consistent-mass solve.
#include "problems/nonlinear_wave.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "util/format_number.h"

namespace hamiltone {

NonlinearWave::NonlinearWave(double alpha, int elements) : alpha_(alpha) {
  if (!std::isfinite(alpha) || alpha < 0.0 || alpha >= 1.0)
    throw std::invalid_argument("alpha = " + formatNumber(alpha) +
                                ": expected 0 <= alpha < 1 ([M §3.3]; at 1 the string is slack)");
  if (elements < 2 || elements > 1'000'000)
    throw std::invalid_argument("elements = " + std::to_string(elements) +
                                ": expected 2 to 1000000 (one interior node at least)");
  nodes_ = elements - 1;
  dx_ = 1.0 / elements;
  // T = Δx tridiag(1/6, 2/3, 1/6) = L D Lᵀ:  d_0 = a,  l_i = b / d_{i−1},  d_i = a − l_i b.
  const double a = dx_ * 2.0 / 3.0, b = dx_ / 6.0;
  lower_.setZero(nodes_);
  inverseDiag_.setZero(nodes_);
  double d = a;
  inverseDiag_[0] = 1.0 / d;
  for (int i = 1; i < nodes_; ++i) {
    lower_[i] = b / d;
    d = a - lower_[i] * b;
    inverseDiag_[i] = 1.0 / d;
  }
}

void NonlinearWave::applyInverseMass(const Vector& p, Vector& out) const noexcept {
  const int n = nodes_;
  for (int c = 0; c < 2; ++c) {
    double* x = out.data() + c * n;
    const double* r = p.data() + c * n;
    x[0] = r[0];  // L y = r
    for (int i = 1; i < n; ++i) x[i] = r[i] - lower_[i] * x[i - 1];
    for (int i = 0; i < n; ++i) x[i] *= inverseDiag_[i];                // D z = y
    for (int i = n - 2; i >= 0; --i) x[i] -= lower_[i + 1] * x[i + 1];  // Lᵀ x = z
  }
}

void NonlinearWave::applyMass(const Vector& v, Vector& out) const noexcept {
  const int n = nodes_;
  const double a = dx_ * 2.0 / 3.0, b = dx_ / 6.0;
  for (int c = 0; c < 2; ++c) {
    const double* x = v.data() + c * n;
    double* y = out.data() + c * n;
    for (int i = 0; i < n; ++i)
      y[i] = a * x[i] + b * ((i > 0 ? x[i - 1] : 0.0) + (i + 1 < n ? x[i + 1] : 0.0));
  }
}

double NonlinearWave::density(double u1, double u2, double alpha) {
  const double s = 1.0 + u1, r = std::hypot(s, u2);
  const double stretch = s > 0.0 ? u2 * u2 / (r + s) : r - s;  // r − (1 + u1), cancellation-free
  return 0.5 * (u1 * u1 + u2 * u2) - alpha * stretch;
}

// ∂V/∂u1 = u1 − α ((1 + u1)/r − 1) = u1 + α u2² / (r (r + 1 + u1)),  ∂V/∂u2 = u2 (1 − α / r).
void NonlinearWave::densityGradient(double u1, double u2, double alpha, double& g1, double& g2) {
  const double s = 1.0 + u1, r = std::hypot(s, u2);
  g1 = s > 0.0 ? u1 + alpha * u2 * u2 / (r * (r + s)) : u1 - alpha * (s / r - 1.0);
  g2 = u2 * (1.0 - alpha / r);
}

// Element e joins nodes e and e + 1 (nodes 0 and N + 1 are the fixed ends): strain
// (u_{e+1} − u_e)/Δx, energy Δx V(strain).
double NonlinearWave::potential(const Vector& q) const noexcept {
  const int n = nodes_;
  const double* u1 = q.data();
  const double* u2 = q.data() + n;
  double v = 0.0;
  for (int e = 0; e <= n; ++e) {
    const double a = ((e < n ? u1[e] : 0.0) - (e > 0 ? u1[e - 1] : 0.0)) / dx_;
    const double b = ((e < n ? u2[e] : 0.0) - (e > 0 ? u2[e - 1] : 0.0)) / dx_;
    v += density(a, b, alpha_);
  }
  return dx_ * v;
}

// ∂/∂u_j Σ_e Δx V(strain_e) = ∇V(strain_{j−1}) − ∇V(strain_j): the Δx cancels the 1/Δx.
double NonlinearWave::gradient(const Vector& q, Vector& grad) const noexcept {
  const int n = nodes_;
  const double* u1 = q.data();
  const double* u2 = q.data() + n;
  double* g1 = grad.data();
  double* g2 = grad.data() + n;
  double v = 0.0;
  for (int e = 0; e <= n; ++e) {
    const double a = ((e < n ? u1[e] : 0.0) - (e > 0 ? u1[e - 1] : 0.0)) / dx_;
    const double b = ((e < n ? u2[e] : 0.0) - (e > 0 ? u2[e - 1] : 0.0)) / dx_;
    v += density(a, b, alpha_);
    double d1 = 0.0, d2 = 0.0;
    densityGradient(a, b, alpha_, d1, d2);
    if (e > 0) {  // node e − 1 (0-based) is the element's left end
      g1[e - 1] -= d1;
      g2[e - 1] -= d2;
    }
    if (e < n) {  // node e is its right end: first touch, so assign
      g1[e] = d1;
      g2[e] = d2;
    }
  }
  return dx_ * v;
}

double NonlinearWave::displacement(const Vector& q, int component, double x) const {
  const double position = x / dx_;
  const int left = std::min(static_cast<int>(std::floor(position)), nodes_);
  const double theta = position - left;
  // interior node j (1-based) is q[component·N + j − 1]; nodes 0 and N + 1 are zero
  auto at = [&](int j) { return j >= 1 && j <= nodes_ ? q[component * nodes_ + j - 1] : 0.0; };
  return (1.0 - theta) * at(left) + theta * at(left + 1);
}

InitialState nonlinearWaveInitialState(const NonlinearWave& wave, double amplitude) {
  const int n = wave.nodes();
  InitialState start{Vector::Zero(2 * n), Vector::Zero(2 * n)};
  for (int j = 1; j <= n; ++j) {
    const double u = amplitude * std::sin(std::numbers::pi * j * wave.dx());
    start.q[j - 1] = u;
    start.q[n + j - 1] = u;
  }
  return start;
}

}  // namespace hamiltone
