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

void require(bool ok, const char* field, double value, const std::string& valid) {
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

  // J_j = ∫ φ_j(x) g(x) dx: the felt's raised cosine g(x) = (1 + cos(π(x − x0)/a)) / 2a on
  // |x − x0| < a = w/2 (unit area) against grid point j's hat φ_j (1 at x_j = (j + 1) h, 0 at its
  // neighbours). The hats sum to 1 from the first grid point to the last; a → 0 gives linear
  // interpolation between the two points around x0, a ≫ h the raised cosine sampled at the points.
  const double h = string_.spacing(), length = string_.physics().length;
  const double x0 = felt.position * length, a = 0.5 * felt.width;
  const double room = 2.0 * std::min(x0, length - x0);
  require(felt.width < room, "width", felt.width,
          "under 2 min(x0, L - x0) = " + formatApprox(room) + " m, so that the felt lies on the " +
              formatApprox(length) + " m string struck at " + formatNumber(felt.position) +
              " of it");
  const bool point = a <= 1e-9 * h;  // a felt that narrow presses as a point, to 1e-9 of h
  const double c = std::numbers::pi / a;
  // ∫ (P + βt)(1 + cos ct) dt, t = x − x0: the closed form over one side of a hat, φ = P + βt.
  auto primitive = [c](double p, double beta, double t) {
    const double sine = std::sin(c * t) / c, cosine = std::cos(c * t) / (c * c);
    return p * (t + sine) + beta * (0.5 * t * t + t * sine + cosine);
  };
  auto side = [&](double from, double to, double alpha, double beta) {  // φ = α + βx on [from, to]
    const double t1 = std::max(from, x0 - a) - x0, t2 = std::min(to, x0 + a) - x0;
    if (!(t2 > t1)) return 0.0;
    const double p = alpha + beta * x0;
    return (primitive(p, beta, t2) - primitive(p, beta, t1)) / (2.0 * a);
  };
  const int points = string_.segments() - 1;
  double total = 0.0;
  for (int j = 0; j < points; ++j) {
    const double weight = point ? std::max(0.0, 1.0 - std::abs(x0 / h - (j + 1)))
                                : side(j * h, (j + 1) * h, -j, 1.0 / h) +
                                      side((j + 1) * h, (j + 2) * h, j + 2.0, -1.0 / h);
    if (weight > 0.0) {
      contactIndex_.push_back(j);
      contactWeight_.push_back(weight);
      total += weight;
    }
  }
  // Where the felt reaches into a segment at an end, that end's hat (whose share the fixed end
  // takes) is missing and Σ J_j < 1: the contact there is the felt's mean of the interpolated u,
  // which is 0 at the end. Elsewhere the hats sum to 1 and so does J, to roundoff: made exact.
  if (x0 - a >= h && x0 + a <= length - h)
    for (double& w : contactWeight_) w /= total;
  support_ = contactIndex_;
  support_.push_back(hammerIndex());
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

void HammeredString::applyStiffnessAndLoss(const Vector& q, const Vector& qPrev, bool prevKept,
                                           Vector& kq, Vector& cq) const {
  string_.applyStiffnessAndLoss(q, qPrev, prevKept, kq, cq);
  kq[hammerIndex()] = 0.0;
  cq[hammerIndex()] = 0.0;
}

}  // namespace hamiltone
