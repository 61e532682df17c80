// The nonlinear wave equation of Marazzato et al. [M §3.3] (from Chabassier & Joly): an R²-valued
// string on [0, 1] in P1 finite elements with the consistent, tridiagonal mass matrix.
#pragma once

#include "schemes/hamiltonian.h"

namespace hamiltone {

// ∂²u/∂t² − ∂x(∇V(∂x u)) = 0 on [0, 1], u(0) = u(1) = 0, u ∈ R²   [M (20)], with
//   V(u1, u2) = (u1² + u2²)/2 − α (sqrt((1 + u1)² + u2²) − (1 + u1)),   0 <= α < 1.
// u1 stretches the string (the 1 + u1), u2 moves it sideways: at rest the two waves travel at
// 1 and sqrt(1 − α). Space: P1 elements of width Δx = 1/elements, N = elements − 1 interior nodes
// per direction, q = (u1 at nodes 1..N, u2 at nodes 1..N) as in the paper. Since ∂x u_N is
// constant on an element, V(q) = Σ_e Δx V(∂x u_N|_e) is exact, and the mass matrix is
// M = diag(T, T), T = Δx tridiag(1/6, 2/3, 1/6) [M §3.3] — not diagonal, so M⁻¹p is a tridiagonal
// solve, by an LDLᵀ factorisation of T made once here.
//
// V is evaluated in a form free of cancellation: for 1 + u1 > 0,
//   sqrt((1 + u1)² + u2²) − (1 + u1) = u2² / (sqrt(...) + 1 + u1),
// so small strains keep full relative precision (needed to see a 1e-16 pseudo-energy error).
// At 1 + u1 = u2 = 0 (an element squeezed to a point) V is not differentiable; nothing guards it.
class NonlinearWave {
 public:
  // Throws std::invalid_argument unless 0 <= alpha < 1 and 2 <= elements <= 1e6.
  NonlinearWave(double alpha, int elements);

  Eigen::Index size() const { return 2 * static_cast<Eigen::Index>(nodes_); }
  int nodes() const { return nodes_; }  // N, interior nodes per direction
  double dx() const { return dx_; }
  double alpha() const { return alpha_; }

  // out = M⁻¹ p: two O(N) tridiagonal solves, in place in `out` (which may not alias p).
  void applyInverseMass(const Vector& p, Vector& out) const noexcept;
  // out = M v (tests, and any start with a velocity).
  void applyMass(const Vector& v, Vector& out) const noexcept;
  double potential(const Vector& q) const noexcept;               // V(q) = ∫ V(∂x u_N)
  double gradient(const Vector& q, Vector& grad) const noexcept;  // ∇V(q); returns V(q)
  // u_N(x) in direction `component` (0 or 1): the P1 interpolant, exact for the FE solution.
  double displacement(const Vector& q, int component, double x) const;

  // The density V(u1, u2) and its gradient, for one element's strain.
  static double density(double u1, double u2, double alpha);
  static void densityGradient(double u1, double u2, double alpha, double& g1, double& g2);

 private:
  double alpha_, dx_;
  int nodes_;
  Vector lower_;        // LDLᵀ of T: the subdiagonal of L (lower_[0] unused)
  Vector inverseDiag_;  // 1 / D
};

// The start used throughout: u(x, 0) = u0 (sin πx, sin πx), ∂t u(x, 0) = 0, i.e. q at the nodes
// x_j = j Δx and p = 0. [M §3.3] gives the amplitudes (0.01, 0.1, 0.3) and the zero velocity but
// not the shape; both components are displaced because with u2 = 0 the α term vanishes and the
// motion is linear.
InitialState nonlinearWaveInitialState(const NonlinearWave& wave, double amplitude);

}  // namespace hamiltone
