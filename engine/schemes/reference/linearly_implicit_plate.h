// BDZ's linearly implicit, energy-conserving scheme (83) for the von Kármán plate: the reference
// the cost comparison of Fig. 10 sets against Störmer–Verlet (82) and the split scheme (38).
#pragma once

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "instruments/plate.h"
#include "schemes/hamiltonian.h"
#include "schemes/step_parameters.h"

namespace hamiltone {

// ℓ(f, ·) of (78) as a sparse matrix: L g = ℓ(f, g) (plate.bracket(f, g)), nine entries a row.
// Every entry of the 3 × 3 stencil is stored, zero or not, so the pattern does not depend on f.
// By the triple self-adjointness of (78) under zero edges, ⟨ℓ(f, g), w⟩ = ⟨ℓ(f, w), g⟩, L is
// symmetric (to roundoff: its mirrored entries are summed in different orders).
Eigen::SparseMatrix<double> bracketMatrix(const VonKarmanPlate& plate, const Vector& f);

// Time levels as the explicit schemes: after construction and after every step it holds q^n,
// q^{n+1} and F^n, F^{n+1}, and reports level n. Same grid, edges, operators and start (85) as
// VonKarmanPlate with StormerVerlet or SplitSav, so their outputs compare point for point.
// Lossless only. Not for the audio path: every step assembles a new matrix and factorises it
// (Eigen's sparse matrices and the factor allocate), which is acceptable for a reference.
//
// (83), with a = ρξ/k², D the rigidity and L = ℓ(q^n, ·) (so ℓ(q^{n+1}, q^n) = L q^{n+1}):
//   a (q^{n+1} − 2q^n + q^{n−1}) = −D DΔΔ q^n + ½ L (F^{n+1} + F^{n−1})          (83a)
//   DΔΔ (F^{n+1} + F^n) = −Eξ L q^{n+1}                                          (83b)
// Eliminating q^{n+1} = r + L F^{n+1}/(2a), r = 2q^n − q^{n−1} − (D/a) DΔΔ q^n + L F^{n−1}/(2a):
//   (DΔΔ + s L²) F^{n+1} = −DΔΔ F^n − Eξ L r,   s = Eξ/(2a) = E k²/(2ρ).
// DΔΔ = DΔ² is SPD (DΔ is symmetric negative definite with zero edges) and L² = LᵀL is PSD, so
// the matrix is SPD: Eigen's SimplicialLDLT (AMD ordering) factorises it — no pivoting, half the
// memory and work of SparseLU. The pattern is the same every step, so it is analysed once and
// only the numeric factorisation is repeated. F is the unknown (not q) because DΔΔ + s L² is
// sparse, while the Schur complement in q, a I + (Eξ/2) L DΔΔ⁻¹ L, is dense.
//
// Conserved energy (not printed in the paper; [49] proves the scheme stable). With ⟨u, w⟩ =
// hx hy Σ u w, take the inner product of (83a) with q^{n+1} − q^{n−1}: the first two terms give
// the differences of a‖q^{n+1} − q^n‖² and D⟨DΔq^{n+1}, DΔq^n⟩; by self-adjointness the last is
// ½⟨L(q^{n+1} − q^{n−1}), F^{n+1} + F^{n−1}⟩, and (83b) at n and n − 1 turns L(q^{n+1} − q^{n−1})
// into −DΔΔ(F^{n+1} − F^{n−1})/Eξ, giving −(‖DΔF^{n+1}‖² − ‖DΔF^{n−1}‖²)/(2Eξ). Hence
//   H^{n+½} = ½(δq)ᵀM(δq)/k² + ½(q^{n+1})ᵀK q^n + ½(V'(F^{n+1}) + V'(F^n)),
//   V'(F) = hx hy/(2Eξ) ‖DΔF‖²,   δq = q^{n+1} − q^n,
// is constant to roundoff — (41) with ½ψ² replaced by the mean of the two Airy energies. As for
// (38), H is non-negative, hence the run stable, under the bound (84) on the linear part.
class LinearlyImplicitPlate {
 public:
  // q^1 by the Taylor start (21), as the explicit schemes; F^0 the Airy function of q^0 (79),
  // F^1 from (83b). Throws std::invalid_argument for a bad k, ε ≠ 0, σ0 ≠ 0 or σ1 ≠ 0 (the
  // reference is lossless), or a start of the wrong size or not finite.
  LinearlyImplicitPlate(const VonKarmanPlate& plate, const StepParameters& params,
                        const InitialState& start);

  // One step of (83); throws std::runtime_error naming the step if the factorisation fails.
  void step();

  Energy energy() const;  // H^{n+½} above; the potential holds the K and Airy terms

  long stepIndex() const { return n_; }
  double time() const { return static_cast<double>(n_) * k_; }
  const Vector& q() const { return prev_; }
  const Vector& qNext() const { return curr_; }
  double dissipated() const { return 0.0; }
  const VonKarmanPlate& system() const { return plate_; }

 private:
  VonKarmanPlate plate_;
  double k_;
  Eigen::SparseMatrix<double> laplacian_, biharmonic_;  // DΔ, DΔΔ
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver_;
  bool analysed_ = false;
  Vector prev_, curr_;    // q^n, q^{n+1}
  Vector fPrev_, fCurr_;  // F^n, F^{n+1}
  long n_ = 0;
};

}  // namespace hamiltone
