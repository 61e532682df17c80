// The felt law, the contact distribution J and the hammer's part of the potential and gradient.
#include "instruments/hammer.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "util/format_number.h"

namespace hamiltone {

namespace {

void require(bool ok, const char* field, double value, const char* valid) {
  if (!ok)
    throw std::invalid_argument(std::string("hammer ") + field + " = " + formatNumber(value) +
                                ": must be " + valid);
}

}  // namespace

Hammer::Hammer(const HammerFelt& f) : felt_(f) {
  require(std::isfinite(f.mass) && f.mass > 0.0, "mass", f.mass, "a finite number > 0 (kg)");
  require(std::isfinite(f.stiffness) && f.stiffness > 0.0, "stiffness", f.stiffness,
          "a finite number > 0 (N/m^p)");
  require(std::isfinite(f.exponent) && f.exponent >= 1.0 && f.exponent <= 6.0, "exponent",
          f.exponent, "between 1 and 6 (felt measures 1.5 to 3.5)");
  require(f.position > 0.0 && f.position < 1.0, "position", f.position,
          "a fraction of the length strictly between 0 and 1");
  require(std::isfinite(f.width) && f.width >= 0.0, "width", f.width, "a finite number >= 0 (m)");
}

double Hammer::potential(double eta) const {
  if (eta <= 0.0) return 0.0;
  return felt_.stiffness / (felt_.exponent + 1.0) * std::pow(eta, felt_.exponent + 1.0);
}

double Hammer::force(double eta) const {
  if (eta <= 0.0) return 0.0;
  return felt_.stiffness * std::pow(eta, felt_.exponent);
}

HammeredString::HammeredString(NonlinearString string, const HammerFelt& felt)
    : string_(std::move(string)), hammer_(felt) {
  const Eigen::Index n = string_.size();
  inverseMass_.resize(n + 1);
  inverseMass_.head(n) = string_.inverseMass();
  inverseMass_[n] = 1.0 / felt.mass;

  // J_j = ∫ φ_j(x) g(x) dx: the felt's raised cosine g (width w, unit area, centred on x0)
  // against grid point j's hat φ_j (1 at x_j = (j + 1) h, 0 at its neighbours). The hats sum to 1
  // from the first grid point to the last; w → 0 gives linear interpolation between the two points
  // around x0, w ≫ h the raised cosine sampled at the points. Simpson's rule on 64 intervals
  // between each two of the integrand's kinks.
  const double h = string_.spacing();
  const double x0 = felt.position * string_.physics().length;
  const double halfWidth = 0.5 * felt.width;
  const int points = string_.segments() - 1;
  auto density = [&](double x) {  // g(x); w = 0 is a point at x0 (below)
    const double d = (x - x0) / halfWidth;
    return std::abs(d) < 1.0 ? (1.0 + std::cos(std::numbers::pi * d)) / (2.0 * halfWidth) : 0.0;
  };
  auto hat = [&](int j, double x) { return std::max(0.0, 1.0 - std::abs(x / h - (j + 1))); };
  double total = 0.0;
  for (int j = 0; j < points; ++j) {
    double weight = 0.0;
    if (halfWidth == 0.0) {
      weight = hat(j, x0);
    } else if (j * h < x0 + halfWidth && (j + 2) * h > x0 - halfWidth) {  // they overlap
      // The integrand's kinks: the hat's three corners and the felt's edges and centre.
      std::vector<double> knots = {j * h,          (j + 1) * h, (j + 2) * h,
                                   x0 - halfWidth, x0,          x0 + halfWidth};
      std::sort(knots.begin(), knots.end());
      const double lo = std::max(j * h, x0 - halfWidth), hi = std::min((j + 2) * h, x0 + halfWidth);
      for (size_t k = 0; k + 1 < knots.size(); ++k) {
        const double a = std::max(knots[k], lo), b = std::min(knots[k + 1], hi);
        if (!(b > a)) continue;
        constexpr int kIntervals = 64;  // even
        const double step = (b - a) / kIntervals;
        double sum = 0.0;
        for (int i = 0; i <= kIntervals; ++i) {
          const double x = a + i * step;
          const double f = hat(j, x) * density(x);
          sum += (i == 0 || i == kIntervals ? 1.0 : i % 2 == 1 ? 4.0 : 2.0) * f;
        }
        weight += sum * step / 3.0;
      }
    }
    if (weight > 0.0) {
      contactIndex_.push_back(j);
      contactWeight_.push_back(weight);
      total += weight;
    }
  }
  // Where the felt lies within a segment of an end, the end's own hat (whose share the fixed end
  // takes) is missing and Σ J_j < 1: the contact there is the felt's mean of the interpolated u,
  // which is 0 at the end. Elsewhere the hats sum to 1 and Jᵀ1 = 1 up to Simpson's error: made
  // exact.
  const double length = string_.physics().length;
  if (x0 - halfWidth >= h && x0 + halfWidth <= length - h)
    for (double& w : contactWeight_) w /= total;
}

double HammeredString::contactDisplacement(const Vector& q) const {
  double s = 0.0;
  for (size_t i = 0; i < contactIndex_.size(); ++i) s += contactWeight_[i] * q[contactIndex_[i]];
  return s;
}

double HammeredString::compression(const Vector& q) const {
  return q[hammerIndex()] - contactDisplacement(q);
}

void HammeredString::applyStiffness(const Vector& q, Vector& out) const {
  string_.applyStiffness(q, out);
  out[hammerIndex()] = 0.0;
}

double HammeredString::splitPotential(const Vector& q) const {
  return string_.splitPotential(q) + hammer_.potential(compression(q));
}

// ∂Φ/∂w = Φ'(η), ∂Φ/∂u_j = −J_j Φ'(η).
double HammeredString::splitGradient(const Vector& q, Vector& grad) const {
  const double eta = compression(q);
  const double f = hammer_.force(eta);
  const double v = string_.splitGradient(q, grad);
  grad[hammerIndex()] = f;
  for (size_t i = 0; i < contactIndex_.size(); ++i) grad[contactIndex_[i]] -= contactWeight_[i] * f;
  return v + (eta > 0.0 ? f * eta / (hammer_.felt().exponent + 1.0) : 0.0);  // Φ = Φ'(η) η/(p+1)
}

double HammeredString::partPotential(int part, const Vector& q) const {
  return part == 0 ? string_.splitPotential(q) : hammer_.potential(compression(q));
}

double HammeredString::partGradient(int part, const Vector& q, Vector& grad) const {
  if (part == 0) {
    grad[hammerIndex()] = 0.0;
    return string_.splitGradient(q, grad);
  }
  // Sparse: only the hammer and the contact points, all rewritten (PartitionedPotential).
  const double eta = compression(q);
  const double f = hammer_.force(eta);
  grad[hammerIndex()] = f;
  for (size_t i = 0; i < contactIndex_.size(); ++i) grad[contactIndex_[i]] = -contactWeight_[i] * f;
  return eta > 0.0 ? f * eta / (hammer_.felt().exponent + 1.0) : 0.0;
}

void HammeredString::applyLossOperator(const Vector& a, const Vector& b, Vector& out) const {
  string_.applyLossOperator(a, b, out);
  out[hammerIndex()] = 0.0;
}

}  // namespace hamiltone
