// Störmer–Verlet (20) with the Taylor start (21): the reference, and the baseline for cost.
#pragma once

#include <utility>

#include "schemes/hamiltonian.h"
#include "schemes/linear_loss.h"
#include "schemes/step_parameters.h"

namespace hamiltone {

// Time levels: after construction and after every step the scheme holds q^n and q^{n+1} and
// reports level n — t = n k, q^n, and the energy H^{n+½} of the interval [t^n, t^{n+1}].
// Loss: as the split scheme's (linear_loss.h), so that with V' ≡ 0 this is exactly (38).
template <HamiltonianSystem S>
class StormerVerlet {
 public:
  StormerVerlet(S system, const StepParameters& params, const InitialState& start)
      : system_(std::move(system)), params_(params), loss_(system_, params) {
    checkStepParameters(params_, /*hasEpsilon=*/false);
    const Eigen::Index n = system_.size();
    checkInitialState(start, n);
    for (Vector* v : {&prev_, &curr_, &next_, &grad_, &kq_}) v->setZero(n);
    prev_ = start.q;
    vPrime_ = gradient(prev_);
    loss_.taylorStart(system_, start, grad_, curr_);  // (21)
  }

  void step() noexcept {
    const double k = params_.k;
    const double invUp = 1.0 / (1.0 + params_.sigma0 * k);
    const double down = 1.0 - params_.sigma0 * k;
    const double twoSigma1K = 2.0 * params_.sigma1 * k;
    const Vector& minv = system_.inverseMass();
    vPrime_ = gradient(curr_);
    const Vector& cq = loss_.frequencyForce(system_, curr_, prev_);
    // (20) with the loss: (1+σ0k) q^{n+1} = 2q^n − (1−σ0k) q^{n−1} − k² M⁻¹∇V(q^n)
    //                                        − 2σ1k M⁻¹C (q^n − q^{n−1})
    if (params_.sigma1 > 0.0)
      next_ = (2.0 * curr_ - down * prev_ - (k * k) * minv.cwiseProduct(grad_) -
               twoSigma1K * minv.cwiseProduct(cq)) *
              invUp;
    else
      next_ = (2.0 * curr_ - down * prev_ - (k * k) * minv.cwiseProduct(grad_)) * invUp;
    if (loss_.any() && params_.trackDissipation)
      dissipated_ += loss_.dissipation(system_, next_, prev_);
    prev_.swap(curr_);
    curr_.swap(next_);
    ++n_;
  }

  // (41) with ψ = 0, plus V'(q^n): the energy SV would conserve were V' ≡ 0.
  Energy energy() const {
    Energy e;
    e.kinetic = intervalKineticEnergy(system_.inverseMass(), prev_, curr_, params_.k) +
                loss_.kineticCorrection(system_, prev_, curr_);
    e.potential = vPrime_;
    if constexpr (S::hasStiffness) e.potential += 0.5 * curr_.dot(kq_);
    return e;
  }

  long stepIndex() const { return n_; }
  double time() const { return static_cast<double>(n_) * params_.k; }
  const Vector& q() const { return prev_; }
  const Vector& qNext() const { return curr_; }
  // Energy taken by the loss since the start: energy().total() + dissipated() is the energy at n =
  // 0.
  double dissipated() const { return dissipated_; }
  const S& system() const { return system_; }
  const StepParameters& parameters() const { return params_; }

 private:
  // ∇V(q) = K q + ∇V'(q) into grad_, K q into kq_; returns V'(q).
  double gradient(const Vector& q) noexcept {
    const double v = system_.splitGradient(q, grad_);
    if constexpr (S::hasStiffness) {
      system_.applyStiffness(q, kq_);
      grad_ += kq_;
    }
    return v;
  }

  S system_;
  StepParameters params_;
  LinearLoss<S> loss_;
  Vector prev_, curr_, next_;  // q^n, q^{n+1}, workspace; rotated by swapping
  Vector grad_, kq_;           // ∇V and K q at the newest level a step used
  double vPrime_ = 0.0;        // V'(q^n)
  double dissipated_ = 0.0;
  long n_ = 0;
};

}  // namespace hamiltone
