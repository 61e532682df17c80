// Marazzato, Ern, Mariotti & Monasse's explicit scheme: BDZ (22) = [M 6], forces integrated
// over the free flight by a symmetric quadrature.
#pragma once

#include <utility>

#include "schemes/hamiltonian.h"
#include "schemes/quadrature.h"
#include "schemes/step_parameters.h"

namespace hamiltone {

// [M (9)]: force = Q_n(∇V(q̂^n)) = h Σ_i w_i ∇V((1 − θ_i) q^n + θ_i q^{n+1}), the impulse over the
// free flight from q^n to q^{n+1}; `gradient(x, grad)` writes ∇V(x). x and grad are workspace.
template <class Gradient>
void flightImpulse(const Quadrature& rule, const Vector& q, const Vector& qNext, double h,
                   Gradient&& gradient, Vector& x, Vector& grad, Vector& force) {
  force.setZero();
  for (int i = 0; i < rule.count; ++i) {
    const double theta = rule.node[i];
    x = (1.0 - theta) * q + theta * qNext;
    gradient(x, grad);
    force += (h * rule.weight[i]) * grad;
  }
}

// Quadrature nodes computed anew per interval in [M §4.3.1]'s count: a rule with nodes at both
// ends of the interval (Gauss–Lobatto) needs n − 1, as its end node is the next interval's start
// on the same continuous free flight; a Gauss–Legendre rule needs all n.
inline long nodesPerInterval(const Quadrature& rule) {
  for (int i = 0; i < rule.count; ++i)
    if (rule.node[i] == 0.0) return rule.count - 1;
  return rule.count;
}

// State at level n: q^n, p^{n−½}, p^{n+½}; reports t = n k, q^n and the pseudo-energy (13)
//   H̃^n = V(q^n) + ½ (p^{n−½})ᵀ M⁻¹ p^{n+½}
// (kinetic = the second term, which has no sign), and the discrete energy (17) on request.
// Started by [M 7]: p^{−½} = p^{½} = p(0), so H̃^0 = H(0) exactly. Lossless, as in the paper.
template <HamiltonianSystem S>
class Marazzato {
 public:
  Marazzato(S system, const StepParameters& params, const InitialState& start, QuadratureRule rule)
      : system_(std::move(system)), params_(params), quadrature_(quadrature(rule)) {
    checkStepParameters(params_, /*hasEpsilon=*/false);
    if (params_.sigma0 != 0.0)
      throw std::invalid_argument("loss sigma0 = " + formatNumber(params_.sigma0) +
                                  ": Marazzato's scheme is lossless here; use sigma0 = 0");
    const Eigen::Index n = system_.size();
    checkInitialState(start, n);
    for (Vector* v : {&q_, &qNext_, &pPrev_, &p_, &pNext_, &x_, &grad_, &force_, &kq_})
      v->setZero(n);
    q_ = start.q;
    pPrev_ = start.p;  // [M 7]
    p_ = start.p;
  }

  // (22) / [M 6]: q^{n+1} = q^n + k M⁻¹ p^{n+½};  p^{n+3/2} = p^{n−½} − 2 Q_n(∇V(q̂^n(t)))
  // with the free flight q̂^n(t) = q^n + (t − t^n) M⁻¹ p^{n+½}, sampled at the nodes [M 9].
  void step() noexcept {
    const double k = params_.k;
    qNext_ = q_ + k * system_.inverseMass().cwiseProduct(p_);
    flightImpulse(
        quadrature_, q_, qNext_, k,
        [this](const Vector& x, Vector& grad) { fullGradient(system_, x, grad, kq_); }, x_, grad_,
        force_);
    pNext_ = pPrev_ - 2.0 * force_;
    // rotate: p^{n−½} ← p^{n+½} ← p^{n+3/2},  q^n ← q^{n+1}
    pPrev_.swap(p_);
    p_.swap(pNext_);
    q_.swap(qNext_);
    ++n_;
  }

  // Pseudo-energy (13): potential V(q^n), "kinetic" ½ (p^{n−½})ᵀ M⁻¹ p^{n+½}.
  Energy energy() const {
    Energy e;
    e.potential = fullPotential(system_, q_, kq_);
    e.kinetic = 0.5 * pPrev_.dot(system_.inverseMass().cwiseProduct(p_));
    return e;
  }

  // Discrete energy (17): V(q^n) + ⅛ (p^{n−½} + p^{n+½})ᵀ M⁻¹ (p^{n−½} + p^{n+½}) >= H̃^n, (18).
  double discreteEnergy() const {
    return fullPotential(system_, q_, kq_) +
           0.125 * ((pPrev_ + p_).array().square() * system_.inverseMass().array()).sum();
  }

  // Force evaluations so far in [M §4.3.1]'s unit, one interaction (a term of V) at one node:
  // steps × nodesPerInterval × interactions, the latter the system's interactionCount() if it
  // has one, else one per coordinate.
  long forceEvaluations() const {
    long interactions = static_cast<long>(system_.size());
    if constexpr (requires { system_.interactionCount(); })
      interactions = system_.interactionCount();
    return n_ * nodesPerInterval(quadrature_) * interactions;
  }

  long stepIndex() const { return n_; }
  double time() const { return static_cast<double>(n_) * params_.k; }
  const Vector& q() const { return q_; }
  const Vector& p() const { return p_; }              // p^{n+½}
  const Vector& pPrevious() const { return pPrev_; }  // p^{n−½}
  double dissipated() const { return 0.0; }
  const S& system() const { return system_; }
  const StepParameters& parameters() const { return params_; }
  const Quadrature& rule() const { return quadrature_; }

 private:
  S system_;
  StepParameters params_;
  Quadrature quadrature_;
  Vector q_, qNext_, pPrev_, p_, pNext_;  // q^n, q^{n+1}, p^{n−½}, p^{n+½}, p^{n+3/2}
  Vector x_, grad_, force_;               // a node on the free flight, ∇V there, Q_n
  mutable Vector kq_;                     // K q, scratch of the potential evaluations
  long n_ = 0;
};

}  // namespace hamiltone
