// The von Kármán plate of BDZ §4.3: transverse displacement q on a simply supported rectangle, the
// Airy stress function F from DΔΔ F = −(Eξ/2) ℓ(q, q), split as (81).
#pragma once

#include <Eigen/Dense>

#include "kernels/kernels.h"
#include "schemes/hamiltonian.h"

namespace hamiltone {

struct PlatePhysics {
  double young = 2e11;        // E, Pa      (BDZ §4.3.3: steel)
  double density = 7850;      // ρ, kg/m³
  double poisson = 0.3;       // ν
  double thickness = 2e-3;    // ξ, m
  double lx = 0.5, ly = 0.5;  // m
  double rigidity() const {   // D = E ξ³ / 12 (1 − ν²)
    return young * thickness * thickness * thickness / (12.0 * (1.0 - poisson * poisson));
  }
};

// q on the (Mx−1)×(My−1) interior points x_l = l hx, y_m = m hy, stored column-major
// (l fastest). With D_xx, D_yy the second differences (zero beyond the edges), DΔ = D_xx + D_yy:
//   M = ρξ hx hy I,   K = D hx hy DΔΔ,   V' = hx hy/(2Eξ) ‖DΔ F‖²,   ∇V' = −hx hy ℓ(q, F) (80)–(81)
// with ℓ of (78), its last term read −½ D_{x−}D_{y−}f · D_{x−}D_{y−}g (SCHEMES §4). The Airy solve
// is exact: DΔ is diagonalised by the 2-D DST-I, applied as dense matrices built here. The loops
// are the kernels' (kernels/kernels.h), on copies of the grids with a zero border.
class VonKarmanPlate {
 public:
  static constexpr bool hasStiffness = true;

  // Throws std::invalid_argument naming the parameter for a non-physical plate or < 2 segments.
  VonKarmanPlate(const PlatePhysics& physics, int segmentsX, int segmentsY);

  Eigen::Index size() const { return inverseMass_.size(); }
  int nx() const { return nx_; }  // interior points along x
  int ny() const { return ny_; }
  double hx() const { return hx_; }
  double hy() const { return hy_; }
  const PlatePhysics& physics() const { return physics_; }

  const Vector& inverseMass() const { return inverseMass_; }
  void applyStiffness(const Vector& q, Vector& out) const;
  double stiffnessEigenvalueMax() const;
  double splitPotential(const Vector& q) const;
  double splitGradient(const Vector& q, Vector& grad) const;
  // M(−DΔ)(a − b): the operator of the frequency-dependent loss σ1, and λmax(−DΔ).
  void applyLossOperator(const Vector& a, const Vector& b, Vector& out) const;
  double lossOperatorEigenvalueMax() const { return laplacianEigenvalue(nx_, ny_); }

  // Eigenvalue (i, j) of −DΔ, i = 1 … nx, j = 1 … ny.
  double laplacianEigenvalue(int i, int j) const;
  // F with DΔΔ F = rhs, exactly (to roundoff), into `f`.
  void solveBiharmonic(const Vector& rhs, Vector& f) const;
  // ℓ(f, g) of (78) into `out`.
  void bracket(const Vector& f, const Vector& g, Vector& out) const;
  // DΔ f into `out`.
  void laplacian(const Vector& f, Vector& out) const;
  // The Airy stress function of a state (the last one a potential or gradient computed).
  const Vector& airy() const { return airy_; }

  void setKernels(const Kernels& kernels) noexcept { kernels_ = &kernels; }

 private:
  double airyAndPotential(const Vector& q) const;        // fills airy_, returns V'
  double airySolve(const Vector& rhs, Vector& f) const;  // solveBiharmonic; returns ‖DΔF‖²
  void pad(const double* v, Vector& padded) const;  // v's nx × ny values inside the zero border
  // out = scale × the interior of a bordered grid
  void unpad(const Vector& padded, double scale, Vector& out) const;
  void scaledLaplacian(const Vector& f, double scale, Vector& out) const;  // scale × DΔ f
  void transformX(const double* r, long ld) const;  // S_x R (R nx × ny) into half_
  void transformY() const;                          // half_ S_y into spectral_
  void padState(const Vector& q) const;             // q's bordered copy and cells
  // ℓ(q, g) into paddedOut_, g given by its bordered copy and cells
  void bracketOfState(const Vector& padded, const Vector& cells) const;

  PlatePhysics physics_;
  int nx_, ny_;
  long px_;        // a bordered row: nx + 2 values
  long rows_;      // the transforms' leading dimension: nx rounded up to a multiple of 8
  long halfRows_;  // ⌈nx/2⌉ rounded up likewise
  double hx_, hy_;
  Vector inverseMass_;
  // The orthonormal DST-I S (symmetric, its own inverse) by the parity of its rows and columns:
  // S(n − 1 − a, b) = (−1)^b S(a, b), so the first ⌈n/2⌉ rows of a transform, from the even and
  // the odd entries apart, give all n: half the products. sxEven_(a, e) = S_x(a, 2e) and
  // sxOdd_(a, o) = S_x(a, 2o + 1), a < ⌈nx/2⌉ (halfRows_ rows); syEven_(e, j) = S_y(2e, j),
  // syOdd_(o, j) = S_y(2o + 1, j), j < ⌈ny/2⌉.
  Eigen::MatrixXd sxEven_, sxOdd_, syEven_, syOdd_;
  Eigen::MatrixXd inverseSquared_;  // 1 / λ_ij² of DΔΔ, rows_ × ny (0 beyond nx)
  mutable Vector airy_, work_;
  mutable Eigen::MatrixXd spectral_, half_;  // rows_ × ny scratch of the transforms
  mutable Eigen::MatrixXd evenX_, oddX_;     // halfRows_ × ny: the half products along x
  mutable Eigen::MatrixXd evenY_, oddY_;     // rows_ × ⌈ny/2⌉: along y
  // The bordered grids (px × (ny + 2)): the state and its cells, another grid and its cells, out.
  mutable Vector paddedQ_, cellsQ_, paddedF_, cellsF_, paddedOut_;
  const Kernels* kernels_ = &selectedKernels();
};

// Initial condition (85): q = α ξ sin(πx/Lx) sin(πy/Ly).
Vector plateFirstMode(const VonKarmanPlate& plate, double alpha);

// Segments along a side of `length` from the bound (84), h >= 2 sqrt(k) (D/ρξ)^¼, times
// `factor` — tightened for a loss σ1 as maxStableStep is: with x = 1/h² and −DΔ <= 8x on a
// square grid, 16 k²κ² x² + 8 σ1 k x <= 1, κ² = D/ρξ.
int plateSegments(const PlatePhysics& physics, double length, double k, double factor,
                  double sigma1 = 0.0);

}  // namespace hamiltone
