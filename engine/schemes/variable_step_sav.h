// BDZ's variable-step explicit exactly energy-conserving SAV scheme (48), conserving (36).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "schemes/hamiltonian.h"
#include "schemes/step_parameters.h"  // checkInitialState
#include "util/format_number.h"

namespace hamiltone {

// (48) is the variable-step form of (47) ≡ (27): its ψ quadratises the whole potential
// V + ε = ½ qᵀKq + V' + ε = ½ψ² (the generalised splitting (46) with K₀ = 0). A K kept linearly,
// as in (38), would make the kinetic-plus-½ q^{n+1}ᵀK q^n balance telescope only for equal steps,
// so no split variant conserves an energy for every step sequence; this one does, and (37) bounds
// p for every step: there is no step bound like (44). With K = 0 (hasStiffness false) ψ is the
// split ψ of (39) and a constant step gives SplitSav's q^n.
// Time levels: after step m the scheme holds q^m, p^{m−½}, ψ^{m−½} at t^m = Σ steps. The half
// levels sit at the midpoints, t^{n+½} = (t^n + t^{n+1})/2, so k^n = (k^{n−½} + k^{n+½})/2:
// second order for a smoothly varying step. The first step is the start (21) with that step.
template <HamiltonianSystem S>
class VariableStepSav {
 public:
  // Throws std::invalid_argument for a start of the wrong size or not finite, or ε < 0.
  VariableStepSav(S system, const InitialState& start, double epsilon = 0.0)
      : system_(std::move(system)), epsilon_(epsilon) {
    if (!std::isfinite(epsilon_) || epsilon_ < 0.0)
      throw std::invalid_argument("gauge shift epsilon = " + formatNumber(epsilon_) +
                                  ": must be a finite number >= 0 (J)");
    const Eigen::Index n = system_.size();
    checkInitialState(start, n);
    q_ = start.q;
    p_ = start.p;
    grad_.setZero(n);
    kq_.setZero(n);
    half_.setZero(n);
    startPotential_ = fullPotential(system_, q_, kq_);
  }

  // Advances by k = t^{n+1} − t^n: (48b), (48c) solved in closed form — the scalar form of
  // Sherman–Morrison (33) — then (48a). Throws std::invalid_argument, naming the step, unless
  // k is finite and > 0.
  void step(double k) {
    if (!std::isfinite(k) || k <= 0.0)
      throw std::invalid_argument("time step k = " + formatNumber(k) + " of step " +
                                  std::to_string(n_) + ": must be a finite number > 0 (seconds)");
    if (n_ == 0)
      start(k);
    else
      advance(k);
    q_ += k * system_.inverseMass().cwiseProduct(p_);  // (48a)
    lastStep_ = k;
    time_ += k;
    ++n_;
    if (n_ == 1) {
      // ψ^{½} = sqrt(2 (V(q^{½}) + ε)) at q^{½} = q(k/2) + O(k³) = q^0 + (k/2) M⁻¹p^{½} +
      // (k²/8) M⁻¹∇V(q^0), grad_ still holding ∇V(q^0); the mean (q^0 + q^1)/2 would be O(k²)
      // off, an error the conserved energy keeps (see SavScheme's start).
      half_ = q_ - (0.5 * k) * system_.inverseMass().cwiseProduct(p_) +
              (0.125 * k * k) * system_.inverseMass().cwiseProduct(grad_);
      psi_ = std::sqrt(2.0 * (fullPotential(system_, half_, kq_) + epsilon_));
    }
  }

  // (36) at level n − ½: ½ (p^{n−½})ᵀM⁻¹p^{n−½} + ½ (ψ^{n−½})² − ε. Before the first step, the
  // exact H(q(0), p(0)), which H^{½} approximates to O(k²).
  Energy energy() const {
    Energy e;
    e.kinetic = 0.5 * p_.dot(system_.inverseMass().cwiseProduct(p_));
    e.potential = n_ == 0 ? startPotential_ : 0.5 * psi_ * psi_ - epsilon_;
    return e;
  }

  long stepIndex() const { return n_; }
  double time() const { return time_; }          // t^n
  const Vector& q() const { return q_; }         // q^n
  const Vector& p() const { return p_; }         // p^{n−½}; p(0) before the first step
  double psi() const { return psi_; }            // ψ^{n−½}
  double lastStep() const { return lastStep_; }  // k^{n−½}
  const S& system() const { return system_; }

 private:
  // (21): p^{½} = p(0) − (k/2) ∇V(q^0), so that (48a) gives q^1 = q^0 + k M⁻¹p(0) − (k²/2) M⁻¹∇V.
  void start(double k) {
    fullGradient(system_, q_, grad_, kq_);
    p_ -= (0.5 * k) * grad_;
  }

  // p^{n+½}, ψ^{n+½} from p^{n−½}, ψ^{n−½} and g^n = ∇V(q^n) / sqrt(2 (V(q^n) + ε))   (28).
  void advance(double k) noexcept {
    const double kn = 0.5 * (lastStep_ + k);  // k^n = t^{n+½} − t^{n−½}
    const double shifted = fullGradient(system_, q_, grad_, kq_) + epsilon_;
    const double s = shifted > 0.0 ? 1.0 / std::sqrt(2.0 * shifted) : 0.0;  // g = s ∇V
    const Vector& minv = system_.inverseMass();
    const double gMg = s * s * grad_.dot(minv.cwiseProduct(grad_));  // gᵀM⁻¹g
    const double gMp = s * grad_.dot(minv.cwiseProduct(p_));         // gᵀM⁻¹p^{n−½}
    // (48b) into (48c): ψ^{n+½} + ψ^{n−½} = (2ψ^{n−½} + k^n gᵀM⁻¹p^{n−½}) / (1 + (k^n)² gᵀM⁻¹g/4)
    const double psiSum = (2.0 * psi_ + kn * gMp) / (1.0 + 0.25 * kn * kn * gMg);
    p_ -= (0.5 * kn * psiSum * s) * grad_;  // (48b)
    psi_ = psiSum - psi_;                   // (48c), by the sum that (48b) used
  }

  S system_;
  double epsilon_;
  Vector q_, p_;                 // q^n, p^{n−½}
  Vector grad_;                  // ∇V at q^n; workspace
  Vector kq_;                    // K q, the scratch of fullPotential / fullGradient
  Vector half_;                  // q^{½}, where the first ψ is taken
  double startPotential_ = 0.0;  // V(q(0))
  double psi_ = 0.0;             // ψ^{n−½}
  double lastStep_ = 0.0;
  double time_ = 0.0;
  long n_ = 0;
};

}  // namespace hamiltone
