// The [M §3.1] particle's potential, its force and its exact solution.
#include "problems/particle.h"

#include <cmath>

namespace hamiltone {

// x = q − 1;  V = 8 (x² − x |x|^{1/2}),  V' = 16 x − 12 |x|^{1/2}   [M §3.1], sign corrected
double Particle::splitPotential(const Vector& q) const {
  const double x = q[0] - 1.0;
  return 8.0 * (x * x - x * std::sqrt(std::abs(x)));
}

double Particle::splitGradient(const Vector& q, Vector& grad) const {
  const double x = q[0] - 1.0;
  const double root = std::sqrt(std::abs(x));
  grad[0] = 16.0 * x - 12.0 * root;
  return 8.0 * (x * x - x * root);
}

double Particle::exactPosition(double t) {
  const double s = std::sin(t);
  return (s * s) * (s * s) + 1.0;
}

double Particle::exactMomentum(double t) {
  const double s = std::sin(t);
  return 4.0 * s * s * s * std::cos(t);
}

// Written out, not evaluated: cos(π/2) rounds to 6e-17, not 0, and the exact energy is 0.
InitialState particleInitialState() { return {Vector::Constant(1, 2.0), Vector::Zero(1)}; }

}  // namespace hamiltone
