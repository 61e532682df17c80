// The single particle of Marazzato et al. [M §3.1], whose exact solution q(t) = sin⁴t + 1 is the
// reference of their convergence study [M Fig. 1].
#pragma once

#include <numbers>

#include "schemes/hamiltonian.h"

namespace hamiltone {

// One unit mass in d = 1 with the potential of [M §3.1], sign corrected:
//   V(q) = 8 ((q − 1)² − (q − 1)^{3/2}),   H = ½ p² + V(q).
// The paper prints V = 8((q − 1)^{3/2} − (q − 1)²), which makes sin⁴t + 1 solve q'' = +V'(q);
// with the sign flipped it solves q'' = −V'(q), and H = 0 along it.
// For q < 1, outside the paper's domain, V is continued as 8((q−1)² − (q−1)|q−1|^{1/2}): C¹ and
// rising, a wall that turns back a numerical solution overshooting q = 1 instead of a NaN.
// V < 0 inside the well (down to −27/32 at q = 25/16), so this model breaks the V' >= 0 of the
// SAV schemes; it is meant for Marazzato's scheme, which never takes the root of V.
class Particle {
 public:
  static constexpr bool hasStiffness = false;

  // The run starts at t0 = π/2 (q = 2, p = 0), not at t = 0: q(0) = 1, p(0) = 0 is an
  // equilibrium (V'(1) = 0) through which the force 12 (q−1)^{1/2} − 16 (q−1) is not Lipschitz,
  // so the rest state is a solution too — and the one the start [M 7] follows.
  static constexpr double startTime = std::numbers::pi / 2;

  Particle() : inverseMass_(Vector::Ones(1)) {}

  Eigen::Index size() const { return 1; }
  const Vector& inverseMass() const { return inverseMass_; }                // m = 1
  void applyStiffness(const Vector&, Vector& out) const { out.setZero(); }  // K = 0
  double stiffnessEigenvalueMax() const { return 0.0; }
  double splitPotential(const Vector& q) const;  // V(q), all of it
  double splitGradient(const Vector& q, Vector& grad) const;

  static double exactPosition(double t);  // q(t) = sin⁴t + 1
  static double exactMomentum(double t);  // p(t) = q'(t) = 4 sin³t cos t

 private:
  Vector inverseMass_;
};

// The exact state at Particle::startTime: q = sin⁴(π/2) + 1 = 2, p = 0.
InitialState particleInitialState();

}  // namespace hamiltone
