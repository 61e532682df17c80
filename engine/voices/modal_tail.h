// The linear tail in the string's own modes (docs/string-grids.md, "The modal tail"). The linear
// string of the scheme — K and C of one grid each for u and v, M diagonal and uniform on each,
// simply supported ends — is diagonalised exactly by the sine transform (DST-I): mode m of a grid
// of M segments is φ_m(j) = sqrt(2/M) sin(π m j / M), with M⁻¹K and M⁻¹C its eigenvalues κ_m and
// γ_m. The linear step (sav.h, stepLinear: (38) with no part loaded, the loss (49))
//   (1 + σ0k) q^{n+1} = (2 − k²M⁻¹K − 2σ1k M⁻¹C) q^n − (1 − σ0k − 2σ1k M⁻¹C) q^{n−1} + k²M⁻¹f
// is then one recursion per mode, the bridge's point forces f entering through φ_m at their nodes
// and every output (a pickup, the bridge's end nodes, the hammer's contact) a dot product with
// the modes. The modes whose energy together is under a floor of the string's (−100 dB, −80 dB
// under the live tail) are dropped, highest first and a vector register of them at a time (the
// arrays padded with zeros to whole registers); the rest step as before, and what
// the dropped ones gave statically under the bridge's force stays in the coupling as a softer
// self-stiffness (residual()). The same linear system, so its energy balance holds step by step
// (energy()), less what a drop removes (returned by truncate()).
#pragma once

#include <array>
#include <span>
#include <vector>

#include "instruments/string.h"
#include "kernels/kernels.h"
#include "schemes/hamiltonian.h"

namespace hamiltone {

class ModalTail {
 public:
  // The outputs read on u, each a linear functional Σ_j c_j u_j: the pickups and the hammer's
  // contact by their node weights c, and the bridge's pull c1 u_{M−1} + c2 u_{M−2} (setPull). The
  // bridge at w pushes the same nodes with −c1 w and −c2 w: a force along the pull's own weights.
  enum Probe { kPickup0, kPickup1, kPull, kContact, kProbes };

  // Sizes the tables for this string's grids (may allocate): the transform's rows, and the probes'
  // modal weights from their node weights (kProbes spans of u's M − 1 values; kPull's is unused)
  // and the pull's nodes (q's indices of u_{M−1} and u_{M−2}). No pull until setPull().
  void prepare(const NonlinearString& string, double k,
               const std::array<std::vector<double>, kProbes>& probes, Eigen::Index last,
               Eigen::Index second);
  // The pull's weights c1, c2 (BridgeCoupling, with the bend). No allocation.
  void setPull(double c1, double c2) noexcept;
  // The modes' recursions for the string as bent now (its β) and the losses σ0, σ1 and its
  // weights (the linear string: v at EA). No allocation.
  void setCoefficients(const NonlinearString& string, double sigma0, double sigma1);

  // The string's u and v (the first (M − 1) + (Mv − 1) coordinates of q) at levels n and n + 1
  // into every mode.
  void enter(const Vector& q, const Vector& qNext) noexcept;
  // The kept modes back to u and v at levels n and n + 1; the other coordinates are left alone.
  void leave(Vector& q, Vector& qNext) const noexcept;

  // One step with the bridge at w (m): the forces −c1 w and −c2 w on the pull's nodes. It writes
  // level n + 2 over level n, which then takes the name of n + 1. (Inline: every sample of every
  // string in its tail takes it.)
  void step(double w) noexcept {
    now_ = next_;
    vLast_ = vLastNext_;
    const double* weights[kProbes];
    for (int p = 0; p < kProbes; ++p) weights[p] = weights_[p].data();
    kernels_->modalStep(u_.steps, u_.c1.data(), u_.c2.data(), weights, -forceScale_ * w, u_.now(),
                        u_.next(), next_.data());
    u_.newer = 1 - u_.newer;
    if (v_.steps == 0) return;  // no modes of v kept: vLastNext_ stays 0
    vLastNext_ = kernels_->freeModalStep(v_.steps, v_.c1.data(), v_.c2.data(), vEnd_.data(),
                                         v_.now(), v_.next());
    v_.newer = 1 - v_.newer;
  }

  // A probe at level n and at level n + 1.
  double at(Probe p) const { return now_[p]; }
  double atNext(Probe p) const { return next_[p]; }
  // ΔT at the bridge's end at level n, EA η_M = −EA v_{Mv−1} / h_v
  // (NonlinearString::linearEndTension); 0 with one coarse cell.
  double endTension() const { return v_.modes == 0 ? 0.0 : -vLast_ * endStiffness_; }

  // H^{n+½} of the kept modes: the scheme's energy() of the linear string (kinetic with its σ1
  // correction, ½ q^{n+1}ᵀ K q^n), J.
  double energy() const noexcept;
  // Drops the highest modes of u, then of v, while what they hold together stays under
  // floor × energy() (none at a floor of 0); returns the energy dropped. They go a register at a
  // time (kMaxLanes modes; first the last register, partly filled where the modes are not a whole
  // number of registers), so that the kept modes fill whole registers or are all of them: the step
  // then runs in whole registers, the padding past the last mode stepping zeros.
  double truncate(double floor) noexcept;
  // Takes every mode again, the dropped ones at rest (where a force may wake them: a strike of the
  // key's other strings).
  void restore() noexcept;
  // The dropped modes' static give under the bridge's force, as a stiffness (N/m) to take off the
  // coupling's own: see takeResidual(). 0 with every mode kept.
  double residual() const { return residual_; }
  int keptTransverse() const { return u_.kept; }
  int keptLongitudinal() const { return v_.kept; }

 private:
  // One grid's modes: amplitudes at levels n and n + 1 (the two arrays take turns), the
  // recursion's coefficients a^{n+2} = c1 a^{n+1} − c2 a^n, and M⁻¹K and M⁻¹C of each mode.
  struct Grid {
    int modes = 0;      // M − 1
    int kept = 0;       // all the modes, or a multiple of kMaxLanes (keep())
    int steps = 0;      // registers(kept): the modes a step runs, the padding's zeros included
    int newer = 1;      // levels[newer] holds n + 1, the other n
    double mass = 0.0;  // ρA h on this grid: M's diagonal
    std::vector<double> levels[2], c1, c2, kappa, gamma;  // the first three to registers(modes)
    std::vector<double> sinTheta, twoCos;  // of θ_i = π i / M, the transform's rows
    double* now() { return levels[1 - newer].data(); }
    double* next() { return levels[newer].data(); }
    const double* now() const { return levels[1 - newer].data(); }
    const double* next() const { return levels[newer].data(); }
    void prepare(int segments, double spacing, double rhoA);
    void keep(int n) noexcept {
      kept = n;
      steps = registers(n);
    }
    // DST-I of `terms` values into M − 1 (Kernels::sineSums).
    void sineSum(const Kernels& kernels, const double* in, int terms, double* out) const noexcept;
    double modeEnergy(int m, double k, double sigma1) const noexcept;
  };
  // n modes and the padding to a whole register.
  static int registers(int n) { return (n + kMaxLanes - 1) / kMaxLanes * kMaxLanes; }
  void probeAll() noexcept;
  void takeResidual() noexcept;

  const Kernels* kernels_ = &selectedKernels();
  Grid u_, v_;
  double k_ = 0.0, sigma1_ = 0.0;
  double forceScale_ = 0.0;    // k² / (ρA h (1 + σ0k)): a force's share of a mode's step
  double endStiffness_ = 0.0;  // EA / h_v, taken once: the bridge's chain runs through v
  // The probes' modal weights (to registers(u's modes)), the pull's nodes', and v's last node's
  // (to registers(v's modes)).
  std::array<std::vector<double>, kProbes> weights_;
  std::vector<double> lastNode_, secondNode_, vEnd_;
  std::array<double, kProbes> now_{}, next_{};
  double vLast_ = 0.0, vLastNext_ = 0.0;
  double residual_ = 0.0;
};

}  // namespace hamiltone
