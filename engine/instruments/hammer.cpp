// The felt law, the contact distribution J and the hammer's part of the potential and gradient.
#include "instruments/hammer.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

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

  // Interior grid point j (0-based) sits at x = (j + 1) h.
  const double h = string_.spacing();
  const double x0 = felt.position * string_.physics().length;
  const int points = string_.segments() - 1;
  double total = 0.0;
  for (int j = 0; j < points; ++j) {
    const double d = ((j + 1) * h - x0) / (0.5 * felt.width);
    if (std::abs(d) < 1.0) {
      contactIndex_.push_back(j);
      contactWeight_.push_back(0.5 * (1.0 + std::cos(std::numbers::pi * d)));
      total += contactWeight_.back();
    }
  }
  if (contactIndex_.empty()) {  // felt narrower than the grid: linear interpolation
    const double s = std::clamp(x0 / h - 1.0, 0.0, points - 1.0);
    const int j = std::min(static_cast<int>(s), points - 1);
    const double frac = s - j;
    contactIndex_ = {j};
    contactWeight_ = {1.0 - frac};
    if (j + 1 < points && frac > 0.0) {
      contactIndex_.push_back(j + 1);
      contactWeight_.push_back(frac);
    }
    total = 1.0;
  }
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
