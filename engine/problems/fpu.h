// The Fermi–Pasta–Ulam chain of BDZ §4.1: 2M unit masses joined alternately by linear springs
// of stiffness ω²/2 and quartic springs, fixed at both ends — (52), split as (53).
#pragma once

#include "schemes/hamiltonian.h"

namespace hamiltone {

class FermiPastaUlam {
 public:
  static constexpr bool hasStiffness = true;

  // Throws std::invalid_argument for pairs < 1 or a non-finite or non-positive ω.
  FermiPastaUlam(int pairs, double omega);

  Eigen::Index size() const { return inverseMass_.size(); }
  int pairs() const { return pairs_; }
  double omega() const { return omega_; }

  const Vector& inverseMass() const { return inverseMass_; }  // M = I
  // K = (ω²/2) I_M ⊗ [1 −1; −1 1]   (53)
  void applyStiffness(const Vector& q, Vector& out) const;
  double stiffnessEigenvalueMax() const { return omega_ * omega_; }  // so (44) is k <= 2/ω (54)
  // V' = Σ_{i=0}^{M} (q_{2i+1} − q_{2i})⁴, with q_0 = q_{2M+1} = 0   (53)
  double splitPotential(const Vector& q) const;
  double splitGradient(const Vector& q, Vector& grad) const;

  // The whole potential (52), written out independently of the split, to check it.
  double potential(const Vector& q) const;

 private:
  int pairs_;
  double omega_;
  Vector inverseMass_;
};

// BDZ §4.1.1: q(0) = α e₄ (the 4th coordinate), p(0) = 0. Needs pairs >= 2.
InitialState fpuInitialState(const FermiPastaUlam& chain, double alpha);

}  // namespace hamiltone
