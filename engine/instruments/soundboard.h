// The piano's soundboard as the modes of a simply supported orthotropic rectangle (rib-stiffened
// spruce), stepped once per sample with an exactly conserved discrete energy.
#pragma once

#include <Eigen/Dense>
#include <span>
#include <vector>

#include "instruments/body_loops.h"

namespace hamiltone {

// A point on the board, m: x along the grain (0 … lx), y across it, along the ribs (0 … ly).
struct BoardPoint {
  double x = 0.0, y = 0.0;
};

// Defaults: a concert grand's board as an equivalent rectangle of ribbed spruce
// (docs/instrument-data.md §6: every figure, its source, and which are engineering choices).
struct SoundboardPhysics {
  double lx = 1.9, ly = 1.3;  // m: 2.47 m² (§6.1)
  double thickness = 9e-3;    // h, m (§6.1)
  double density = 664.2;     // ρ, kg/m³: spruce 380 plus the ribs' mass smeared over h (§6.2)
  double d1 = 671.0;          // D1, N·m: along the grain, E1 h³/12(1 − ν12ν21) (§6.2)
  double d2 = 10220.0;        // D2, N·m: across the grain, the ribs' EI per spacing (§6.2)
  double d3 = 90.5;           // D3 = D12 + 2 D66, N·m (§6.2)
  double lossFactor = 0.02;   // η: σ_m = η ω_m / 2 (§6.3)
  double maxModeHz = 1000.0;  // every mode up to here (§6.4: the cost with 88 points)
  double surfaceDensity() const { return density * thickness; }  // ρh, kg/m²
};

// Each mode a_m of shape φ_m(x, y) = sin(mπx/lx) sin(nπy/ly), modal mass M = ρh lx ly / 4,
//   M δtt a = −K̂ a^n − 2Mσ δt· a + Σ_k φ_m(x_k) F_k^n,   K̂ = M (4/k²) sin²(ω k/2)   (S1)
// K̂ makes the lossless discrete frequency exactly ω; the loss is centred. Energy
//   H^{n+½} = Σ_m M/2 ((a^{n+1} − a^n)/k)² + K̂/2 a^{n+1} a^n                          (S2)
//   H^{n+½} − H^{n−½} = −k Σ 2Mσ (δt· a)² + Σ_k F_k (w_k^{n+1} − w_k^{n−1})/2           (S3)
// and H ≥ 0 while ωk < 2 (always: the modes stop below fs/π). w = Φa at the bridge points.
class Soundboard {
 public:
  // May allocate. Throws std::invalid_argument naming the field, its value and the valid range.
  void prepare(const SoundboardPhysics& physics, double sampleRate,
               std::span<const BoardPoint> bridgePoints, const BoardPoint (&pickups)[2]);
  void reset() noexcept;  // the board at rest, the tallies zero; keeps the modes

  int points() const noexcept { return static_cast<int>(w_.size()); }
  // The points in use (all after prepare): step() computes w at these only, the others keep
  // stale values. Forces may act at any point: they reach the modes whatever this list, and so
  // does their work in supplied(). Copies; no allocation.
  void setActivePoints(std::span<const int> points) noexcept;
  int activePoints() const noexcept { return activeCount_; }
  // w and the previous level's w at one point, brought up to date (before it is put in use).
  void refreshPoint(int point) noexcept;
  double displacement(int point) const noexcept { return w_[point]; }  // w_k at level n
  const Eigen::VectorXd& displacements() const noexcept { return w_; }
  const Eigen::VectorXd& previousDisplacements() const noexcept { return wPrev_; }  // w^{n−1}
  void addForce(int point, double force) noexcept { force_[point] += force; }       // F_k^n, N
  // Forces at all points at once (one per point), added to those of addForce.
  void addForces(std::span<const double> forces) noexcept;
  void step() noexcept;  // level n → n+1; clears the forces
  // Board velocity (m/s) at the two pickup points, (a^n − a^{n−1})/k: the radiation proxy.
  void pickups(double& left, double& right) const noexcept;

  double energy() const noexcept;  // H^{n−½} of (S2), J
  double dissipated() const noexcept { return dissipated_; }
  double supplied() const noexcept { return supplied_; }
  double lastWork() const noexcept { return lastWork_; }  // the last step's share of supplied()

  int modes() const noexcept { return static_cast<int>(omega_.size()); }
  double modeHz(int mode) const noexcept;
  int modeM(int mode) const noexcept { return index_[mode].first; }
  int modeN(int mode) const noexcept { return index_[mode].second; }
  double modalMass() const noexcept { return mass_; }
  double modeDecayRate(int mode) const noexcept { return sigma_[mode]; }              // σ_m, 1/s
  double modeStiffness(int mode) const noexcept { return mass_ * omegaHat2_[mode]; }  // K̂_m
  double modeAmplitude(int mode) const noexcept { return a_[mode]; }                  // a_m^n
  double shape(int mode, const BoardPoint& p) const noexcept;                         // φ_m(x, y)
  // φ_m(x_k) as the products use them (rounded to float), modes × points.
  const Eigen::MatrixXd& shapes() const noexcept { return phiColumns_; }
  double timeStep() const noexcept { return k_; }
  const SoundboardPhysics& physics() const noexcept { return physics_; }

 private:
  SoundboardPhysics physics_;
  double k_ = 0.0, mass_ = 0.0;
  std::vector<std::pair<int, int>> index_;
  Eigen::VectorXd omega_, omegaHat2_, sigma_;
  Eigen::VectorXd c1_, c2_, c3_;  // a^{n+1} = c1 a^n − c2 a^{n−1} + c3 g   (S1 solved)
  // Φ: points × modes, each point's modes contiguous (ldModes_ a row, padded with zeros), in float
  // (body_loops.h): g = Φᵀ F, w = Φa. phiColumns_ holds the same values, modes × points, in double.
  std::vector<float> phi_;
  long ldModes_ = 0;
  Eigen::MatrixXd phiColumns_;
  const BodyLoops* loops_ = nullptr;
  Eigen::Matrix<double, 2, Eigen::Dynamic, Eigen::RowMajor> pickupShapes_;
  Eigen::VectorXd a_, aPrev_, g_, force_, w_, wPrev_;
  std::vector<int> active_;  // points in use, active_[0 … activeCount_)
  int activeCount_ = 0;
  double dissipated_ = 0.0, supplied_ = 0.0, lastWork_ = 0.0;
};

// Where the keys cross the bridges, in fractions of lx and ly: the bass bridge from A0 to E2 and
// the treble bridge from F2 to C8 (break at E2/F2, MIDI 40/41: docs/instrument-data.md §1.2), keys
// evenly spaced along each straight segment. An approximation of a grand's curved bridges, kept
// clear of the edges where every mode's shape vanishes (§6.5).
struct BridgeGeometry {
  BoardPoint bassLow{0.82, 0.30}, bassHigh{0.74, 0.62};      // A0, E2
  BoardPoint trebleLow{0.66, 0.80}, trebleHigh{0.14, 0.18};  // F2, C8
};
// Points of the keys lowestNote … highestNote (MIDI, within 21 … 108) on `board`, m.
std::vector<BoardPoint> bridgeLine(int lowestNote, int highestNote, const SoundboardPhysics& board,
                                   const BridgeGeometry& geometry = {});

}  // namespace hamiltone
