// The geometrically exact stiff string of BDZ §4.2: transverse u and longitudinal v on a uniform
// grid with fixed ends, split as (65) with bending stiffness EI ∂x⁴u added to K.
#pragma once

#include <algorithm>

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

// q = [u_1 … u_{M−1}, v_1 … v_{M−1}] on x_l = l h, h = L/M; u = v = 0 at both ends, and u'' = 0
// there too (simply supported) for the stiffness term.
//   M = ρA h I
//   K = h [ −T0 D2 + EI D2²   0 ;  0   −T0 D2 ]                        (65) + stiffness
//   V' = h (EA − T0)/2 Σ_{l=1}^{M} (s_l − 1)²,  s_l = sqrt((1 + η_l)² + ζ_l²),  ζ = D₋u, η = D₋v
class NonlinearString {
 public:
  static constexpr bool hasStiffness = true;

  // Throws std::invalid_argument naming the parameter if a value is not physical, if EA <= T0
  // (V' would not be >= 0), or if segments < 2.
  NonlinearString(const StringPhysics& physics, int segments);

  Eigen::Index size() const { return inverseMass_.size(); }
  int segments() const { return segments_; }
  double spacing() const { return h_; }
  const StringPhysics& physics() const { return physics_; }

  const Vector& inverseMass() const { return inverseMass_; }
  void applyStiffness(const Vector& q, Vector& out) const;
  double stiffnessEigenvalueMax() const;
  double splitPotential(const Vector& q) const;
  double splitGradient(const Vector& q, Vector& grad) const;

  // M(−L)(a − b), L = D2 on u and on v: the operator of the frequency-dependent loss σ1.
  void applyLossOperator(const Vector& a, const Vector& b, Vector& out) const;
  double lossOperatorEigenvalueMax() const;  // λmax(−D2) < 4/h²

  // Pitch bend: the transverse wave sees the tension β·T0 (the longitudinal wave and V' keep T0,
  // as a tuning peg's small stretch leaves EA − T0 unchanged). stiffnessEigenvalueMax() answers for
  // the largest β allowed, so a scheme built after setTensionRange() stays stable for any bend.
  void setTensionRange(double maxScale);  // >= 1; resets β to 1
  void setTensionScale(double scale) { tensionScale_ = std::clamp(scale, 0.0, tensionScaleMax_); }
  double tensionScale() const { return tensionScale_; }

  // Eigenvalue m = 1 … M−1 of M⁻¹K on u: (βT0/ρA)(4/h²) s² + (EI/ρA)(16/h⁴) s⁴, s = sin(mπ/2M).
  double transverseEigenvalue(int m) const;
  double transverseEigenvalue(int m, double scale) const;  // at β = scale
  // Of M⁻¹K on v: (T0/ρA)(4/h²) s².
  double longitudinalEigenvalue(int m) const;

 private:
  StringPhysics physics_;
  int segments_;
  double h_;
  Vector inverseMass_;
  double tensionScale_ = 1.0, tensionScaleMax_ = 1.0;
  mutable Vector work1_, work2_;  // per-segment work of the stencils and the gradient, size M
};

// How the grid spacing h follows from the time step k (BDZ §4.2, SCHEMES §3).
enum class GridRule {
  transverse,    // the stiff-string bound (44) with the σ1 term: the finest stable grid
  longitudinal,  // h >= sqrt(E/ρ) k: the longitudinal wave resolved, as in the paper's runs
};

// The smallest h the rule allows: transverse h² = (c²k² + 4σ1k + sqrt((c²k² + 4σ1k)² + 16κ²k²))/2
// with c² = T0/ρA, κ² = EI/ρA (the continuous form of maxStableStep, so slightly conservative);
// longitudinal h = max(sqrt(E/ρ) k, the transverse h).
double minimalSpacing(const StringPhysics& physics, GridRule rule, double k, double sigma1);
// M = floor(L / (factor · h_min)) segments, at least 2. Throws std::invalid_argument if factor < 1
// or the string is too short for two segments.
int gridSegments(const StringPhysics& physics, GridRule rule, double k, double sigma1,
                 double factor);

}  // namespace hamiltone
