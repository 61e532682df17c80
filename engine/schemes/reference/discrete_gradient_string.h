// BDZ's fully implicit, energy-conserving scheme (67)–(68) for the geometrically exact string,
// solved by Newton–Raphson: the reference the cost comparison of Fig. 7 sets against (66), (38).
#pragma once

#include <Eigen/SparseCore>
#include <Eigen/SparseLU>

#include "instruments/string.h"
#include "schemes/hamiltonian.h"

namespace hamiltone {

// Time levels as the explicit schemes: after construction and after every step it holds q^n and
// q^{n+1} and reports level n. Lossless only. Not for the audio path: every Newton iteration
// refactorises the Jacobian (SparseLU allocates), which is acceptable for a reference.
//
// (67) with (57b): the quadratic part of V' is K q taken at (q^{n+1} + q^{n−1})/2 (its discrete
// gradient (68), exactly; K also carries the model's EI and β), the nonlinear part V' of (65) by
// (68) segment by segment. Per step, the unknown x = q^{n+1} solves
//   F(x) = M (x − 2q^n + q^{n−1})/k² + K (x + q^{n−1})/2 + h [D₋ᵀ g_ζ; D₋ᵀ g_η] = 0,
// with g_ζ depending on ζ^{n+1} alone (η^n fixed) and g_η on η^{n+1} alone (ζ^n fixed): the
// Jacobian is block diagonal in u and v, each block banded (tridiagonal, pentadiagonal with EI).
class DiscreteGradientString {
 public:
  static constexpr double tolerance = 1e-13;  // Newton, as in BDZ Fig. 7
  static constexpr int maxIterations = 20;

  // q^1 by the Taylor start (21). Throws std::invalid_argument if k <= 0 or the state's size
  // is not string.size().
  DiscreteGradientString(const NonlinearString& string, double k, const InitialState& start);

  // One step of (67)–(68). Newton from x = 2q^n − q^{n−1} stops when the update's max norm is
  // <= tolerance · max(‖x‖∞, ‖q^n‖∞); throws std::runtime_error naming the step if that takes
  // more than maxIterations.
  void step();

  // H^{n+½} = ½(δq)ᵀM(δq)/k² + ¼(q^{n+1}ᵀKq^{n+1} + q^nᵀKq^n)
  //           + h/2 Σ_l [𝒱'(ζ_l^{n+1}, η_l^n) + 𝒱'(ζ_l^n, η_l^{n+1})]:
  // the energy (67)–(68) conserve (§4.2.2 states conservation without numbering it; it follows
  // from multiplying (67) by (q^{n+1} − q^{n−1})ᵀ/2 and summing (68) by parts).
  Energy energy() const;

  long stepIndex() const { return n_; }
  double time() const { return static_cast<double>(n_) * k_; }
  const Vector& q() const { return prev_; }
  const Vector& qNext() const { return curr_; }
  double dissipated() const { return 0.0; }
  const NonlinearString& system() const { return string_; }
  int lastIterations() const { return lastIterations_; }  // Newton iterations of the last step
  int maxIterationsUsed() const { return maxIterationsUsed_; }
  long totalIterations() const { return totalIterations_; }

 private:
  // F(x) into residual_ and the Jacobian's nonlinear diagonal weights into weights_ (2M: ζ then η
  // segments).
  void residual(const Vector& x, const Vector& qn, const Vector& qm);
  void assembleJacobian();

  NonlinearString string_;
  double k_;
  Eigen::SparseMatrix<double> stiffness_, jacobian_;  // K; ρAh/k² I + K/2 + ∂G/∂x
  Eigen::SparseLU<Eigen::SparseMatrix<double>> solver_;
  Vector prev_, curr_, next_;  // q^n, q^{n+1}, workspace; rotated by swapping
  Vector residual_, weights_, work_;
  long n_ = 0;
  int lastIterations_ = 0, maxIterationsUsed_ = 0;
  long totalIterations_ = 0;
};

}  // namespace hamiltone
