// BDZ's explicit exactly energy-conserving SAV schemes: non-split (27), split-potential (38).
#pragma once

#include <cmath>
#include <utility>

#include "schemes/hamiltonian.h"
#include "schemes/linear_loss.h"
#include "schemes/step_parameters.h"

namespace hamiltone {

// Which part of the potential is quadratised: all of V (27), or V' only with K q taken
// linearly (38). Under V' ≡ 0 the split form is exactly Störmer–Verlet (§3.5).
enum class SavForm { nonSplit, split };

// Time levels: after construction and after every step the scheme holds q^n, q^{n+1} and
// ψ^{n+½} and reports level n — t = n k, q^n, and the energy H^{n+½} of (36)/(41).
// The reported potential excludes the gauge shift ε: ½ψ² − ε ≈ V'(q^{n+½}).
// Loss (linear_loss.h): σ0 centred as in (49), so the left matrix (1+σ0k) I + αβᵀ is still
// inverted by Sherman–Morrison; σ1 explicit. The balance (50) holds exactly (dissipated()).
template <HamiltonianSystem S, SavForm form>
class SavScheme {
  static constexpr bool splitK = form == SavForm::split && S::hasStiffness;

 public:
  SavScheme(S system, const StepParameters& params, const InitialState& start)
      : system_(std::move(system)), params_(params), loss_(system_, params) {
    checkStepParameters(params_, /*hasEpsilon=*/true);
    const Eigen::Index n = system_.size();
    checkInitialState(start, n);
    if constexpr (splitK) checkStabilityBound();
    for (Vector* v : {&prev_, &curr_, &next_, &grad_, &kq_}) v->setZero(n);
    // (21); leaves K q^0 in kq_.
    prev_ = start.q;
    fullGradient(system_, prev_, grad_, kq_);
    loss_.taylorStart(system_, start, grad_, curr_);
    // ψ^{½} = sqrt(2 (V'(q^{½}) + ε)) with q^{½} = (q^0 + q^1)/2: second order, like (32).
    next_ = 0.5 * (prev_ + curr_);
    psi_ = std::sqrt(2.0 * (quadratisedPotential(next_) + params_.epsilon));
  }

  // One step of (38) [(27) when nonSplit]: q^{n+1} from q^n, q^{n−1}, ψ^{n−½} by (40) and
  // Sherman–Morrison (33), then ψ^{n+½} by (38c). In the paper's naming the members hold
  // q^{n−1} = prev_, q^n = curr_, q^{n+1} = next_ during the step.
  void step() noexcept {
    if (loss_.any())
      stepInternal<true>();
    else
      stepInternal<false>();
  }

  // (41) [(36) when nonSplit], at level n: kinetic ½(δq)ᵀM(δq)/k², potential ½ q^{n+1}ᵀK q^n + ½ψ²
  // − ε.
  Energy energy() const {
    Energy e;
    e.kinetic = intervalKineticEnergy(system_.inverseMass(), prev_, curr_, params_.k) +
                loss_.kineticCorrection(system_, prev_, curr_);
    e.potential = 0.5 * psi_ * psi_ - params_.epsilon;
    if constexpr (splitK) e.potential += 0.5 * curr_.dot(kq_);
    return e;
  }

  long stepIndex() const { return n_; }
  double time() const { return static_cast<double>(n_) * params_.k; }
  const Vector& q() const { return prev_; }
  const Vector& qNext() const { return curr_; }
  double psi() const { return psi_; }  // ψ^{n+½}
  // Energy taken by the loss since the start: energy().total() + dissipated() is constant (50).
  double dissipated() const { return dissipated_; }
  const S& system() const { return system_; }
  const StepParameters& parameters() const { return params_; }

 private:
  // The step, with the loss branch lifted out of the loops. Two passes over the grid: the first
  // gathers the dot products that (33) needs, the second writes q^{n+1}. The reductions are
  // vectorised (`omp simd`, with -fopenmp-simd): a fixed, deterministic summation order.
  template <bool lossy>
  void stepInternal() noexcept {
    const double k = params_.k;
    const double up = 1.0 + params_.sigma0 * k;
    const double down = 1.0 - params_.sigma0 * k;
    const double kk = k * k;
    const Eigen::Index n = system_.size();
    const double* minv = system_.inverseMass().data();
    const double* qm = prev_.data();
    const double* q = curr_.data();
    double* qp = next_.data();
    const double* gv = grad_.data();
    const double* kq = kq_.data();

    // (39): g = ∇V' / sqrt(2 (V' + ε)), g = 0 where V' + ε = 0. grad_ holds ∇V', g = s ∇V'.
    const double shifted = gradient() + params_.epsilon;
    const double s = shifted > 0.0 ? 1.0 / std::sqrt(2.0 * shifted) : 0.0;
    const double h = 0.5 * k * s;  // α = h M⁻¹∇V',  β = h ∇V'   (31)

    const double twoSigma1K = 2.0 * params_.sigma1 * k;
    const double* cq = lossy ? loss_.frequencyForce(system_, curr_, prev_).data() : nullptr;

    double gq = 0.0, gqm = 0.0, gMg = 0.0, gMKq = 0.0, gMCq = 0.0;
#pragma omp simd reduction(+ : gq, gqm, gMg, gMKq, gMCq)
    for (Eigen::Index i = 0; i < n; ++i) {
      gq += gv[i] * q[i];
      gqm += gv[i] * qm[i];
      gMg += gv[i] * minv[i] * gv[i];
      if constexpr (splitK) gMKq += gv[i] * (minv[i] * kq[i]);
      if constexpr (lossy) gMCq += gv[i] * (minv[i] * cq[i]);
    }
    const double btqm = h * gqm;     // βᵀ q^{n−1}
    const double bta = h * h * gMg;  // βᵀ α
    // (40) with the loss (49) and the σ1 term:
    //   b = (2I − k²M⁻¹K) q^n − 2kψ α − ((1−σ0k) I − αβᵀ) q^{n−1} − 2σ1k M⁻¹C (q^n − q^{n−1}),
    // of which Sherman–Morrison (33) needs βᵀb, here assembled from the dot products above.
    const double twoKPsi = 2.0 * k * psi_;
    const double gb =
        2.0 * gq - twoKPsi * h * gMg - down * gqm + h * gMg * btqm - kk * gMKq - twoSigma1K * gMCq;
    const double coef = h * gb / (up + bta);  // βᵀb / (1+σ0k + βᵀα)

    // (33) with A0 = (1+σ0k) I: q^{n+1} = (b − α coef) / (1+σ0k); α's multiples collected in c.
    const double c = h * (btqm - twoKPsi - coef);
    const double invUp = 1.0 / up;
    double gdq = 0.0;
#pragma omp simd reduction(+ : gdq)
    for (Eigen::Index i = 0; i < n; ++i) {
      double b = 2.0 * q[i] - down * qm[i];
      if constexpr (splitK) b -= kk * (minv[i] * kq[i]);
      if constexpr (lossy) b -= twoSigma1K * (minv[i] * cq[i]);
      const double x = (b + c * (minv[i] * gv[i])) * invUp;
      qp[i] = x;
      gdq += gv[i] * (x - qm[i]);
    }
    psi_ += 0.5 * s * gdq;                                                         // (38c)
    if constexpr (lossy) dissipated_ += loss_.dissipation(system_, next_, prev_);  // (50)

    prev_.swap(curr_);
    curr_.swap(next_);
    ++n_;
  }

  // (44): k <= 2 / sqrt(λmax(M^-½ K M^-½)), else the energy (41) has no sign and no bound;
  // with σ1 > 0 the bound of maxStableStep.
  void checkStabilityBound() const {
    const double lambda = system_.stiffnessEigenvalueMax();
    if (!(lambda >= 0.0) || !std::isfinite(lambda))
      throw std::invalid_argument("stiffness eigenvalue bound " + formatNumber(lambda) +
                                  " is not a finite number >= 0");
    double lambdaL = 0.0;
    if constexpr (HasLossOperator<S>) lambdaL = system_.lossOperatorEigenvalueMax();
    const double kMax = maxStableStep(lambda, lambdaL, params_.sigma1);
    if (params_.k > kMax)
      throw std::invalid_argument(
          "time step k = " + formatNumber(params_.k) +
          " breaks the stability bound (44) of the split scheme: k <= " + formatNumber(kMax));
  }

  // The potential that ψ quadratises: V' for (38), the whole V for (27).
  double quadratisedPotential(const Vector& q) {
    if constexpr (form == SavForm::split) return system_.splitPotential(q);
    return fullPotential(system_, q, kq_);
  }

  // Its gradient at q^n into grad_ (and K q^n into kq_ where K is taken linearly); returns it.
  double gradient() noexcept {
    if constexpr (form == SavForm::nonSplit) return fullGradient(system_, curr_, grad_, kq_);
    if constexpr (splitK) system_.applyStiffness(curr_, kq_);
    return system_.splitGradient(curr_, grad_);
  }

  S system_;
  StepParameters params_;
  LinearLoss<S> loss_;
  Vector prev_, curr_, next_;  // q^n, q^{n+1}, workspace; rotated by swapping
  Vector grad_, kq_;           // ∇V' (∇V) and K q at the newest level a step used
  double psi_ = 0.0;           // ψ^{n+½}
  double dissipated_ = 0.0;
  long n_ = 0;
};

template <HamiltonianSystem S>
using NonSplitSav = SavScheme<S, SavForm::nonSplit>;  // (27): unconditionally stable
template <HamiltonianSystem S>
using SplitSav = SavScheme<S, SavForm::split>;  // (38): stable under (44)

}  // namespace hamiltone
