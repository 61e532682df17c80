// The bridge the strings of a key end on: a mass on a spring with a resistance (the soundboard's
// driving point, docs/instrument-data.md §6), and the string–bridge coupling that keeps the
// strings' scheme (38) and the bridge together exactly energy-conserving.
#pragma once

#include <numbers>

#include "instruments/string.h"
#include "schemes/hamiltonian.h"

namespace hamiltone {

// The largest angle α a bridge takes: 10°, nearly seven times the steepest downbearing quoted in
// docs/instrument-data.md §3.7 (1½°); the reaction the drive neglects grows as sin²α.
inline constexpr double kMaxBridgeAngle = 10.0 * std::numbers::pi / 180.0;

struct BridgePhysics {
  double mass = 0.0;        // M_b, kg
  double stiffness = 0.0;   // K_b, N/m
  double resistance = 0.0;  // R_b, kg/s (N per m/s)
  // α, rad: the angle between the speaking length and the board's plane where it crosses the
  // bridge (its share of the downbearing, docs/instrument-data.md §3.7). The string's tension
  // change ΔT then pushes the bridge towards the board by ΔT sin α: its longitudinal end force.
  double angle = 0.0;
};

// The string's end u_M = w rides on the bridge (moving simply supported end: D2 u = 0 there).
// The string's K energy h/2 Σ βT0 (D₋u)² + EI h/2 Σ (D2 u)² then holds w in its last segment and
// its last second difference; the terms with w are
//   E_c = w (c1 u_{M−1} + c2 u_{M−2}) + ½ K_s w²,
//   c1 = −(βT0/h + 2 EI/h³),  c2 = EI/h³,  K_s = βT0/h + EI/h³.
// Taken as the scheme takes K, E_c^{n+½} = ½ (Cᵀu^{n+1} w^n + Cᵀu^n w^{n+1}) + ½ K_s w^{n+1} w^n,
// the string feels f = −C w^n and the bridge −Cᵀu^n − K_s w^n, and the strings, the bridge and
// E_c together conserve their energy exactly (less the losses). The bridge's displacement is
// taken as transverse only (the string's end moves with it; its longitudinal end stays fixed);
// V' keeps u_M = 0, an error of order w/u, the bridge moving microns where the string moves
// millimetres.
class BridgeCoupling {
 public:
  BridgeCoupling() = default;
  // From the string's grid, tension (with its bend β) and stiffness; `lastIndex` is u_{M−1}'s
  // place in the scheme's q (u comes first: M − 2).
  explicit BridgeCoupling(const NonlinearString& string);

  double forceOnLast(double w) const { return -c1_ * w; }    // on u_{M−1}
  double forceOnSecond(double w) const { return -c2_ * w; }  // on u_{M−2}
  Eigen::Index lastIndex() const { return last_; }
  // u_{M−2}'s place; on a string of two segments (one node) u_{M−2} is the fixed end, c2 = 0, and
  // this names u_{M−1} again, so that every use stays inside q.
  Eigen::Index secondIndex() const { return second_; }
  // −∂E_c/∂w at level n: the string's pull on the bridge.
  double forceOnBridge(const Vector& q, double w) const {
    return forceFromPull(c1_ * q[last_] + c2_ * q[second_], w);
  }
  // The same from the string's c1 u_{M−1} + c2 u_{M−2} (a string stepped in its modes,
  // modal_tail.h, which reads it as one sum), the self-stiffness less `residual`, the give of the
  // modes it dropped (ModalTail::residual()).
  double forceFromPull(double pull, double w, double residual = 0.0) const {
    return -pull - (self_ - residual) * w;
  }
  // E_c^{n+½} from q^n, q^{n+1}, w^n, w^{n+1}.
  double energy(const Vector& q, const Vector& qNext, double w, double wNext) const {
    return energy(c1_ * q[last_] + c2_ * q[second_], c1_ * qNext[last_] + c2_ * qNext[second_], w,
                  wNext);
  }
  // The same from the string's c1 u_{M−1} + c2 u_{M−2} at levels n and n + 1 (and `residual` as in
  // forceFromPull).
  double energy(double cq, double cqNext, double w, double wNext, double residual = 0.0) const {
    return 0.5 * (cqNext * w + cq * wNext) + 0.5 * (self_ - residual) * wNext * w;
  }
  // c1 and c2: the pull's weights on u_{M−1} and u_{M−2}, and the forces' on the string
  // (forceOnLast(w) = −c1 w).
  double lastWeight() const { return c1_; }
  double secondWeight() const { return c2_; }
  double selfStiffness() const { return self_; }

 private:
  Eigen::Index last_ = 0, second_ = 0;
  double c1_ = 0.0, c2_ = 0.0, self_ = 0.0;
};

// M_b δtt w = −K_b w^n − R_b δt· w + F^n + D^n, the resistance centred (as σ0 in (49)):
//   w^{n+1} = (2 w^n − (1 − R_b k/2M_b) w^{n−1} + (k²/M_b)(F^n + D^n − K_b w^n))
//             / (1 + R_b k/2M_b),
// H^{n+½} = ½ M_b (δ₊w)² + ½ K_b w^{n+1} w^n, H^{n+½} − H^{n−½} = (F^n + D^n)(w^{n+1} − w^{n−1})/2
// − R_b k (δt· w)². F is the strings' transverse pull, whose work the coupling E_c returns to them;
// D a drive from outside that balance — the strings' longitudinal end force through the angle α,
// which the strings do not feel back (w does not enter their V': a neglected reaction of order
// EA sin²α / L, 40 to 400 N/m a string at 1° from bass to treble, against the bridges' 1e5 to
// 7e5) — its work tallied in supplied().
// The equation being linear, w = w_F + w_D, each part the response to F or D alone, and each
// keeps its own balance above: energy() is H(w_F) + H(w_D) and dissipated() sums R_b k (δt· w)²
// of each part (the cross terms of H(w_F + w_D) dropped), so the strings, both parts and E_c
// balance exactly with supplied(). The strings' ends follow w_F only (E_c), the board takes both:
// the motion D drives is passed on, not back. D is one-way; letting the motion it drives reach
// the strings through E_c closed a loop with a one-way link, which is not passive (tension change
// → w_D → the strings' ends → their tension change): A0 at velocity 127 on grand-piano then rang
// at −65 dBFS for good after its release, a steady longitudinal mode (465.75 Hz and its
// harmonics), at 0.5° as at 1°. With w_D on its own, only R_b takes its energy: an angle needs a
// resistance (prepare()).
// Levels as the scheme's: after a step it holds both parts at levels n and n + 1; the strings'
// next step takes w_F^{n+1}, current(), and so does the force of the bridge's next step.
class Bridge {
 public:
  // Throws std::invalid_argument naming the field if a value is not finite and >= 0 (mass > 0),
  // an angle > 0 on a bridge without resistance (the motion the drive gives it would never end),
  // or if k² (K_b + `addedStiffness`) / M_b >= 4 — the strings' K_s summed: the explicit coupling
  // would not be stable.
  void prepare(const BridgePhysics& physics, double k, double addedStiffness);
  void reset() noexcept;

  double current() const { return w1_; }             // w_F at the level the next steps' forces use
  double displacement() const { return w1_ + d1_; }  // w = w_F + w_D there: what the board takes
  // One step under the force F (the strings' pull, at level current()) and the drive D. Returns
  // w_F^{n+1}.
  double step(double force, double drive = 0.0) noexcept;

  double energy() const;  // H^{n+½} of the bridge alone: of w_F and of w_D
  double dissipated() const { return dissipated_; }
  double supplied() const { return supplied_; }  // the drives' work since reset(), J
  // What the bridge passes on to the soundboard at the last level: K_b w + R_b ẇ, w = w_F + w_D.
  double forceOnBoard() const;
  const BridgePhysics& physics() const { return physics_; }

 private:
  BridgePhysics physics_;
  // k, 1/(1 + Rk/2M), 1 − Rk/2M, k²/M, 1/k: the step's constants, the divisions taken once (the
  // step is on every sample's chain of latencies from the strings back to them).
  double k_ = 0.0, invUp_ = 1.0, down_ = 1.0, kkOverM_ = 0.0, rate_ = 0.0;
  double w0_ = 0.0, w1_ = 0.0;  // w_F^n, w_F^{n+1}
  double d0_ = 0.0, d1_ = 0.0;  // w_D^n, w_D^{n+1}
  // One step of either part under its force, its losses added to dissipated_.
  double advance(double& before, double& now, double force) noexcept;
  double partEnergy(double before, double now) const;
  double dissipated_ = 0.0, supplied_ = 0.0;
};

}  // namespace hamiltone
