// Marazzato et al.'s scheme [M (6)] for any SPD mass matrix M (applied as a solve) and any step
// sequence h_n, with the adaptive step of [M Remark 8].
#pragma once

#include <algorithm>
#include <cmath>
#include <concepts>
#include <limits>
#include <stdexcept>
#include <utility>

#include "schemes/hamiltonian.h"
#include "schemes/marazzato.h"
#include "schemes/quadrature.h"
#include "schemes/step_parameters.h"

namespace hamiltone {

// H = ½ pᵀM⁻¹p + V(q) with M SPD but not necessarily diagonal (a finite-element mass matrix):
// the model applies M⁻¹ itself. Outputs go to caller-owned vectors of size(); nothing allocates.
template <class S>
concept MassMatrixSystem = requires(const S& s, const Vector& q, Vector& out) {
  { s.size() } -> std::convertible_to<Eigen::Index>;
  s.applyInverseMass(q, out);                             // out = M⁻¹ q
  { s.potential(q) } -> std::convertible_to<double>;      // V(q)
  { s.gradient(q, out) } -> std::convertible_to<double>;  // out = ∇V(q); returns V(q)
};

// [M Remark 8]: after each momentum update, accept the step only if the gap (18)
//   H^{n+1} − H̃^{n+1} = ⅛ [p]ᵀM⁻¹[p],  [p] = p^{n+3/2} − p^{n+½},
// is at most epsilonFly · H̃^{n+1}. A step that fails is thrown away and redone from the same
// state (q^n, p^{n−½}, p^{n+½}) — which the attempt did not touch — with half the step. Theorem 1
// holds step by step for whatever h_n is used (its proof involves h_n only through q^{n+1} and
// p^{n+3/2}), so the accepted sequence conserves (13) exactly as a fixed step would, up to the
// quadrature error; a rejected attempt leaves no trace. Growth: after `growAfter` accepted steps
// in a row whose gap is at most epsilonFly H̃ / 4, the step doubles, capped at the first (maximum)
// step — the gap is O(h²) (Remark 8), so a doubled step should still pass. A step that would have
// to fall below minStep ends the run: step() returns false.
// Limit: the start [M (7)] and every change of step leave a (−1)ⁿ component in the jumps (the
// leapfrog's parasitic mode, eigenvalue −1 in Prop. 6) that does not shrink with h, so after a
// halving the gap may stay above epsilonFly H̃ / 4 and the step not grow back.
struct AdaptiveStep {
  bool enabled = false;
  double epsilonFly = 3e-4;  // [M §3.3]: 0.03 %
  double minStep = 0.0;
  int growAfter = 4;
};

// State at level n: t^n, q^n, p^{n−½}, p^{n+½} and their velocities M⁻¹p. Started by [M (7)]:
// p^{−½} = p^{½} = p(0), so H̃^0 = H(0).
template <MassMatrixSystem S>
class VariableStepMarazzato {
 public:
  VariableStepMarazzato(S system, double step, const InitialState& start, QuadratureRule rule,
                        AdaptiveStep adaptive = {})
      : system_(std::move(system)),
        quadrature_(quadrature(rule)),
        adaptive_(adaptive),
        maxStep_(step),
        step_(step) {
    checkStepParameters({.k = step}, /*hasEpsilon=*/false);
    if (adaptive_.enabled && !(adaptive_.epsilonFly > 0.0 && std::isfinite(adaptive_.epsilonFly)))
      throw std::invalid_argument("eps_fly = " + formatNumber(adaptive_.epsilonFly) +
                                  ": must be a finite number > 0");
    if (adaptive_.enabled && !(adaptive_.minStep > 0.0 && adaptive_.minStep <= step))
      throw std::invalid_argument("minimum step = " + formatNumber(adaptive_.minStep) +
                                  ": must be > 0 and at most the step " + formatNumber(step));
    const Eigen::Index n = system_.size();
    checkInitialState(start, n);
    for (Vector* v :
         {&q_, &qNext_, &pPrev_, &p_, &pNext_, &vPrev_, &v_, &vNext_, &x_, &grad_, &force_})
      v->setZero(n);
    q_ = start.q;
    pPrev_ = start.p;  // [M (7)]
    p_ = start.p;
    system_.applyInverseMass(p_, v_);
    vPrev_ = v_;
    potential_ = system_.potential(q_);
    pseudoEnergy_ = potential_ + 0.5 * pPrev_.dot(v_);  // [M (13)]
  }

  // One accepted step. Returns false (state unchanged) when the adaptive bound cannot be met
  // with a step >= minStep.
  bool step() noexcept {
    for (;;) {
      attempt(step_);
      // [M (18)]: ⅛ [p]ᵀM⁻¹[p] with M⁻¹[p] = M⁻¹p^{n+3/2} − M⁻¹p^{n+½}, no extra solve.
      gapNext_ = 0.125 * (pNext_ - p_).dot(vNext_ - v_);
      if (!adaptive_.enabled || gapNext_ <= adaptive_.epsilonFly * pseudoNext_) break;
      if (0.5 * step_ < adaptive_.minStep) return false;
      step_ *= 0.5;  // [M Remark 8]: halve and redo from level n
      ++rejected_;
    }
    lastStep_ = step_;
    minUsed_ = std::min(minUsed_, step_);
    maxUsed_ = std::max(maxUsed_, step_);
    if (adaptive_.enabled) {
      worstGapRatio_ = std::max(worstGapRatio_, gapNext_ / (adaptive_.epsilonFly * pseudoNext_));
      calm_ = gapNext_ <= adaptive_.epsilonFly * pseudoNext_ / 4.0 ? calm_ + 1 : 0;
      if (calm_ >= adaptive_.growAfter && step_ < maxStep_) {
        step_ = std::min(2.0 * step_, maxStep_);
        calm_ = 0;
      }
    }
    // rotate: p^{n−½} ← p^{n+½} ← p^{n+3/2},  q^n ← q^{n+1}, and their velocities
    pPrev_.swap(p_);
    p_.swap(pNext_);
    vPrev_.swap(v_);
    v_.swap(vNext_);
    q_.swap(qNext_);
    potential_ = potentialNext_;
    pseudoEnergy_ = pseudoNext_;
    time_ += lastStep_;
    ++n_;
    return true;
  }

  // Pseudo-energy (13) at t^n: V(q^n) + ½ (p^{n−½})ᵀM⁻¹p^{n+½} (the kinetic part has no sign).
  double pseudoEnergy() const { return pseudoEnergy_; }
  // Discrete energy (17): V(q^n) + ⅛ (p^{n−½} + p^{n+½})ᵀM⁻¹(p^{n−½} + p^{n+½}) >= (13), (18).
  double discreteEnergy() const { return potential_ + 0.125 * (pPrev_ + p_).dot(vPrev_ + v_); }

  long stepIndex() const { return n_; }
  double time() const { return time_; }
  double lastStep() const { return lastStep_; }  // h_{n−1} = t^n − t^{n−1}; 0 at n = 0
  double nextStep() const { return step_; }      // the step the next attempt will try
  const Vector& q() const { return q_; }
  const Vector& p() const { return p_; }              // p^{n+½}
  const Vector& pPrevious() const { return pPrev_; }  // p^{n−½}
  const S& system() const { return system_; }
  const Quadrature& rule() const { return quadrature_; }
  long forceEvaluations() const { return forces_; }  // accepted and rejected attempts
  long rejectedSteps() const { return rejected_; }
  double minStepUsed() const { return minUsed_; }
  double maxStepUsed() const { return maxUsed_; }
  // max over accepted steps of gap / (epsilonFly H̃), <= 1 by construction when adaptive.
  double worstGapRatio() const { return worstGapRatio_; }

 private:
  // [M (6a)]: q^{n+1} = q^n + h M⁻¹p^{n+½};  [M (6b), (9)]: p^{n+3/2} = p^{n−½} − 2 Q_n(∇V(q̂^n))
  // with the free flight q̂^n sampled at the quadrature nodes. Writes only the *Next_ levels.
  void attempt(double h) noexcept {
    qNext_ = q_ + h * v_;
    flightImpulse(
        quadrature_, q_, qNext_, h,
        [this](const Vector& x, Vector& grad) { system_.gradient(x, grad); }, x_, grad_, force_);
    forces_ += quadrature_.count;
    pNext_ = pPrev_ - 2.0 * force_;
    system_.applyInverseMass(pNext_, vNext_);
    potentialNext_ = system_.potential(qNext_);
    pseudoNext_ = potentialNext_ + 0.5 * p_.dot(vNext_);  // [M (13)] at n + 1
  }

  S system_;
  Quadrature quadrature_;
  AdaptiveStep adaptive_;
  double maxStep_, step_;
  Vector q_, qNext_, pPrev_, p_, pNext_;  // q^n, q^{n+1}, p^{n−½}, p^{n+½}, p^{n+3/2}
  Vector vPrev_, v_, vNext_;              // M⁻¹ of the three momenta
  Vector x_, grad_, force_;               // a node on the free flight, ∇V there, Q_n
  double potential_ = 0.0, pseudoEnergy_ = 0.0;
  double potentialNext_ = 0.0, pseudoNext_ = 0.0, gapNext_ = 0.0;
  double time_ = 0.0, lastStep_ = 0.0;
  double minUsed_ = std::numeric_limits<double>::infinity(), maxUsed_ = 0.0;
  double worstGapRatio_ = 0.0;
  long n_ = 0, forces_ = 0, rejected_ = 0;
  int calm_ = 0;
};

}  // namespace hamiltone
