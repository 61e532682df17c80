// The linear loss the schemes share: −2σ0 M q' centred as in (49), and the frequency-dependent
// −2σ1 M(−L) q' taken explicitly by a backward difference, each with its exact energy balance.
#pragma once

#include <cmath>
#include <stdexcept>

#include "schemes/hamiltonian.h"
#include "schemes/step_parameters.h"
#include "util/format_number.h"

namespace hamiltone {

// A model with a frequency-dependent loss says which operator it acts through: C = M(−L) >= 0,
// L its Laplacian (possibly weighted per wave, NonlinearString::LossWeights), applied to a
// difference of two states (a − b) into a third vector, and λmax(M⁻¹C).
template <class S>
concept HasLossOperator = requires(const S& s, const Vector& a, Vector& out) {
  s.applyLossOperator(a, a, out);
  { s.lossOperatorEigenvalueMax() } -> std::convertible_to<double>;
};

// A model whose stiffness stencil can give C(q^n − q^{n−1}) on the way (NonlinearString): K q^n
// and C(q^n − q^{n−1}) in one call, `prevKept` true when its last such call was on q^{n−1}.
template <class S>
concept HasStiffnessAndLoss = requires(const S& s, const Vector& a, Vector& out) {
  s.applyStiffnessAndLoss(a, a, true, out, out);
};

// With C = M(−L) and the backward difference δ−q = (q^n − q^{n−1})/k for the σ1 term,
// multiplying the scheme by (q^{n+1} − q^{n−1})/2 gives
//   Ĥ^{n+½} − Ĥ^{n−½} = −σ0/(2k) ‖Δ‖²_M − σ1/(2k) Δᵀ C Δ <= 0,   Δ = q^{n+1} − q^{n−1},
// for the energy Ĥ = H − σ1/(2k) (q^{n+1} − q^n)ᵀ C (q^{n+1} − q^n): the backward difference
// costs a negative kinetic term, which the stability bound must cover (maxStableStep).
template <HamiltonianSystem S>
class LinearLoss {
 public:
  LinearLoss() = default;
  LinearLoss(const S& system, const StepParameters& p)
      : sigma0_(p.sigma0), sigma1_(p.sigma1), k_(p.k) {
    if constexpr (!HasLossOperator<S>) {
      if (p.sigma1 != 0.0)
        throw std::invalid_argument("loss sigma1 = " + formatNumber(p.sigma1) +
                                    ": this model has no frequency-dependent loss; use 0");
    }
    cq_.setZero(system.size());
    diff_.setZero(system.size());
    mass_ = system.inverseMass().cwiseInverse();
  }

  bool any() const { return sigma0_ > 0.0 || sigma1_ > 0.0; }
  void setSigma0(double sigma0) noexcept { sigma0_ = sigma0; }
  double sigma0() const { return sigma0_; }
  double sigma1() const { return sigma1_; }

  // C (q^n − q^{n−1}), the σ1 force of the step before its factor −2σ1; zero when σ1 = 0.
  const Vector& frequencyForce(const S& s, const Vector& q, const Vector& qPrev) noexcept {
    if constexpr (HasLossOperator<S>) {
      if (sigma1_ > 0.0) s.applyLossOperator(q, qPrev, cq_);
    }
    return cq_;
  }

  // The same with K q^n into kq, both from the model's one call (HasStiffnessAndLoss), which
  // sigma1 > 0 requires.
  const Vector& frequencyForceAndStiffness(const S& s, const Vector& q, const Vector& qPrev,
                                           bool prevKept,
                                           Vector& kq) noexcept requires HasStiffnessAndLoss<S> {
    s.applyStiffnessAndLoss(q, qPrev, prevKept, kq, cq_);
    return cq_;
  }

  // The energy the step q^{n−1} → q^{n+1} took (the right side above).
  double dissipation(const S& s, const Vector& qNext, const Vector& qPrev) noexcept {
    double d = 0.0;
    if (sigma0_ > 0.0)
      d +=
          sigma0_ / (2.0 * k_) * ((qNext - qPrev).array().square() / s.inverseMass().array()).sum();
    if constexpr (HasLossOperator<S>) {
      if (sigma1_ > 0.0) {
        s.applyLossOperator(qNext, qPrev, diff_);
        d += sigma1_ / (2.0 * k_) * (qNext - qPrev).dot(diff_);
      }
    }
    return d;
  }

  // The Taylor start (21) with the loss in the acceleration: q^1 = q^0 + k v0 + (k²/2) a0,
  // a0 = −M⁻¹∇V(q^0) − 2σ0 v0 − 2σ1 M⁻¹C v0, v0 = M⁻¹p(0). Writes q^1 into `q1`.
  void taylorStart(const S& s, const InitialState& start, const Vector& gradV0, Vector& q1) {
    const double k = k_;
    const Vector& minv = s.inverseMass();
    q1 = start.q + k * (1.0 - sigma0_ * k) * minv.cwiseProduct(start.p) -
         0.5 * k * k * minv.cwiseProduct(gradV0);
    if constexpr (HasLossOperator<S>) {
      if (sigma1_ > 0.0) {
        diff_ = minv.cwiseProduct(start.p);
        s.applyLossOperator(diff_, Vector::Zero(diff_.size()), cq_);  // C v0
        q1 -= sigma1_ * k * k * minv.cwiseProduct(cq_);
        cq_.setZero();
      }
    }
  }

  // −σ1/(2k) (q1 − q0)ᵀ C (q1 − q0): the σ1 part of the kinetic energy of Ĥ.
  double kineticCorrection(const S& s, const Vector& q0, const Vector& q1) const {
    if constexpr (HasLossOperator<S>) {
      if (sigma1_ > 0.0) {
        s.applyLossOperator(q1, q0, diff_);
        return -sigma1_ / (2.0 * k_) * (q1 - q0).dot(diff_);
      }
    }
    return 0.0;
  }

 private:
  double sigma0_ = 0.0, sigma1_ = 0.0, k_ = 0.0;
  Vector cq_;            // C (q^n − q^{n−1})
  Vector mass_;          // diagonal of M
  mutable Vector diff_;  // scratch of dissipation() and kineticCorrection()
};

// The largest k for which Ĥ of the split scheme (38) is non-negative: in M-normalised modes the
// kinetic part is ½|v|²(1 − σ1 k λ_L − k² λ_K / 4), so k² λK/4 + σ1 λL k <= 1 — (44) when σ1 = 0.
// Exact for one uniform wave, whose K and L share eigenvectors and peak at the same mode; a string
// with u and v apart takes it block by block (NonlinearString::maxStableStep).
inline double maxStableStep(double lambdaK, double lambdaL, double sigma1) {
  const double b = sigma1 * lambdaL;
  if (lambdaK <= 0.0) return b > 0.0 ? 1.0 / b : INFINITY;
  return 2.0 * (std::sqrt(b * b + lambdaK) - b) / lambdaK;
}

}  // namespace hamiltone
