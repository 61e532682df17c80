// BDZ's explicit exactly energy-conserving SAV schemes: non-split (27), split-potential (38).
#pragma once

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <utility>

#include "kernels/kernels.h"
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
// A PartitionedPotential gets one ψ_j per part (split form only): the left matrix is
// (1+σ0k) I + Σ_j α_j β_jᵀ, inverted by Woodbury with a P×P solve; the energy has Σ_j ½ψ_j².
template <HamiltonianSystem S, SavForm form>
class SavScheme {
  static constexpr bool splitK = form == SavForm::split && S::hasStiffness;
  static constexpr bool partitioned = form == SavForm::split && PartitionedPotential<S>;
  static constexpr int parts = [] {
    if constexpr (partitioned) return S::potentialParts;
    return 1;
  }();
  // A system that names each part's support (partSupport: the coordinates where ∇V'_j may be
  // nonzero, empty for all of them) with part 0 dense and the others sparse: see sparseDots.
  static constexpr bool sparseCapable = partitioned && requires(const S& s) { s.partSupport(0); };
  using Small = Eigen::Matrix<double, parts, parts>;
  using SmallVector = Eigen::Matrix<double, parts, 1>;

 public:
  SavScheme(S system, const StepParameters& params, const InitialState& start)
      : system_(std::move(system)), params_(params), loss_(system_, params) {
    checkStepParameters(params_, /*hasEpsilon=*/true);
    const Eigen::Index n = system_.size();
    checkInitialState(start, n);
    if constexpr (splitK) checkStabilityBound();
    for (Vector* v : {&prev_, &curr_, &next_, &kq_, &force_, &extra_}) v->setZero(n);
    for (Vector& g : grads_) g.setZero(n);
    // (21); leaves K q^0 in kq_.
    prev_ = start.q;
    fullGradient(system_, prev_, grads_[0], kq_);
    loss_.taylorStart(system_, start, grads_[0], curr_);
    // ψ^{½} = sqrt(2 (V'(q^{½}) + ε)) with q^{½} = q(k/2) + O(k³), the Taylor start (21) taken to
    // half a step: q^0 + (k/2) v^0 + (k²/8) a^0 with a^0 = 2(q^1 − q^0 − k v^0)/k² (loss included)
    // is (3q^0 + q^1)/4 + (k/4) v^0. The mean (q^0 + q^1)/2 is off by (k²/8) a^0, an error the
    // exactly conserved energy then keeps for the whole run: on the FPU chain at α = 100 it made
    // (38) 9× less accurate than Störmer–Verlet, where BDZ Fig. 3 has the two track each other.
    next_ = 0.75 * prev_ + 0.25 * curr_ +
            (0.25 * params_.k) * system_.inverseMass().cwiseProduct(start.p);
    for (int j = 0; j < parts; ++j)
      psi_[j] = std::sqrt(2.0 * (quadratisedPotential(j, next_) + params_.epsilon));
    if constexpr (sparseCapable) {
      sparse_ = system_.partSupport(0).empty();
      for (int j = 1; j < parts; ++j) sparse_ = sparse_ && !system_.partSupport(j).empty();
    }
  }

  // One step of (38) [(27) when nonSplit]: q^{n+1} from q^n, q^{n−1}, ψ^{n−½} by (40) and
  // Sherman–Morrison (33), then ψ^{n+½} by (38c). In the paper's naming the members hold
  // q^{n−1} = prev_, q^n = curr_, q^{n+1} = next_ during the step.
  void step() noexcept {
    if (loss_.any() || forced_ || damped_)
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
    e.potential = 0.0;
    for (double psi : psi_) e.potential += 0.5 * psi * psi - params_.epsilon;
    if constexpr (splitK) e.potential += 0.5 * curr_.dot(kq_);
    return e;
  }

  // Changes σ0 between steps, e.g. a damper falling on the string: any σ0 >= 0 with σ0 k < 1 keeps
  // the bound (44), which depends on σ1 only. The balance (50) goes on with the new value.
  void setSigma0(double sigma0) noexcept {
    params_.sigma0 = sigma0;
    loss_.setSigma0(sigma0);
  }

  // An external force f (N per coordinate) acting through the next steps: M δtt q = … + f, so b
  // gains k² M⁻¹ f and the energy grows by fᵀ(q^{n+1} − q^{n−1})/2 a step, tallied in supplied()
  // whatever trackDissipation says: H + dissipated − supplied stays constant.
  void setForce(Eigen::Index i, double f) noexcept {
    force_[i] = f;
    forced_ = true;
  }
  void clearForce() noexcept {
    force_.setZero();
    forced_ = false;
  }
  double supplied() const { return supplied_; }

  // A force on a few coordinates (a string's last nodes held by a bridge): as setForce() but
  // without a pass over the grid — b gains k² M⁻¹ f at those coordinates only. Each step takes
  // the values set last (slot 0 … kPointForces−1; an unset slot is 0) and adds their work to
  // supplied().
  static constexpr int kPointForces = 2;
  void setPointForce(int slot, Eigen::Index i, double f) noexcept {
    pointIndex_[slot] = i;
    pointForce_[slot] = f;
  }

  // A dashpot of resistance r (kg/s) on coordinate i — a damper's felt pressing on the string
  // there — acting through the next steps (slot 0 … kPointDampers−1; r = 0 lifts it). Centred:
  //   M δtt q = … − r (q^{n+1} − q^{n−1})/(2k) e_i,                                      (D1)
  // so the left matrix gains d = r k M⁻¹_ii / 2 at (i, i): still diagonal plus Σ α_j β_jᵀ, solved
  // exactly by the same Woodbury with those few diagonal entries changed (stepInternal). Each step
  // takes r/(4k) (q_i^{n+1} − q_i^{n−1})² >= 0 of the energy, tallied in dissipated(): the scheme
  // stays dissipative and stable for any r >= 0.
  static constexpr int kPointDampers = 8;
  // Slots on one coordinate add; an r that is not > 0 (NaN too) lifts the slot.
  void setPointDamper(int slot, Eigen::Index i, double r) noexcept {
    damperIndex_[slot] = i;
    damperR_[slot] = r > 0.0 ? r : 0.0;
    // d = r k M⁻¹_ii / 2 per slot, the slots on one coordinate gathered into the first of them.
    damperD_.fill(0.0);
    damped_ = false;
    for (int m = 0; m < kPointDampers; ++m) {
      if (damperR_[m] == 0.0) continue;
      int first = 0;  // stops at m at the latest
      while (damperIndex_[first] != damperIndex_[m] || damperR_[first] == 0.0) ++first;
      damperD_[first] += 0.5 * damperR_[m] * params_.k * system_.inverseMass()[damperIndex_[m]];
      damped_ = true;
    }
  }

  // Sets coordinate i at levels n and n+1 — a hammer placed and launched, or caught. The caller
  // keeps V' unchanged by it (the coordinate out of contact), so ψ stays consistent; the energy
  // changes by the kinetic energy given or taken, which energy() then reports.
  void setCoordinate(Eigen::Index i, double qn, double qNext) noexcept {
    prev_[i] = qn;
    curr_[i] = qNext;
    prevKept_ = false;
  }

  // Sets the state to q^n = q, q^{n+1} = qNext, `steps` steps on — a state stepped elsewhere (a
  // string's linear tail in its modes, modal_tail.h), whose ψ_j the caller has kept consistent:
  // the parts it leaves are slack or dropped. K q^n is taken again. What the steps taken elsewhere
  // dissipated and were supplied is not in dissipated() and supplied().
  void setLevels(const Vector& q, const Vector& qNext, long steps) noexcept {
    prev_ = q;
    curr_ = qNext;
    n_ += steps;
    prevKept_ = false;
    stiffnessChanged();
  }
  bool damped() const { return damped_; }  // a point damper holds a coordinate (setPointDamper)

  // After a change of K between steps (a string retensioned by the pitch bend): K q^n is taken
  // again, so energy() reports H of the new K on the same state. The difference is the work the
  // change did, which the next steps then conserve.
  void stiffnessChanged() noexcept {
    if constexpr (splitK) system_.applyStiffness(prev_, kq_);
  }

  // Sets ψ_j^{n+½} back to sqrt(2 (V'_j(q^{n+½}) + ε)), q^{n+½} = (q^n + q^{n+1})/2, dropping
  // the O(k²) residual ψ_j keeps once its part goes slack (a hammer after the strike). The
  // energy changes by what the residual held, which energy() then reports.
  void resetPsi(int part) noexcept {
    next_ = 0.5 * (prev_ + curr_);  // next_ is workspace between steps
    psi_[part] = std::sqrt(2.0 * (quadratisedPotential(part, next_) + params_.epsilon));
  }

  // Drops part j's V'_j from the steps — a string gone linear, whose caller has put V''s quadratic
  // part at rest into K (NonlinearString::setLinearised) and takes K q again (stiffnessChanged()):
  // ∇V'_j is no longer taken and ψ_j is set to sqrt(2ε), so that its ½ψ_j² − ε is 0. The energy
  // changes by what ψ_j held, which energy() then reports. With no part loaded a step is then one
  // pass: Störmer–Verlet with the loss (49) and the dampers (D1). restorePart() takes V'_j back,
  // ψ_j from V'_j(q^{n+½}) as resetPsi().
  void dropPart(int part) noexcept requires(form == SavForm::split) {
    dropped_[part] = true;
    grads_[part].setZero();
    psi_[part] = std::sqrt(2.0 * params_.epsilon);
  }
  void restorePart(int part) noexcept requires(form == SavForm::split) {
    dropped_[part] = false;
    resetPsi(part);
  }

  // The instruction set of the one-part passes (default: selectedKernels()).
  void setKernels(const Kernels& kernels) noexcept { kernels_ = &kernels; }

  long stepIndex() const { return n_; }
  double time() const { return static_cast<double>(n_) * params_.k; }
  const Vector& q() const { return prev_; }
  const Vector& qNext() const { return curr_; }
  double psi(int part = 0) const { return psi_[part]; }  // ψ_j^{n+½}
  // Energy taken by the loss since the start: energy().total() + dissipated() is constant (50).
  // Zero when the parameters turned trackDissipation off.
  double dissipated() const { return dissipated_; }
  const S& system() const { return system_; }
  // For a parameter change between steps that the system bounds itself, such as a string's bend
  // within the tension range it was built with: (44) was checked once, at construction.
  S& system() { return system_; }
  const StepParameters& parameters() const { return params_; }

 private:
  // The step, with the loss branch lifted out of the loops. Two passes over the grid: the first
  // gathers the dot products that (33) needs, the second writes q^{n+1}. The reductions are
  // vectorised (`omp simd`, with -fopenmp-simd): a fixed, deterministic summation order.
  template <bool lossy>
  void stepInternal() noexcept {
    // Named one by one, not bound as a structure: the lambda below captures them (Clang before
    // 16 cannot capture structured bindings).
    const StepView v = view();
    const double k = v.k, up = v.up, down = v.down, kk = v.kk;
    const Eigen::Index n = v.n;
    const double *minv = v.minv, *qm = v.qm, *q = v.q;
    double* qp = v.qp;
    const double* kq = kq_.data();

    // K q^n into kq_: with the loss's C(q^n − q^{n−1}) from the same sweep where the model can
    // (HasStiffnessAndLoss), the last step's second difference kept for q^{n−1}.
    const Vector* fusedLoss = nullptr;
    if constexpr (splitK) {
      if constexpr (lossy && HasStiffnessAndLoss<S>) {
        if (params_.sigma1 > 0.0) {
          fusedLoss = &loss_.frequencyForceAndStiffness(system_, curr_, prev_, prevKept_, kq_);
          prevKept_ = true;  // of q^n, the next step's q^{n−1}
        }
      }
      if (!fusedLoss) {
        system_.applyStiffness(curr_, kq_);
        prevKept_ = false;
      }
    }

    // (39): g_j = ∇V'_j / sqrt(2 (V'_j + ε)), g_j = 0 where V'_j + ε = 0; grads_ hold ∇V'_j, so
    // g_j = s_j ∇V'_j, and α_j = h_j M⁻¹∇V'_j, β_j = h_j ∇V'_j   (31).
    // A slack part (V'_j = 0, so ∇V'_j = 0: a hammer off the string) adds nothing to the update;
    // with at most one part under load the scalar one-part passes below serve.
    std::array<const double*, parts> g;
    double s[parts], h[parts];
    int loaded = 0, onlyLoaded = 0;
    for (int j = 0; j < parts; ++j) {
      const double potential = gradient(j);
      const double shifted = potential + params_.epsilon;
      s[j] = shifted > 0.0 ? 1.0 / std::sqrt(2.0 * shifted) : 0.0;
      h[j] = 0.5 * k * s[j];
      g[j] = grads_[j].data();
      if (!dropped_[j] && (potential != 0.0 || parts == 1)) {
        ++loaded;
        onlyLoaded = j;
      }
    }
    const bool onePass = parts == 1 || loaded <= 1;
    // Several parts loaded (a hammer on the string): the sparse ones (a felt's few nodes) are
    // summed and corrected over their own coordinates, the dense one by the one-part kernels.
    const bool sparse = !onePass && sparse_;
    // The loss's σ1 term and the external force enter b alike, b −= M⁻¹ extra_ with
    // extra_ = 2σ1k C(q^n − q^{n−1}) − k² f. Unforced with one part loaded, the kernels scale
    // C(q^n − q^{n−1}) as they read it (the same products, one pass fewer).
    const double* cq = nullptr;
    double cqScale = 1.0;
    if constexpr (lossy) {
      const Vector& lossForce =
          fusedLoss ? *fusedLoss : loss_.frequencyForce(system_, curr_, prev_);
      if (forced_) {
        extra_ = (2.0 * params_.sigma1 * k) * lossForce - kk * force_;
        cq = extra_.data();
      } else if (onePass || sparse) {
        cq = lossForce.data();
        cqScale = 2.0 * params_.sigma1 * k;
      } else {
        extra_ = (2.0 * params_.sigma1 * k) * lossForce;
        cq = extra_.data();
      }
    }

    if (loaded == 0) {
      stepLinear<lossy>(cq, cqScale);
      return;
    }
    if (onePass && !damped_) {
      stepOnePart<lossy>(onlyLoaded, s[onlyLoaded], h[onlyLoaded], cq, cqScale, g[onlyLoaded]);
      return;
    }

    // Pass 1: ∇V'_jᵀ of q^n, q^{n−1}, M⁻¹K q^n, M⁻¹C(q^n − q^{n−1}), and ∇V'_iᵀ M⁻¹ ∇V'_j.
    // With one part loaded (a string off its hammer: nearly every step) the passes are the
    // kernels of the CPU's instruction set (kernels/kernels.h); with several, array reductions.
    double gq[parts] = {}, gqm[parts] = {}, gMKq[parts] = {}, gMCq[parts] = {};  // gMCq: of extra_
    double gMg[parts * parts] = {};
    if (onePass || sparse) {
      const int a = onePass ? onlyLoaded : 0;
      double dots[5];
      kernels_->savDots(n, g[a], q, qm, minv, splitK ? kq : nullptr, lossy ? cq : nullptr, cqScale,
                        dots);
      gq[a] = dots[0], gqm[a] = dots[1], gMKq[a] = dots[2], gMCq[a] = dots[3];
      gMg[a * parts + a] = dots[4];
      if (sparse) sparseDots(g, cq, cqScale, gq, gqm, gMKq, gMCq, gMg);
    } else {
#pragma omp simd reduction(+ : gq[:parts], gqm[:parts], gMKq[:parts], gMCq[:parts], \
                               gMg[:parts * parts])
      for (Eigen::Index i = 0; i < n; ++i) {
        for (int a = 0; a < parts; ++a) {
          const double ga = g[a][i];
          gq[a] += ga * q[i];
          gqm[a] += ga * qm[i];
          if constexpr (splitK) gMKq[a] += ga * (minv[i] * kq[i]);
          if constexpr (lossy) gMCq[a] += ga * (minv[i] * cq[i]);
          for (int b = a; b < parts; ++b) gMg[a * parts + b] += ga * minv[i] * g[b][i];
        }
      }
    }
    // The point forces enter b as k² M⁻¹ f at their coordinates: −gMCq gains k² ∇V'_jᵀ M⁻¹ f.
    for (int p = 0; p < kPointForces; ++p) {
      const Eigen::Index i = pointIndex_[p];
      for (int a = 0; a < parts; ++a) gMCq[a] -= kk * g[a][i] * minv[i] * pointForce_[p];
    }
    // (40) with the loss (49) and the σ1 term:
    //   b = (2I − k²M⁻¹K) q^n − 2k Σ ψ_j α_j − ((1−σ0k) I − Σ α_j β_jᵀ) q^{n−1}
    //       − 2σ1k M⁻¹C (q^n − q^{n−1}),
    // of which Woodbury needs Vᵀb = (β_iᵀ b)_i, assembled from the dot products above.
    // (33) generalised: q^{n+1} = (b − U y) / (1+σ0k), y = ((1+σ0k) I + VᵀU)⁻¹ Vᵀb,
    // U = [α_j], V = [β_j].
    Small vtu;
    SmallVector vtb, bLinear;  // bLinear_j: the weight of α_j in b
    for (int a = 0; a < parts; ++a) {
      bLinear[a] = h[a] * gqm[a] - 2.0 * k * psi_[a];  // β_jᵀ q^{n−1} − 2kψ_j
      for (int b = a; b < parts; ++b) vtu(a, b) = vtu(b, a) = h[a] * h[b] * gMg[a * parts + b];
    }
    for (int a = 0; a < parts; ++a) {
      double gb = 2.0 * gq[a] - down * gqm[a] - kk * gMKq[a] - gMCq[a];
      for (int b = 0; b < parts; ++b)
        gb += bLinear[b] * h[b] * gMg[std::min(a, b) * parts + std::max(a, b)];
      vtb[a] = h[a] * gb;
    }
    // The dampers (D1): D = (1+σ0k) I + Σ_m d_m e_m e_mᵀ, b' = b + Σ_m d_m q_m^{n−1} e_m. Woodbury
    // with D: y = ((1+σ0k) I + W)⁻¹ z, W = (1+σ0k) Vᵀ D⁻¹ U, z = (1+σ0k) Vᵀ D⁻¹ b', and
    // q^{n+1} = D⁻¹ (b' − U y) — the undamped coordinates as before, the damped ones below.
    // bDamped_m: b'_m, b at the damped coordinate before U y.
    double bDamped[kPointDampers] = {};
    if (damped_) {
      for (int m = 0; m < kPointDampers; ++m) {
        const Eigen::Index i = damperIndex_[m];
        const double d = damperD_[m];
        if (d == 0.0) continue;
        double b = dampedBase<lossy>(v, i, d, cq, cqScale);
        for (int a = 0; a < parts; ++a) b += h[a] * minv[i] * g[a][i] * bLinear[a];
        addPointForces(v, i, b);
        bDamped[m] = b;
        const double shrink = up / (up + d) - 1.0;  // (1+σ0k) D⁻¹ − I at i
        for (int a = 0; a < parts; ++a) {
          const double va = h[a] * g[a][i];  // β_a at i
          vtb[a] += va * (d * qm[i] + shrink * b);
          for (int c2 = 0; c2 < parts; ++c2) vtu(a, c2) += shrink * va * h[c2] * minv[i] * g[c2][i];
        }
      }
    }
    const SmallVector y = (Small::Identity() * up + vtu).inverse() * vtb;
    double c[parts];  // the weights of M⁻¹∇V'_j in q^{n+1} (1+σ0k)
    for (int a = 0; a < parts; ++a) c[a] = h[a] * (bLinear[a] - y[a]);

    // Pass 2: q^{n+1}, and ∇V'_jᵀ (q^{n+1} − q^{n−1}) for (38c).
    const double invUp = 1.0 / up;
    auto newPosition = [&](Eigen::Index i, double correction) {
      double b = 2.0 * q[i] - down * qm[i];
      if constexpr (splitK) b -= kk * (minv[i] * kq[i]);
      if constexpr (lossy) b -= minv[i] * cq[i];
      return qp[i] = (b + correction) * invUp;
    };
    double gdq[parts] = {};
    if (onePass || sparse) {
      const int a = onePass ? onlyLoaded : 0;
      gdq[a] = kernels_->savUpdate(n, g[a], q, qm, minv, splitK ? kq : nullptr,
                                   lossy ? cq : nullptr, cqScale, down, kk, c[a], invUp, qp);
      if (sparse) sparseUpdate(g, c, invUp, gdq);
    } else {
#pragma omp simd reduction(+ : gdq[:parts])
      for (Eigen::Index i = 0; i < n; ++i) {
        double correction = 0.0;
        for (int a = 0; a < parts; ++a) correction += c[a] * (minv[i] * g[a][i]);
        const double x = newPosition(i, correction);
        for (int a = 0; a < parts; ++a) gdq[a] += g[a][i] * (x - qm[i]);
      }
    }
    // The point forces' share of q^{n+1}, added after pass 2 wrote the rest.
    for (int p = 0; p < kPointForces; ++p) {
      const Eigen::Index i = pointIndex_[p];
      const double dx = kk * minv[i] * pointForce_[p] * invUp;
      qp[i] += dx;
      for (int a = 0; a < parts; ++a) gdq[a] += g[a][i] * dx;
    }
    // The damped coordinates: D⁻¹ (b' − U y) there, b' − U y = b'_m − Σ_j α_j y_j.
    for (int m = 0; damped_ && m < kPointDampers; ++m) {
      const double d = damperD_[m];
      if (d == 0.0) continue;
      const Eigen::Index i = damperIndex_[m];
      double x = bDamped[m];
      for (int a = 0; a < parts; ++a) x -= h[a] * minv[i] * g[a][i] * y[a];
      x /= up + d;
      const double dx = x - qp[i];
      qp[i] = x;
      for (int a = 0; a < parts; ++a) gdq[a] += g[a][i] * dx;
      tallyDamper(v, i, d, x);
    }
    for (int p = 0; p < kPointForces; ++p)
      supplied_ += 0.5 * pointForce_[p] * (qp[pointIndex_[p]] - qm[pointIndex_[p]]);
    for (int a = 0; a < parts; ++a) psi_[a] += 0.5 * s[a] * gdq[a];  // (38c)
    finishStep<lossy>();
  }

  // The sparse parts' share of pass 1, part 0 dense (its sums from the kernels): each part's dot
  // products over its support, and ∇V'_0ᵀ M⁻¹ ∇V'_a there — outside it ∇V'_a is 0. x read as
  // xScale·x, as the kernels read it.
  void sparseDots(const std::array<const double*, parts>& g, const double* x, double xScale,
                  double* gq, double* gqm, double* gMKq, double* gMCq, double* gMg) const noexcept {
    if constexpr (sparseCapable) {
      const double *minv = system_.inverseMass().data(), *q = curr_.data(), *qm = prev_.data();
      for (int a = 1; a < parts; ++a)
        for (const Eigen::Index i : system_.partSupport(a)) {
          const double ga = g[a][i];
          gq[a] += ga * q[i];
          gqm[a] += ga * qm[i];
          if constexpr (splitK) gMKq[a] += ga * (minv[i] * kq_[i]);
          if (x) gMCq[a] += ga * (minv[i] * (xScale * x[i]));
          gMg[a] += ga * minv[i] * g[0][i];  // (0, a): with the dense part
          for (int b = a; b < parts; ++b) gMg[a * parts + b] += ga * minv[i] * g[b][i];
        }
    }
  }

  // Pass 2's sparse share: after the kernels wrote q^{n+1} with part 0's correction, each sparse
  // part's c_a M⁻¹∇V'_a over its support, part 0's ∇V'_0ᵀ(q^{n+1} − q^{n−1}) brought up to date
  // there, then each sparse part's own sum.
  void sparseUpdate(const std::array<const double*, parts>& g, const double* c, double invUp,
                    double* gdq) noexcept {
    if constexpr (sparseCapable) {
      const double *minv = system_.inverseMass().data(), *qm = prev_.data();
      double* qp = next_.data();
      for (int a = 1; a < parts; ++a)
        for (const Eigen::Index i : system_.partSupport(a)) {
          const double dx = c[a] * (minv[i] * g[a][i]) * invUp;
          qp[i] += dx;
          gdq[0] += g[0][i] * dx;
        }
      for (int a = 1; a < parts; ++a)
        for (const Eigen::Index i : system_.partSupport(a)) gdq[a] += g[a][i] * (qp[i] - qm[i]);
    }
  }

  // The step's constants and its three levels: q^{n−1}, q^n and q^{n+1} being written.
  struct StepView {
    double k, up, down, kk;  // k, 1 + σ0k, 1 − σ0k, k²
    Eigen::Index n;
    const double* minv;
    const double* qm;
    const double* q;
    double* qp;
  };
  StepView view() noexcept {
    const double k = params_.k;
    return {k,
            1.0 + params_.sigma0 * k,
            1.0 - params_.sigma0 * k,
            k * k,
            system_.size(),
            system_.inverseMass().data(),
            prev_.data(),
            curr_.data(),
            next_.data()};
  }

  // After q^{n+1}: the loss's share (50) and the force's work, then the levels move on.
  template <bool lossy>
  void finishStep() noexcept {
    if constexpr (lossy) {
      if (params_.trackDissipation)
        dissipated_ += loss_.dissipation(system_, next_, prev_);  // (50)
      if (forced_) supplied_ += 0.5 * force_.dot(next_ - prev_);  // the work of f over the step
    }
    prev_.swap(curr_);
    curr_.swap(next_);
    ++n_;
  }

  // The step with one part loaded and no damper — a string off its hammer, nearly every step: the
  // Woodbury solve of stepInternal is then one division, y = vᵀb / ((1+σ0k) + vᵀu), and the slack
  // parts, whose ∇V'_j is zero, add nothing (their ψ_j stays as it is).
  template <bool lossy>
  void stepOnePart(int a, double s, double h, const double* cq, double cqScale,
                   const double* g) noexcept {
    const auto [k, up, down, kk, n, minv, qm, q, qp] = view();
    const double* kq = splitK ? kq_.data() : nullptr;
    double dots[5];  // gᵀq, gᵀqm, gᵀM⁻¹Kq, gᵀM⁻¹(extra), gᵀM⁻¹g
    kernels_->savDots(n, g, q, qm, minv, kq, lossy ? cq : nullptr, cqScale, dots);
    double gMCq = dots[3];
    for (int p = 0; p < kPointForces; ++p)
      gMCq -= kk * g[pointIndex_[p]] * minv[pointIndex_[p]] * pointForce_[p];
    const double bLinear = h * dots[1] - 2.0 * k * psi_[a];  // βᵀq^{n−1} − 2kψ
    const double vtu = h * h * dots[4];
    const double vtb =
        h * (2.0 * dots[0] - down * dots[1] - kk * dots[2] - gMCq + bLinear * h * dots[4]);
    const double y = vtb / (up + vtu);  // (33)
    const double invUp = 1.0 / up;
    double gdq = kernels_->savUpdate(n, g, q, qm, minv, kq, lossy ? cq : nullptr, cqScale, down, kk,
                                     h * (bLinear - y), invUp, qp);
    for (int p = 0; p < kPointForces; ++p) {
      const Eigen::Index i = pointIndex_[p];
      const double dx = kk * minv[i] * pointForce_[p] * invUp;
      qp[i] += dx;
      gdq += g[i] * dx;
    }
    for (int p = 0; p < kPointForces; ++p)
      supplied_ += 0.5 * pointForce_[p] * (qp[pointIndex_[p]] - qm[pointIndex_[p]]);
    psi_[a] += 0.5 * s * gdq;  // (38c)
    finishStep<lossy>();
  }

  // (D1)'s b' at a damped coordinate i, but for the parts' terms and the point forces:
  // 2q_i − (1−σ0k) q_i^{n−1} + d q_i^{n−1} − k² M⁻¹(K q)_i − M⁻¹ x_i, x read as xScale·x.
  template <bool lossy>
  double dampedBase(const StepView& v, Eigen::Index i, double d, const double* x,
                    double xScale) const noexcept {
    double b = 2.0 * v.q[i] - v.down * v.qm[i] + d * v.qm[i];
    if constexpr (splitK) b -= v.kk * (v.minv[i] * kq_[i]);
    if constexpr (lossy) b -= xScale * v.minv[i] * x[i];
    return b;
  }
  // The point forces on coordinate i into b: k² M⁻¹ f, slot by slot.
  void addPointForces(const StepView& v, Eigen::Index i, double& b) const noexcept {
    for (int p = 0; p < kPointForces; ++p)
      if (pointIndex_[p] == i) b += v.kk * v.minv[i] * pointForce_[p];
  }
  // The damper's loss over the step at i, q_i^{n+1} = x: r/(4k) Δ², r = 2d/(k M⁻¹_ii)  (D1).
  void tallyDamper(const StepView& v, Eigen::Index i, double d, double x) noexcept {
    if (params_.trackDissipation)
      dissipated_ += d / (2.0 * v.k * v.k * v.minv[i]) * (x - v.qm[i]) * (x - v.qm[i]);
  }

  // The step with no part loaded (V' dropped, or at rest, and the hammer off the string):
  // ∇V' = 0 leaves (40) b / (1+σ0k), one pass; ψ stays as it is. A damped coordinate takes
  // b' / (1+σ0k + d) (D1).
  template <bool lossy>
  void stepLinear(const double* cq, double cqScale) noexcept {
    const StepView v = view();
    const double invUp = 1.0 / v.up;
    const double* kq = splitK ? kq_.data() : nullptr;
    kernels_->linearUpdate(v.n, v.q, v.qm, v.minv, kq, lossy ? cq : nullptr, cqScale, v.down, v.kk,
                           invUp, v.qp);
    for (int p = 0; p < kPointForces; ++p)
      v.qp[pointIndex_[p]] += v.kk * v.minv[pointIndex_[p]] * pointForce_[p] * invUp;
    for (int m = 0; damped_ && m < kPointDampers; ++m) {
      const double d = damperD_[m];
      if (d == 0.0) continue;
      const Eigen::Index i = damperIndex_[m];
      double b = dampedBase<lossy>(v, i, d, cq, cqScale);
      addPointForces(v, i, b);
      const double x = b / (v.up + d);
      v.qp[i] = x;
      tallyDamper(v, i, d, x);
    }
    for (int p = 0; p < kPointForces; ++p)
      supplied_ += 0.5 * pointForce_[p] * (v.qp[pointIndex_[p]] - v.qm[pointIndex_[p]]);
    finishStep<lossy>();
  }

  // (44): k <= 2 / sqrt(λmax(M^-½ K M^-½)), else the energy (41) has no sign and no bound;
  // with σ1 > 0 the bound of maxStableStep.
  void checkStabilityBound() const {
    const double lambda = system_.stiffnessEigenvalueMax();
    if (!(lambda >= 0.0) || !std::isfinite(lambda))
      throw std::invalid_argument("stiffness eigenvalue bound " + formatNumber(lambda) +
                                  " is not a finite number >= 0");
    // A system whose K and C act on blocks apart bounds each block (NonlinearString).
    const double kMax = [&] {
      if constexpr (requires(const S& s) { s.maxStableStep(0.0); })
        return system_.maxStableStep(params_.sigma1);
      double lambdaL = 0.0;
      if constexpr (HasLossOperator<S>) lambdaL = system_.lossOperatorEigenvalueMax();
      return maxStableStep(lambda, lambdaL, params_.sigma1);
    }();
    if (params_.k > kMax)
      throw std::invalid_argument(
          "time step k = " + formatNumber(params_.k) +
          " breaks the stability bound (44) of the split scheme: k <= " + formatNumber(kMax));
  }

  // The potential that ψ_j quadratises: V'_j (or all of V') for (38), the whole V for (27).
  double quadratisedPotential(int part, const Vector& q) {
    if constexpr (partitioned) return system_.partPotential(part, q);
    if constexpr (form == SavForm::split) return system_.splitPotential(q);
    return fullPotential(system_, q, kq_);
  }

  // Its gradient at q^n into grads_[part] (and K q^n into kq_ for (27)); returns the potential.
  double gradient(int part) noexcept {
    if constexpr (form == SavForm::nonSplit) return fullGradient(system_, curr_, grads_[0], kq_);
    if (dropped_[part]) return 0.0;
    if constexpr (partitioned) return system_.partGradient(part, curr_, grads_[part]);
    return system_.splitGradient(curr_, grads_[0]);
  }

  S system_;
  StepParameters params_;
  LinearLoss<S> loss_;
  Vector prev_, curr_, next_;        // q^n, q^{n+1}, workspace; rotated by swapping
  std::array<Vector, parts> grads_;  // ∇V'_j (∇V for (27)) at the newest level a step used
  Vector kq_;                        // and K q there
  bool prevKept_ = false;  // the model keeps what its stiffness sweep of q^{n−1} gave the loss
  std::array<double, parts> psi_{};    // ψ_j^{n+½}
  std::array<bool, parts> dropped_{};  // dropPart()
  bool sparse_ = false;                // part 0 dense, the others with a support (sparseCapable)
  Vector force_;                       // external force f, N per coordinate
  Vector extra_;  // 2σ1k C(q^n − q^{n−1}) − k² f: what b loses through M⁻¹
  bool forced_ = false;
  std::array<Eigen::Index, kPointForces> pointIndex_{};
  std::array<double, kPointForces> pointForce_{};
  std::array<Eigen::Index, kPointDampers> damperIndex_{};
  std::array<double, kPointDampers> damperR_{};  // kg/s; 0: lifted
  std::array<double, kPointDampers> damperD_{};  // (D1)'s d, gathered per coordinate
  bool damped_ = false;
  double supplied_ = 0.0;  // work of f and of the point forces since the start
  double dissipated_ = 0.0;
  long n_ = 0;
  const Kernels* kernels_ = &selectedKernels();
};

template <HamiltonianSystem S>
using NonSplitSav = SavScheme<S, SavForm::nonSplit>;  // (27): unconditionally stable
template <HamiltonianSystem S>
using SplitSav = SavScheme<S, SavForm::split>;  // (38): stable under (44)

}  // namespace hamiltone
