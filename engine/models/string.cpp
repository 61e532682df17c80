// The string's stiffness stencils and its split potential (65) with the gradient by the chain rule.
#include "models/string.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "models/grid.h"
#include "util/format_number.h"

namespace hamiltone {

namespace {

void requirePositive(const char* name, double value, const char* unit) {
  if (!std::isfinite(value) || value <= 0.0)
    throw std::invalid_argument(std::string(name) + " = " + formatNumber(value) +
                                ": must be a finite number > 0 (" + unit + ")");
}

// out_j = c (a_{j−1} − 2 a_j + a_{j+1}) / h² on j = 0 … n−1, a = 0 beyond both ends: c D2 a.
void secondDifference(const double* a, double* out, Eigen::Index n, double c) {
  if (n == 1) {
    out[0] = -2.0 * c * a[0];
    return;
  }
  out[0] = c * (a[1] - 2.0 * a[0]);
  for (Eigen::Index j = 1; j + 1 < n; ++j) out[j] = c * (a[j - 1] - 2.0 * a[j] + a[j + 1]);
  out[n - 1] = c * (a[n - 2] - 2.0 * a[n - 1]);
}

}  // namespace

NonlinearString::NonlinearString(const StringPhysics& p, int segments)
    : physics_(p), segments_(segments) {
  requirePositive("density", p.density, "kg/m^3");
  requirePositive("area", p.area, "m^2");
  requirePositive("length", p.length, "m");
  requirePositive("young", p.young, "Pa");
  requirePositive("tension", p.tension, "N");
  if (!std::isfinite(p.inertia) || p.inertia < 0.0)
    throw std::invalid_argument("inertia = " + formatNumber(p.inertia) +
                                ": must be a finite number >= 0 (m^4)");
  if (p.young * p.area <= p.tension)
    throw std::invalid_argument("tension = " + formatNumber(p.tension) +
                                " N: must be below E*A = " + formatNumber(p.young * p.area) +
                                " N, or the split potential (65) is not >= 0");
  if (segments < 2)
    throw std::invalid_argument("segments = " + std::to_string(segments) + ": must be >= 2");
  h_ = p.length / segments;
  const Eigen::Index n = 2 * static_cast<Eigen::Index>(segments - 1);
  inverseMass_ = Vector::Constant(n, 1.0 / (p.linearDensity() * h_));
  work1_.setZero(segments);
  work2_.setZero(segments);
}

void NonlinearString::applyStiffness(const Vector& q, Vector& out) const {
  const Eigen::Index n = segments_ - 1;
  const double invH2 = 1.0 / (h_ * h_);
  secondDifference(q.data() + n, out.data() + n, n, -physics_.tension * h_ * invH2);  // −T0 h D2 v
  const double t = tensionScale_ * physics_.tension * h_;
  if (physics_.inertia == 0.0) {
    secondDifference(q.data(), out.data(), n, -t * invH2);  // −βT0 h D2 u
    return;
  }
  // h (−βT0 D2 + EI D2²) u. D2² with D2 u = 0 at the ends is the simply supported biharmonic.
  const double ei = physics_.young * physics_.inertia * h_;
  double* d2u = work1_.data();
  double* d4u = work2_.data();
  secondDifference(q.data(), d2u, n, invH2);
  secondDifference(d2u, d4u, n, invH2);
  for (Eigen::Index j = 0; j < n; ++j) out[j] = -t * d2u[j] + ei * d4u[j];
}

double NonlinearString::transverseEigenvalue(int m) const {
  return transverseEigenvalue(m, tensionScale_);
}

double NonlinearString::transverseEigenvalue(int m, double scale) const {
  const double s = std::sin(m * std::numbers::pi / (2.0 * segments_));
  const double rhoA = physics_.linearDensity();
  const double h2 = h_ * h_;
  return scale * physics_.tension / rhoA * 4.0 / h2 * s * s +
         physics_.young * physics_.inertia / rhoA * 16.0 / (h2 * h2) * s * s * s * s;
}

double NonlinearString::longitudinalEigenvalue(int m) const {
  const double s = std::sin(m * std::numbers::pi / (2.0 * segments_));
  return physics_.tension / physics_.linearDensity() * 4.0 / (h_ * h_) * s * s;
}

void NonlinearString::setTensionRange(double maxScale) {
  if (!(maxScale >= 1.0 && maxScale <= 4.0))
    throw std::invalid_argument("tension scale range " + formatNumber(maxScale) +
                                ": must be between 1 and 4 (two octaves of bend)");
  tensionScaleMax_ = maxScale;
  tensionScale_ = 1.0;
}

double NonlinearString::stiffnessEigenvalueMax() const {
  // At the largest β the range allows; >= the longitudinal eigenvalue, mode by mode.
  return transverseEigenvalue(segments_ - 1, tensionScaleMax_);
}

double NonlinearString::lossOperatorEigenvalueMax() const {
  const double s = std::sin((segments_ - 1) * std::numbers::pi / (2.0 * segments_));
  return 4.0 / (h_ * h_) * s * s;
}

void NonlinearString::applyLossOperator(const Vector& a, const Vector& b, Vector& out) const {
  const Eigen::Index n = 2 * static_cast<Eigen::Index>(segments_ - 1);
  out.head(n) = a.head(n) - b.head(n);
  const double c = -physics_.linearDensity() * h_ / (h_ * h_);  // M (−D2) = −ρA h D2
  double* d = work1_.data();
  for (Eigen::Index half : {Eigen::Index{0}, n / 2}) {
    std::copy(out.data() + half, out.data() + half + n / 2, d);
    secondDifference(d, out.data() + half, n / 2, c);
  }
}

namespace {

// One segment's share of (65): with ζ, η its strains, returns (s − 1)² and sets φ (s − 1)/s, the
// factor of ∂V'/∂ζ = c φ ζ and ∂V'/∂η = c φ (1 + η). s − 1 = (2η + η² + ζ²)/(s + 1): no
// cancellation at small strain.
inline double segmentExcess(double zeta, double eta, double& phi) {
  const double stretch = std::sqrt((1.0 + eta) * (1.0 + eta) + zeta * zeta);
  const double excess = (2.0 * eta + eta * eta + zeta * zeta) / (stretch + 1.0);
  phi = excess / stretch;
  return excess * excess;
}

}  // namespace

// ζ_l = D₋u, η_l = D₋v on the M segments (u_0 = u_M = 0); V' = h (EA − T0)/2 Σ (s_l − 1)².
// The end segments are taken apart so the loop over the others has no branch and vectorises.
double NonlinearString::splitPotential(const Vector& q) const {
  const Eigen::Index m = segments_;
  const double* u = q.data();
  const double* v = q.data() + (m - 1);
  const double invH = 1.0 / h_;
  double phi;
  double sum = segmentExcess(u[0] * invH, v[0] * invH, phi) +
               segmentExcess(-u[m - 2] * invH, -v[m - 2] * invH, phi);
#pragma omp simd reduction(+ : sum)
  for (Eigen::Index l = 1; l < m - 1; ++l) {
    double f;
    sum += segmentExcess((u[l] - u[l - 1]) * invH, (v[l] - v[l - 1]) * invH, f);
  }
  return 0.5 * h_ * (physics_.young * physics_.area - physics_.tension) * sum;
}

// ∂V'/∂ζ_l = c φ_l ζ_l, ∂V'/∂η_l = c φ_l (1 + η_l), c = h (EA − T0); then
// ∇_u V' = D₋ᵀ(∂V'/∂ζ): (D₋ᵀ w)_j = (w_j − w_{j+1}) / h, likewise for v.
double NonlinearString::splitGradient(const Vector& q, Vector& grad) const {
  const Eigen::Index m = segments_;
  const double* u = q.data();
  const double* v = q.data() + (m - 1);
  const double invH = 1.0 / h_;
  const double c = h_ * (physics_.young * physics_.area - physics_.tension);
  double* wz = work1_.data();
  double* we = work2_.data();
  auto segment = [&](Eigen::Index l, double zeta, double eta) {
    double phi;
    const double e = segmentExcess(zeta, eta, phi);
    wz[l] = c * phi * zeta;
    we[l] = c * phi * (1.0 + eta);
    return e;
  };
  double sum =
      segment(0, u[0] * invH, v[0] * invH) + segment(m - 1, -u[m - 2] * invH, -v[m - 2] * invH);
#pragma omp simd reduction(+ : sum)
  for (Eigen::Index l = 1; l < m - 1; ++l)
    sum += segment(l, (u[l] - u[l - 1]) * invH, (v[l] - v[l - 1]) * invH);
  double* gu = grad.data();
  double* gv = grad.data() + (m - 1);
#pragma omp simd
  for (Eigen::Index j = 0; j < m - 1; ++j) {
    gu[j] = (wz[j] - wz[j + 1]) * invH;
    gv[j] = (we[j] - we[j + 1]) * invH;
  }
  return 0.5 * c * sum;
}

double minimalSpacing(const StringPhysics& p, GridRule rule, double k, double sigma1) {
  const double c2 = p.tension / p.linearDensity();
  const double kappa2 = p.young * p.inertia / p.linearDensity();
  const double a = c2 * k * k + 4.0 * sigma1 * k;
  const double transverse = std::sqrt(0.5 * (a + std::sqrt(a * a + 16.0 * kappa2 * k * k)));
  if (rule == GridRule::transverse) return transverse;
  return std::max(std::sqrt(p.young / p.density) * k, transverse);
}

int gridSegments(const StringPhysics& p, GridRule rule, double k, double sigma1, double factor) {
  if (!(factor >= 1.0) || !std::isfinite(factor))
    throw std::invalid_argument("grid factor = " + formatNumber(factor) + ": must be >= 1");
  const double h = factor * minimalSpacing(p, rule, k, sigma1);
  return segmentsAlong(
      p.length, h, k, 1e6, "length",
      rule == GridRule::transverse ? "stiff-string bound (44)" : "h >= sqrt(E/rho) k");
}

}  // namespace hamiltone
