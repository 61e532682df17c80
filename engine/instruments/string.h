// The geometrically exact stiff string of BDZ §4.2: transverse u and longitudinal v on uniform
// grids with fixed ends, split as (65) with bending stiffness EI ∂x⁴u added to K. v may live on a
// coarser grid nested in u's (SCHEMES §3b), so that the longitudinal wave is resolved at audio
// rate.
#pragma once

#include <algorithm>

#include "kernels/kernels.h"
#include "schemes/hamiltonian.h"

namespace hamiltone {

struct StringPhysics {
  double density = 7850.0;  // ρ, kg/m³
  double area = 8.87e-7;    // A, m²
  double length = 1.259;    // L, m
  double young = 2.02e11;   // E, Pa
  double tension = 759.0;   // T0, N
  double inertia = 0.0;     // I of the cross-section for bending, m⁴ (0: no stiffness)
  double linearDensity() const { return density * area; }  // ρA, kg/m
};

// The two grids: u on `transverse` segments (Mu), v on `longitudinal` segments (Mv), Mu = r·Mv,
// so every coarse cell J holds r fine segments. Mv = Mu is the single grid of (65); Mv = 1 leaves
// no longitudinal unknown: the tension follows the mean strain (Kirchhoff–Carrier).
struct StringGrid {
  int transverse = 0;
  int longitudinal = 0;
  bool operator==(const StringGrid&) const = default;
};

// q = [u_1 … u_{Mu−1}, v_1 … v_{Mv−1}] on x_l = l h_u and x_J = J h_v, h = L/M; u = v = 0 at both
// ends, and u'' = 0 there too (simply supported) for the stiffness term. ζ = D₋u on the fine
// segments, η = D₋v on the coarse ones.
//   M = ρA diag(h_u I, h_v I)
//   K = [ h_u (−T0 D2 + EI D2²)   0 ;  0   h_v (−T0 D2) ]                   (65) + stiffness
//   V' = (EA − T0)/2 Σ_J h_v ε_J²,  ε_J = S_J − 1,  S_J = sqrt((1 + η_J)² + (1/r) Σ_{l∈J} ζ_l²)
// the strain of each coarse cell from its mean square slope (docs/string-grids.md, "The strain of
// a cell"); with r = 1 it is (65): V' = h (EA − T0)/2 Σ_l (s_l − 1)², s_l the segment's stretch.
class NonlinearString {
 public:
  static constexpr bool hasStiffness = true;

  // Throws std::invalid_argument naming the parameter if a value is not physical, if EA <= T0
  // (V' would not be >= 0), if Mu < 2, Mv < 1 or Mv does not divide Mu.
  NonlinearString(const StringPhysics& physics, StringGrid grid);
  NonlinearString(const StringPhysics& physics, int segments)  // the single grid of (65)
      : NonlinearString(physics, StringGrid{segments, segments}) {}

  Eigen::Index size() const { return inverseMass_.size(); }
  int segments() const { return segments_; }  // Mu: u's grid, where the pickups and hammer sit
  const StringGrid& grid() const { return grid_; }
  Eigen::Index transverseSize() const { return segments_ - 1; }  // u's share of q, first
  double spacing() const { return h_; }
  double longitudinalSpacing() const { return hv_; }
  const StringPhysics& physics() const { return physics_; }

  const Vector& inverseMass() const { return inverseMass_; }
  void applyStiffness(const Vector& q, Vector& out) const;
  double stiffnessEigenvalueMax() const;
  double splitPotential(const Vector& q) const;
  double splitGradient(const Vector& q, Vector& grad) const;
  // The string's pull along its axis on its far end (x = L, where a bridge sits) beyond the static
  // T0, at the q of the last splitGradient() — in a scheme's step, q^n: with v_M the end's
  // longitudinal displacement (held at 0), ΔT = ∂(½ qᵀKq + V')/∂v_M = T0 η_M + (1/h_v) ∂V'/∂η_M,
  // η_M the last coarse strain. On a string stretched uniformly by ε it is EA ε (Hooke).
  double endTension() const { return endTension_; }

  // C(a − b), C = M(−Λ) the operator of the frequency-dependent loss σ1 (linear_loss.h), with
  //   −Λ = w_u (−D2) on u,   w_v0 I + w_v1 (−D2) on v,
  // so that the scheme's σ1 damps a mode of wavenumber² ξ at σ1 w_u ξ on u and σ1 (w_v0 + w_v1 ξ)
  // on v: each wave may have its own law. The paper's (49) has one, w = (1, 0, 1), the default.
  // `out` must not be `a` or `b`.
  struct LossWeights {
    double transverse = 1.0;            // w_u
    double longitudinalConstant = 0.0;  // w_v0, 1/m²
    double longitudinal = 1.0;          // w_v1
  };
  // Throws std::invalid_argument if a weight is negative or not finite.
  void setLossWeights(const LossWeights& weights);
  const LossWeights& lossWeights() const { return lossWeights_; }
  void applyLossOperator(const Vector& a, const Vector& b, Vector& out) const;
  // applyStiffness(q, kq) and applyLossOperator(q, qPrev, cq) together: on u, C(q − qPrev) is
  // −ρA w_u h (D2 q − D2 qPrev)/h², and the stiffness stencil takes D2 q/h² anyway; D2 qPrev/h² is
  // the one this call took for its q the last time, when `prevKept` says that q was this qPrev
  // (the scheme's previous step), else it is taken here. Equal to the two calls within roundoff.
  // For the scheme that steps this string alone: a call from elsewhere between its steps would
  // replace what it kept.
  void applyStiffnessAndLoss(const Vector& q, const Vector& qPrev, bool prevKept, Vector& kq,
                             Vector& cq) const;
  // λmax(M⁻¹C): the larger of w_u (4/h²) sin²((Mu−1)π/2Mu) and w_v0 + w_v1 (4/h_v²) sin²(…) on v.
  double lossOperatorEigenvalueMax() const;
  // The bound (44) with the loss σ1, block by block: K and C act on u and on v apart, so the scheme
  // is stable when each block is — the smaller of maxStableStep(λK, λC, σ1) on u (K at the largest
  // bend) and on v (K holds T0 there), the top modes of each. Taking the largest λK and λC of the
  // whole string instead mixes u's stiffness with v's loss and refuses stable laws.
  double maxStableStep(double sigma1) const;

  // Pitch bend: the transverse wave sees the tension β·T0 (the longitudinal wave and V' keep T0,
  // as a tuning peg's small stretch leaves EA − T0 unchanged). stiffnessEigenvalueMax() answers for
  // the largest β allowed, so a scheme built after setTensionRange() stays stable for any bend.
  void setTensionRange(double maxScale);  // >= 1; resets β to 1
  // The instruction set of the stencils and the stretches (default: selectedKernels()).
  void setKernels(const Kernels& kernels) noexcept { kernels_ = &kernels; }
  void setTensionScale(double scale) { tensionScale_ = std::clamp(scale, 0.0, tensionScaleMax_); }
  double tensionScale() const { return tensionScale_; }

  // The linear string (docs/string-grids.md, "The linear tail"): V' replaced by its quadratic part
  // at rest, (EA − T0)/2 Σ_J h_v η_J² — the longitudinal wave's stiffness beyond T0 — taken into
  // K, whose v block then holds EA: −EA h_v D2 v. What it leaves out is the tension modulation, the
  // strain u's slopes add to each cell (Z_J/2). A scheme that drops V' (SavScheme::dropPart) and
  // takes K again (stiffnessChanged) steps the linear string; the longitudinal wave keeps its
  // speed.
  void setLinearised(bool on) noexcept { linearised_ = on; }
  // The stretch u's slopes hold in v at small amplitude, which the linear string no longer holds:
  // v where the tension is uniform along the string, η_J = −(EA − T0)/(2EA) (Z_J − Z̄) (from
  // T0 η + (EA − T0)(η + Z/2) the same in every cell, ε ≈ η + Z/2), Z_J the cell's mean square
  // slope at q, Z̄ their mean over the cells (v = 0 at both ends). Into v's Mv − 1 nodes; nothing
  // with one coarse cell. No allocation.
  void quasiStaticStretch(const Vector& q, double* v) const noexcept;
  // The bound (44) for the linear string: v's block at EA. Where v's grid does not resolve the
  // longitudinal wave (c_L k > h_v, the transverse grid) it is shorter than a step there.
  double linearisedMaxStableStep(double sigma1) const;
  // ΔT at the far end of the linear string at q: EA η_M (0 with one coarse cell, Mv = 1).
  double linearEndTension(const Vector& q) const;

  // Eigenvalue m = 1 … M−1 of M⁻¹K on u: (βT0/ρA)(4/h²) s² + (EI/ρA)(16/h⁴) s⁴, s = sin(mπ/2M).
  double transverseEigenvalue(int m) const;
  double transverseEigenvalue(int m, double scale) const;  // at β = scale
  // Of M⁻¹K on v, m = 1 … Mv−1: (T0/ρA)(4/h_v²) s², s = sin(mπ/2Mv).
  double longitudinalEigenvalue(int m) const;

 private:
  // λmax(M⁻¹C) on u and on v (v's only where Mv >= 2).
  double transverseLossTop() const;
  double longitudinalLossTop() const;
  // The bound (44) block by block, v's block at tension vTension (T0, or the linear string's EA).
  double blockStableStep(double sigma1, double vTension) const;
  double singleGridPotential(const Vector& q) const;
  double singleGridGradient(const Vector& q, Vector& grad) const;
  double twoGridPotential(const Vector& q) const;
  double cellsPotential(double squaredStrains) const;  // V' of the two grids from Σ_J ε_J²
  double twoGridGradient(const Vector& q, Vector& grad) const;
  struct OneCell {
    double strain, strainOverStretch;  // ε = S − 1 and ε/S of the string's one coarse cell
  };
  OneCell oneCell(const Vector& q) const;
  double oneCellGradient(const Vector& q, Vector& grad) const;
  void cellStrains(const Vector& q, double* strain, double* inverseStretch) const;
  void longitudinalStiffness(const Vector& q, Vector& out) const;              // K q on v
  void longitudinalLoss(const Vector& a, const Vector& b, Vector& out) const;  // C(a − b) on v
  void coarseStiffnessAndLoss(const Vector& q, const Vector& qPrev, Vector& kq, Vector& cq) const;

  StringPhysics physics_;
  StringGrid grid_;
  int segments_, ratio_;  // Mu, r = Mu / Mv
  double h_, hv_;         // h_u, h_v
  Vector inverseMass_;
  double tensionScale_ = 1.0, tensionScaleMax_ = 1.0;
  bool linearised_ = false;
  LossWeights lossWeights_;
  mutable double endTension_ = 0.0;
  // Work of the stencils and the potentials, per fine segment: work1_ the stiffness stencil's D2 u
  // and, with work2_, the single grid's ∂V'/∂ζ and ∂V'/∂η (Mu each); work3_ and scratch_ the
  // single grid's u and v padded with their fixed ends (Mu + 1 each; work3_ also the quasi-static
  // stretch's u). Per coarse cell (Mv): cell1_ … cell3_. forcesWork_: the two grids' kernels'
  // (Kernels::cellStretches, twoGridForces).
  mutable Vector work1_, work2_, work3_, cell1_, cell2_, cell3_;
  mutable Vector scratch_, forcesWork_;
  mutable Vector d2_, d2Prev_;  // D2 u/h² of applyStiffnessAndLoss's q and of the one before
  const Kernels* kernels_ = &selectedKernels();
};

// How the grid spacing h follows from the time step k (BDZ §4.2, SCHEMES §3).
enum class GridRule {
  transverse,    // the stiff-string bound (44) with the σ1 term: the finest stable grid
  longitudinal,  // h >= sqrt(E/ρ) k: the longitudinal wave resolved, as in the paper's runs
  twoGrid,       // u on the transverse grid, v on a coarse nested one with h_v >= sqrt(E/ρ) k
};

// As a preset writes it (scheme.grid_rule): "two-grid", "transverse", "longitudinal".
constexpr const char* gridRuleName(GridRule rule) {
  return rule == GridRule::twoGrid      ? "two-grid"
         : rule == GridRule::transverse ? "transverse"
                                        : "longitudinal";
}

// The smallest h the rule allows (u's for twoGrid): transverse h² = (c²k² + 4σ1k + sqrt((c²k² +
// 4σ1k)² + 16κ²k²))/2 with c² = T0/ρA, κ² = EI/ρA (the continuous form of maxStableStep, so
// slightly conservative); longitudinal h = max(sqrt(E/ρ) k, the transverse h).
double minimalSpacing(const StringPhysics& physics, GridRule rule, double k, double sigma1);
// M = floor(L / (factor · h_min)) segments, at least 2. Throws std::invalid_argument if factor < 1
// or the string is too short for two segments.
int gridSegments(const StringPhysics& physics, GridRule rule, double k, double sigma1,
                 double factor);

// The coarse cells up to which the two grids' v takes one sweep for its stiffness and loss
// (NonlinearString::coarseStiffnessAndLoss) rather than the kernels: measured, not derived.
constexpr int kFewCoarseCells = 8;

// v's spacing on the two grids as a multiple of sqrt(E/ρ) k: the longitudinal Courant number is
// 1/1.05 (SCHEMES §3b; at 1.43 the glide collapses to a quarter of the converged one).
constexpr double kLongitudinalGridFactor = 1.05;

// The transverse grid's least factor: on the bound (44) itself its top mode rings at the Nyquist
// frequency (stringGrid).
constexpr double kOffTheBound = 1.02;

// The grids of `rule` (SCHEMES §3b for twoGrid). transverse and longitudinal: Mu = Mv =
// gridSegments(), the transverse grid's factor at least kOffTheBound. twoGrid: Mv = max(1, floor(L
// / (1.05 sqrt(E/ρ) k))); u's finest grid sized for the design tension `tensionMargin`·T0
// (stability needs T0, accuracy under tension modulation the margin), coarsened by `factor`, then
// rounded down to a multiple r·Mv (with fewer coarse cells where that keeps more of u's grid).
// Throws std::invalid_argument like gridSegments(), or for a margin < 1.
StringGrid stringGrid(const StringPhysics& physics, GridRule rule, double k, double sigma1,
                      double factor, double tensionMargin);

}  // namespace hamiltone
