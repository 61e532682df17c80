// The inhomogeneous linear wave of [M §4.3.2]: u_tt = (c² u_x)_x on (0, 1), c = 10 left of 0.5 and
// 1 right of it, fixed ends; finite differences (28), partitioned slow/fast at the interface.
#pragma once

#include <span>
#include <vector>

#include "schemes/hamiltonian.h"

namespace hamiltone {

// Which initial velocity: the paper's printed v⁰ = 8(x − 0.2) e^{−(20(x−0.2))²} = −u⁰' (a pulse
// that splits, 55 % right-going and 45 % left-going, since c₁ = 10), or v⁰ = −c₁ u⁰' (purely
// right-going, the case the paper's exact solution is written for).
enum class WaveStart { paper, rightGoing };

// N = 1/Δx intervals, x_i = iΔx; the particles are the interior nodes i = 1 … N−1 (storage
// j = i − 1, unit masses), u_0 = u_N = 0. Spring s = 1 … N joins nodes s−1 and s with stiffness
// ω²_{s−½} = c(x_{s−½})²/Δx²: H = ½ Σ p_i² + ½ Σ_s ω²_{s−½} (q_s − q_{s−1})². Fast: x_i < 0.5;
// mixed: x_i = 0.5 (i = N/2); slow: x_i > 0.5. V_F = springs 1 … N/2 (c₁), V_M = spring N/2+1,
// V_S = springs N/2+2 … N (c₂).
class InhomogeneousWave {
 public:
  static constexpr double kFastSpeed = 10.0;  // c₁
  static constexpr double kSlowSpeed = 1.0;   // c₂

  // Throws std::invalid_argument unless N = 1/Δx is an even integer >= 4 (to 1e-9).
  explicit InhomogeneousWave(double dx);

  Eigen::Index size() const { return inverseMass_.size(); }
  int intervals() const { return intervals_; }
  double dx() const { return dx_; }
  double position(Eigen::Index j) const { return static_cast<double>(j + 1) * dx_; }
  const Vector& inverseMass() const { return inverseMass_; }

  std::span<const Eigen::Index> fastParticles() const { return fast_; }
  std::span<const Eigen::Index> mixedParticles() const { return mixed_; }
  std::span<const Eigen::Index> slowParticles() const { return slow_; }
  std::span<const Eigen::Index> coupledSlowParticles() const { return coupled_; }

  double fastPotential(const Vector& q) const;
  double mixedPotential(const Vector& q) const;
  double slowPotential(const Vector& q) const;
  void addFastGradient(const Vector& q, double w, Vector& out) const;
  void addMixedGradient(const Vector& q, double w, Vector& out) const;
  void addSlowGradient(const Vector& q, double w, Vector& out) const;
  long fastInteractions() const { return intervals_ / 2; }
  long mixedInteractions() const { return 1; }
  long slowInteractions() const { return intervals_ / 2 - 1; }

  // The CFL bounds of [M (16)] per region, h <= 2/√λmax with λmax <= 4c²/Δx² (Gershgorin):
  // Δx/c₁ for h_F, Δx/c₂ for h_S.
  double fastStepBound() const { return dx_ / kFastSpeed; }
  double slowStepBound() const { return dx_ / kSlowSpeed; }

 private:
  double potential(int first, int last, double stiffness, const Vector& q) const;
  void addGradient(int first, int last, double stiffness, const Vector& q, double w,
                   Vector& out) const;

  int intervals_;
  double dx_;
  double fastStiffness_, slowStiffness_;  // c₁²/Δx², c₂²/Δx²
  Vector inverseMass_;
  std::vector<Eigen::Index> fast_, mixed_, slow_, coupled_;
};

// u⁰(x) = 10⁻² e^{−(20(x−0.2))²} 1_{(0,0.5)}(x)   [M §4.3.2]
double waveInitialDisplacement(double x);
// v⁰ of the chosen start (see WaveStart).
double waveInitialVelocity(double x, WaveStart start);
// u(x_j), v(x_j) at the nodes.
InitialState waveInitialState(const InhomogeneousWave& wave, WaveStart start);

// The exact solution of (27) for t <= 0.5 (before the transmitted wave meets the wall at x = 1),
// [M §4.3.2]'s sums over k with u⁰ replaced by the right-going profile P = F − G(−·) of the start
// u⁰ = F + G, F = ½(1 + β/c₁) u⁰, G = ½(1 − β/c₁) u⁰, v⁰ = −β u⁰' (the left-going G reflected at
// x = 0 joins F): with r = (c₂ − c₁)/(c₁ + c₂),
//   x < 0.5: u = Σ_k r^k (P(x + k − c₁t) − P(k − x − c₁t)),
//   x > 0.5: u = 2c₁/(c₁ + c₂) Σ_k r^k P(c₁/c₂ (x − 0.5) + k + 0.5 − c₁t).
// The paper's formula is the case β = c₁ (P = u⁰). Terms outside P's support (−0.5, 0.5) or with
// |r|^k < 1e-300 are dropped.
double waveExactDisplacement(double x, double t, WaveStart start);

}  // namespace hamiltone
