// The Fermi–Pasta–Ulam chain with slow/fast dynamics of [M §4.3.1]: stiff linear springs on the
// left, soft quartic ones on the right, fixed at both ends; partitioned as in [M §4.1].
#pragma once

#include <span>
#include <vector>

#include "schemes/hamiltonian.h"

namespace hamiltone {

// H = ½ Σ_{i=1}^{2m} p_i² + ω²/4 Σ_{i=1}^{m} (q_i − q_{i−1})² + Σ_{i=m}^{2m} (q_{i+1} − q_i)⁴,
// q_0 = q_{2m+1} = 0, unit masses. The m linear springs join wall–q_1–…–q_m, the m + 1 quartic
// ones q_m–q_{m+1}–…–q_{2m}–wall. So q_1…q_{m−1} are fast, q_m mixed, q_{m+1}…q_{2m} slow (the
// paper's m − 1, 1 and m): V_F = the linear springs (m), V_M = (q_{m+1} − q_m)⁴ (1),
// V_S = the other quartic springs (m). Storage is 0-based: x[j] = q_{j+1}.
class SlowFastFermiPastaUlam {
 public:
  // Throws std::invalid_argument for pairs < 1 or a non-finite or non-positive ω.
  SlowFastFermiPastaUlam(int pairs, double omega);

  Eigen::Index size() const { return inverseMass_.size(); }
  int pairs() const { return pairs_; }
  double omega() const { return omega_; }
  const Vector& inverseMass() const { return inverseMass_; }  // M = I

  std::span<const Eigen::Index> fastParticles() const { return fast_; }
  std::span<const Eigen::Index> mixedParticles() const { return mixed_; }
  std::span<const Eigen::Index> slowParticles() const { return slow_; }
  std::span<const Eigen::Index> coupledSlowParticles() const { return coupled_; }

  double fastPotential(const Vector& q) const;   // ω²/4 Σ_{i=1}^{m} (q_i − q_{i−1})²
  double mixedPotential(const Vector& q) const;  // (q_{m+1} − q_m)⁴
  double slowPotential(const Vector& q) const;   // Σ_{i=m+1}^{2m} (q_{i+1} − q_i)⁴
  void addFastGradient(const Vector& q, double w, Vector& out) const;
  void addMixedGradient(const Vector& q, double w, Vector& out) const;
  void addSlowGradient(const Vector& q, double w, Vector& out) const;
  long fastInteractions() const { return pairs_; }
  long mixedInteractions() const { return 1; }
  long slowInteractions() const { return pairs_; }

  // The largest eigenvalue of the linear springs' stiffness (V_F's Hessian), for the fast CFL
  // bound h_F < 2/√λ of [M (16)].
  double fastEigenvalueMax() const;

  // The whole H's potential written out from the formula above, to check the split.
  double potential(const Vector& q) const;

 private:
  double at(const Vector& q, int i) const;  // q_i, 1-based, with the walls

  int pairs_;
  double omega_;
  Vector inverseMass_;
  std::vector<Eigen::Index> fast_, mixed_, slow_, coupled_;
};

// The paper does not give its start; ours is BDZ §4.1.1's, q(0) = α e_{m+1} (the slow particle
// next to the interface: e₄ for m = 3), p(0) = 0.
InitialState slowFastInitialState(const SlowFastFermiPastaUlam& chain, double alpha);

}  // namespace hamiltone
