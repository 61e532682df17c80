// Marazzato et al.'s asynchronous slow/fast scheme [M (21)–(25)]: fast and mixed particles step
// at h_F, slow ones at h_S = K h_F, each on its own free flight; pseudo-energy (26).
#pragma once

#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "schemes/hamiltonian.h"
#include "schemes/marazzato.h"
#include "schemes/quadrature.h"
#include "util/format_number.h"

namespace hamiltone {

// A system split as in [M §4.1]: V(q) = V_S(q_S) + V_M(q_M, q_S) + V_F(q_F, q_M), diagonal M.
// The particles are partitioned into fast F, mixed M and slow S index sets; `coupledSlow` is the
// part of S that V_M depends on (the slow side of the interface). The add…Gradient functions add
// w ∂V_X/∂q_i to out_i for the particles V_X depends on, leaving the other entries alone, and
// read q only there: V_F reads F ∪ M, V_M reads M ∪ coupledSlow, V_S reads S. An interaction
// is one term of V (a spring); the counts make the force-evaluation unit of [M §4.3.1].
// Nothing here may allocate.
template <class S>
concept SlowFastSystem = requires(const S& s, const Vector& q, Vector& out, double w) {
  { s.size() } -> std::convertible_to<Eigen::Index>;
  { s.inverseMass() } -> std::convertible_to<const Vector&>;
  { s.fastParticles() } -> std::convertible_to<std::span<const Eigen::Index>>;
  { s.mixedParticles() } -> std::convertible_to<std::span<const Eigen::Index>>;
  { s.slowParticles() } -> std::convertible_to<std::span<const Eigen::Index>>;
  { s.coupledSlowParticles() } -> std::convertible_to<std::span<const Eigen::Index>>;
  { s.fastPotential(q) } -> std::convertible_to<double>;   // V_F
  { s.mixedPotential(q) } -> std::convertible_to<double>;  // V_M
  { s.slowPotential(q) } -> std::convertible_to<double>;   // V_S
  s.addFastGradient(q, w, out);
  s.addMixedGradient(q, w, out);
  s.addSlowGradient(q, w, out);
  { s.fastInteractions() } -> std::convertible_to<long>;
  { s.mixedInteractions() } -> std::convertible_to<long>;
  { s.slowInteractions() } -> std::convertible_to<long>;
};

// A slow/fast system seen whole, V = V_S + V_M + V_F with K = 0, for the synchronous scheme
// Marazzato<WholeSystem<S>> — the reference the asynchronous scheme is measured against.
template <SlowFastSystem S>
class WholeSystem {
 public:
  static constexpr bool hasStiffness = false;
  explicit WholeSystem(S system) : system_(std::move(system)) {}

  Eigen::Index size() const { return system_.size(); }
  const Vector& inverseMass() const { return system_.inverseMass(); }
  void applyStiffness(const Vector&, Vector& out) const { out.setZero(); }  // K = 0
  double stiffnessEigenvalueMax() const { return 0.0; }
  double splitPotential(const Vector& q) const {
    return system_.slowPotential(q) + system_.mixedPotential(q) + system_.fastPotential(q);
  }
  double splitGradient(const Vector& q, Vector& grad) const {
    grad.setZero();
    system_.addFastGradient(q, 1.0, grad);
    system_.addMixedGradient(q, 1.0, grad);
    system_.addSlowGradient(q, 1.0, grad);
    return splitPotential(q);
  }
  long interactionCount() const {
    return system_.fastInteractions() + system_.mixedInteractions() + system_.slowInteractions();
  }
  const S& parts() const { return system_; }

 private:
  S system_;
};

// State at the coarse node t^n = n h_S: q^n (q^{n,0} for F ∪ M); for S the momenta p^{n−½},
// p^{n+½}, for F ∪ M p^{n,−½} = p^{n−1,K−½} and p^{n,½}. step() advances one coarse step, K fine
// ones. Started like [M 7]: p^{−½} = p^{½} = p(0) for every particle, so H̃^0 = H(0).
template <SlowFastSystem S>
class AsynchronousMarazzato {
 public:
  // Throws std::invalid_argument for a non-positive h_F, a ratio K < 1, a partition that is not
  // one of the particles, or a start of the wrong size.
  AsynchronousMarazzato(S system, double fineStep, long ratio, const InitialState& start,
                        QuadratureRule rule)
      : system_(std::move(system)),
        fineStep_(fineStep),
        coarseStep_(static_cast<double>(ratio) * fineStep),
        ratio_(ratio),
        quadrature_(quadrature(rule)) {
    if (!(fineStep > 0.0) || !std::isfinite(fineStep))
      throw std::invalid_argument("h_F = " + formatNumber(fineStep) + ": must be finite and > 0");
    if (ratio < 1)
      throw std::invalid_argument("K = h_S / h_F = " + std::to_string(ratio) +
                                  ": must be an integer >= 1");
    const Eigen::Index n = system_.size();
    checkInitialState(start, n);
    checkPartition(n);
    for (auto part : {system_.fastParticles(), system_.mixedParticles()})
      fastAndMixed_.insert(fastAndMixed_.end(), part.begin(), part.end());
    for (Vector* v : {&qNext_, &x_, &force_}) v->setZero(n);
    q_ = start.q;
    pPrev_ = start.p;  // [M 7]
    p_ = start.p;
    const long nodes = nodesPerInterval(quadrature_);
    fineEvaluations_ = nodes * (system_.fastInteractions() + system_.mixedInteractions());
    coarseEvaluations_ = nodes * system_.slowInteractions();
  }

  void step() noexcept {
    const Vector& invMass = system_.inverseMass();
    const auto slow = system_.slowParticles();
    const auto coupled = system_.coupledSlowParticles();
    // Slow free flight (24) over [t^n, t^{n+1}]: its end q_S^{n+1}, (25a).
    for (Eigen::Index i : slow) {
      qNext_[i] = q_[i] + coarseStep_ * (invMass[i] * p_[i]);
      force_[i] = 0.0;
    }
    for (long m = 0; m < ratio_; ++m) {
      for (Eigen::Index i : fastAndMixed_) {
        qNext_[i] = q_[i] + fineStep_ * (invMass[i] * p_[i]);  // (21a)
        force_[i] = 0.0;
      }
      for (int j = 0; j < quadrature_.count; ++j) {
        const double theta = quadrature_.node[j];
        const double w = fineStep_ * quadrature_.weight[j];
        for (Eigen::Index i : fastAndMixed_)
          x_[i] = (1.0 - theta) * q_[i] + theta * qNext_[i];  // (22)
        // The slow flight (24) at t^{n,m} + θ h_F, a fraction s of the coarse interval.
        const double s = (static_cast<double>(m) + theta) / static_cast<double>(ratio_);
        for (Eigen::Index i : coupled) x_[i] = (1.0 - s) * q_[i] + s * qNext_[i];
        system_.addFastGradient(x_, w, force_);   // (21b), (23)
        system_.addMixedGradient(x_, w, force_);  // (23); its slow side summed over m in (25b)
      }
      for (Eigen::Index i : fastAndMixed_) {
        const double next = pPrev_[i] - 2.0 * force_[i];  // (21b), (23)
        pPrev_[i] = p_[i];
        p_[i] = next;
        q_[i] = qNext_[i];
      }
      evaluations_ += fineEvaluations_;
    }
    for (int j = 0; j < quadrature_.count; ++j) {
      const double theta = quadrature_.node[j];
      for (Eigen::Index i : slow) x_[i] = (1.0 - theta) * q_[i] + theta * qNext_[i];  // (24)
      system_.addSlowGradient(x_, coarseStep_ * quadrature_.weight[j], force_);       // (25b)
    }
    for (Eigen::Index i : slow) {
      const double next = pPrev_[i] - 2.0 * force_[i];  // (25b)
      pPrev_[i] = p_[i];
      p_[i] = next;
      q_[i] = qNext_[i];  // (25a)
    }
    evaluations_ += coarseEvaluations_;
    ++n_;
  }

  // Pseudo-energy (26) at t^n: potential V_S + V_M + V_F at q^n, "kinetic"
  // Σ_S p^{n−½}·p^{n+½}/2m + Σ_{F∪M} p^{n,−½}·p^{n,½}/2m (no sign).
  Energy energy() const {
    Energy e;
    e.potential =
        system_.slowPotential(q_) + system_.mixedPotential(q_) + system_.fastPotential(q_);
    e.kinetic = 0.5 * pPrev_.dot(system_.inverseMass().cwiseProduct(p_));
    return e;
  }

  // Force evaluations so far, in the unit of [M §4.3.1] (see nodesPerInterval): per fine step
  // (V_F and V_M interactions) × nodes, per coarse step V_S interactions × nodes.
  long forceEvaluations() const { return evaluations_; }

  long stepIndex() const { return n_; }
  double time() const { return static_cast<double>(n_) * coarseStep_; }
  double fineStep() const { return fineStep_; }
  double coarseStep() const { return coarseStep_; }
  long ratio() const { return ratio_; }
  const Vector& q() const { return q_; }
  const Vector& p() const { return p_; }
  const Vector& pPrevious() const { return pPrev_; }
  double dissipated() const { return 0.0; }
  const S& system() const { return system_; }
  const Quadrature& rule() const { return quadrature_; }

 private:
  // Every particle in exactly one of F, M, S; coupledSlow within S.
  void checkPartition(Eigen::Index n) const {
    std::vector<int> owner(static_cast<size_t>(n), -1);
    int part = 0;
    for (auto set : {system_.fastParticles(), system_.mixedParticles(), system_.slowParticles()}) {
      for (Eigen::Index i : set) {
        if (i < 0 || i >= n || owner[static_cast<size_t>(i)] != -1)
          throw std::invalid_argument("particle " + std::to_string(i) +
                                      " is outside 0…size−1 or in two of F, M, S");
        owner[static_cast<size_t>(i)] = part;
      }
      ++part;
    }
    for (int o : owner)
      if (o == -1) throw std::invalid_argument("a particle is in none of F, M, S");
    for (Eigen::Index i : system_.coupledSlowParticles())
      if (i < 0 || i >= n || owner[static_cast<size_t>(i)] != 2)
        throw std::invalid_argument("coupled particle " + std::to_string(i) + " is not slow");
  }

  S system_;
  double fineStep_, coarseStep_;  // h_F, h_S = K h_F
  long ratio_;                    // K
  Quadrature quadrature_;
  std::vector<Eigen::Index> fastAndMixed_;  // F ∪ M
  Vector q_, qNext_;  // q^n (q^{n,m} on F ∪ M), the end of the current free flight
  Vector pPrev_, p_;  // p^{·−½}, p^{·+½} at each particle's own level
  Vector x_, force_;  // a node on the free flights, Σ w ∂V/∂q there
  long fineEvaluations_ = 0, coarseEvaluations_ = 0, evaluations_ = 0;
  long n_ = 0;
};

}  // namespace hamiltone
