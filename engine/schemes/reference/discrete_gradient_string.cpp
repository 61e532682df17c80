// The string's discrete-gradient scheme (67)–(68): residual, banded Jacobian, Newton–Raphson.
#include "schemes/reference/discrete_gradient_string.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "util/format_number.h"

namespace hamiltone {

namespace {

// s = sqrt((1 + η)² + ζ²) and s − 1 = (2η + η² + ζ²)/(s + 1), free of cancellation at small strain.
struct Stretch {
  double s, excess;
};
inline Stretch stretch(double zeta, double eta) {
  const double s = std::sqrt((1.0 + eta) * (1.0 + eta) + zeta * zeta);
  return {s, (2.0 * eta + eta * eta + zeta * zeta) / (s + 1.0)};
}

// One segment's discrete gradient (68) of 𝒱' = c/2 (s − 1)², c = EA − T0, and its derivative in
// the new strain. With s1 − s0 = (ζ1 − ζ0)(ζ1 + ζ0)/(s1 + s0) the quotient needs no division by
// ζ1 − ζ0: g_ζ = c/2 (ζ1 + ζ0)(e1 + e0)/(s1 + s0), e = s − 1; likewise in η, with 2 + η1 + η0.
struct Quotient {
  double g, dg;
};
inline Quotient zetaQuotient(double c, double z1, double z0, double eta) {
  const Stretch a = stretch(z1, eta), b = stretch(z0, eta);
  const double sum = a.s + b.s, e = a.excess + b.excess;
  return {0.5 * c * (z1 + z0) * e / sum,
          0.5 * c * (e / sum + 2.0 * (z1 + z0) * z1 / (a.s * sum * sum))};
}
inline Quotient etaQuotient(double c, double e1, double e0, double zeta) {
  const Stretch a = stretch(zeta, e1), b = stretch(zeta, e0);
  const double sum = a.s + b.s, e = a.excess + b.excess;
  return {0.5 * c * (2.0 + e1 + e0) * e / sum,
          0.5 * c * (e / sum + 2.0 * (2.0 + e1 + e0) * (1.0 + e1) / (a.s * sum * sum))};
}

// ζ_l = D₋a on segment l = 0 … M−1 of the M−1 interior values a (zero at both ends).
inline double strain(const double* a, Eigen::Index l, Eigen::Index m, double invH) {
  return ((l < m - 1 ? a[l] : 0.0) - (l > 0 ? a[l - 1] : 0.0)) * invH;
}

}  // namespace

DiscreteGradientString::DiscreteGradientString(const NonlinearString& string, double k,
                                               const InitialState& start)
    : string_(string), k_(k) {
  if (!std::isfinite(k) || k <= 0.0)
    throw std::invalid_argument("k = " + formatNumber(k) + ": must be a finite number > 0");
  if (string_.grid().longitudinal != string_.segments())
    throw std::invalid_argument("the discrete-gradient reference (67) is for the single grid of "
                                "(65): u and v on the same segments");
  const Eigen::Index n = string_.size();
  if (start.q.size() != n || start.p.size() != n)
    throw std::invalid_argument("initial state of size " + std::to_string(start.q.size()) +
                                ": the string has " + std::to_string(n) + " coordinates");
  for (Vector* v : {&prev_, &curr_, &next_, &residual_, &work_}) v->setZero(n);
  weights_.setZero(2 * string_.segments());

  // K column by column, five at a time: it is block diagonal with half-bandwidth <= 2, so probes
  // five apart never share a row.
  std::vector<Eigen::Triplet<double>> entries;
  const Eigen::Index half = n / 2;
  for (Eigen::Index colour = 0; colour < 5; ++colour) {
    next_.setZero();
    for (Eigen::Index j = colour; j < n; j += 5) next_[j] = 1.0;
    string_.applyStiffness(next_, work_);
    for (Eigen::Index j = colour; j < n; j += 5) {
      const Eigen::Index lo = j < half ? 0 : half, hi = j < half ? half : n;
      for (Eigen::Index i = std::max(lo, j - 2); i < std::min(hi, j + 3); ++i)
        if (work_[i] != 0.0) entries.emplace_back(i, j, work_[i]);
    }
  }
  stiffness_.resize(n, n);
  stiffness_.setFromTriplets(entries.begin(), entries.end());

  // (21): q^1 = q^0 + k M⁻¹p − k²/2 M⁻¹∇V(q^0).
  const Vector& minv = string_.inverseMass();
  prev_ = start.q;
  fullGradient(string_, prev_, residual_, work_);
  curr_ = prev_ + k * minv.cwiseProduct(start.p) - 0.5 * k * k * minv.cwiseProduct(residual_);
}

void DiscreteGradientString::residual(const Vector& x, const Vector& qn, const Vector& qm) {
  const Eigen::Index m = string_.segments();
  const double invH = 1.0 / string_.spacing();
  const StringPhysics& p = string_.physics();
  const double c = p.young * p.area - p.tension;
  const double mass = p.linearDensity() * string_.spacing() / (k_ * k_);
  work_ = x + qm;
  residual_ = mass * (x - 2.0 * qn + qm) + 0.5 * (stiffness_ * work_);  // (67), linear part
  const double *u1 = x.data(), *u0 = qm.data(), *un = qn.data();
  const double *v1 = u1 + (m - 1), *v0 = u0 + (m - 1), *vn = un + (m - 1);
  double* ru = residual_.data();
  double* rv = ru + (m - 1);
  for (Eigen::Index l = 0; l < m; ++l) {
    // (68): g_ζ at η^n, g_η at ζ^n. h D₋ᵀw adds w_l to node l and subtracts it from node l − 1.
    const Quotient gz =
        zetaQuotient(c, strain(u1, l, m, invH), strain(u0, l, m, invH), strain(vn, l, m, invH));
    const Quotient ge =
        etaQuotient(c, strain(v1, l, m, invH), strain(v0, l, m, invH), strain(un, l, m, invH));
    if (l < m - 1) {
      ru[l] += gz.g;
      rv[l] += ge.g;
    }
    if (l > 0) {
      ru[l - 1] -= gz.g;
      rv[l - 1] -= ge.g;
    }
    weights_[l] = gz.dg * invH;
    weights_[m + l] = ge.dg * invH;
  }
}

// ρAh/k² I + K/2 + h D₋ᵀ diag(∂g/∂ζ¹) D₋ on u (and the same in η on v): the nonlinear part is
// (a_l + a_{l+1})/h on the diagonal and −a_{l+1}/h beside it.
void DiscreteGradientString::assembleJacobian() {
  const Eigen::Index m = string_.segments();
  const double mass = string_.physics().linearDensity() * string_.spacing() / (k_ * k_);
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<std::size_t>(stiffness_.nonZeros()) + 6 * m);
  for (Eigen::Index j = 0; j < stiffness_.outerSize(); ++j)
    for (Eigen::SparseMatrix<double>::InnerIterator it(stiffness_, j); it; ++it)
      entries.emplace_back(it.row(), it.col(), 0.5 * it.value());
  for (Eigen::Index block : {Eigen::Index{0}, Eigen::Index{1}}) {
    const Eigen::Index offset = block * (m - 1);
    const double* a = weights_.data() + block * m;
    for (Eigen::Index j = 0; j < m - 1; ++j) {
      entries.emplace_back(offset + j, offset + j, mass + a[j] + a[j + 1]);
      if (j + 1 < m - 1) {
        entries.emplace_back(offset + j, offset + j + 1, -a[j + 1]);
        entries.emplace_back(offset + j + 1, offset + j, -a[j + 1]);
      }
    }
  }
  jacobian_.resize(2 * (m - 1), 2 * (m - 1));
  jacobian_.setFromTriplets(entries.begin(), entries.end());
}

void DiscreteGradientString::step() {
  next_ = 2.0 * curr_ - prev_;  // the linear extrapolation starts Newton
  const double scale = std::max(next_.lpNorm<Eigen::Infinity>(), curr_.lpNorm<Eigen::Infinity>());
  for (int iteration = 1;; ++iteration) {
    if (iteration > maxIterations || !next_.allFinite())
      throw std::runtime_error("discrete-gradient string (67): Newton did not converge in " +
                               std::to_string(maxIterations) + " iterations at step " +
                               std::to_string(n_ + 1));
    residual(next_, curr_, prev_);
    assembleJacobian();
    solver_.compute(jacobian_);
    if (solver_.info() != Eigen::Success)
      throw std::runtime_error("discrete-gradient string (67): singular Jacobian at step " +
                               std::to_string(n_ + 1));
    const Vector update = solver_.solve(residual_);
    next_ -= update;
    if (update.lpNorm<Eigen::Infinity>() <=
        tolerance * std::max(scale, next_.lpNorm<Eigen::Infinity>())) {
      lastIterations_ = iteration;
      break;
    }
  }
  maxIterationsUsed_ = std::max(maxIterationsUsed_, lastIterations_);
  totalIterations_ += lastIterations_;
  prev_.swap(curr_);
  curr_.swap(next_);
  ++n_;
}

Energy DiscreteGradientString::energy() const {
  const Eigen::Index m = string_.segments();
  const double invH = 1.0 / string_.spacing();
  const StringPhysics& p = string_.physics();
  const double c = p.young * p.area - p.tension;
  const double *u0 = prev_.data(), *u1 = curr_.data();
  const double *v0 = u0 + (m - 1), *v1 = u1 + (m - 1);
  double sum = 0.0;
  for (Eigen::Index l = 0; l < m; ++l) {
    const double z0 = strain(u0, l, m, invH), z1 = strain(u1, l, m, invH);
    const double e0 = strain(v0, l, m, invH), e1 = strain(v1, l, m, invH);
    const double a = stretch(z1, e0).excess, b = stretch(z0, e1).excess;
    sum += a * a + b * b;
  }
  Energy e;
  e.kinetic = intervalKineticEnergy(string_.inverseMass(), prev_, curr_, k_);
  e.potential = 0.25 * (curr_.dot(stiffness_ * curr_) + prev_.dot(stiffness_ * prev_)) +
                0.5 * string_.spacing() * 0.5 * c * sum;
  return e;
}

}  // namespace hamiltone
