// The plate's linearly implicit scheme (83): ℓ(q^n, ·) as a matrix, the SPD solve for F^{n+1}.
#include "schemes/reference/linearly_implicit_plate.h"

#include <stdexcept>
#include <string>
#include <vector>

#include "util/format_number.h"

namespace hamiltone {

namespace {

using Triplets = std::vector<Eigen::Triplet<double>>;

// D_xx (along x, 1/hx²) or D_yy as a sparse matrix, zero beyond the edges.
Eigen::SparseMatrix<double> secondDifference(const VonKarmanPlate& plate, bool alongX) {
  const int nx = plate.nx(), ny = plate.ny();
  const double c = alongX ? 1.0 / (plate.hx() * plate.hx()) : 1.0 / (plate.hy() * plate.hy());
  const Eigen::Index stride = alongX ? 1 : nx;
  Triplets entries;
  for (int m = 0; m < ny; ++m)
    for (int l = 0; l < nx; ++l) {
      const Eigen::Index i = l + static_cast<Eigen::Index>(nx) * m;
      const int along = alongX ? l : m, count = alongX ? nx : ny;
      entries.emplace_back(i, i, -2.0 * c);
      if (along > 0) entries.emplace_back(i, i - stride, c);
      if (along + 1 < count) entries.emplace_back(i, i + stride, c);
    }
  Eigen::SparseMatrix<double> d(plate.size(), plate.size());
  d.setFromTriplets(entries.begin(), entries.end());
  return d;
}

}  // namespace

// (78) row by row: ℓ(f, g)_p = f_xx D_yy g + f_yy D_xx g − ½/(hx hy)² Σ_c c_f c_g over the four
// cells c around p, c_g = g(x1, y1) − g(x1, y0) − g(x0, y1) + g(x0, y0) (as
// VonKarmanPlate::bracket).
Eigen::SparseMatrix<double> bracketMatrix(const VonKarmanPlate& plate, const Vector& f) {
  const int nx = plate.nx(), ny = plate.ny();
  const double ix2 = 1.0 / (plate.hx() * plate.hx()), iy2 = 1.0 / (plate.hy() * plate.hy());
  const double ixy2 = ix2 * iy2;
  auto index = [nx](int l, int m) { return l + static_cast<Eigen::Index>(nx) * m; };
  auto inside = [nx, ny](int l, int m) { return l >= 0 && l < nx && m >= 0 && m < ny; };
  auto at = [&](int l, int m) { return inside(l, m) ? f[index(l, m)] : 0.0; };
  Triplets entries;
  entries.reserve(static_cast<std::size_t>(22 * plate.size()));
  for (int m = 0; m < ny; ++m)
    for (int l = 0; l < nx; ++l) {
      const Eigen::Index p = index(l, m);
      const double fxx = (at(l - 1, m) - 2.0 * at(l, m) + at(l + 1, m)) * ix2;
      const double fyy = (at(l, m - 1) - 2.0 * at(l, m) + at(l, m + 1)) * iy2;
      auto add = [&](int lq, int mq, double value) {
        if (inside(lq, mq)) entries.emplace_back(p, index(lq, mq), value);
      };
      add(l, m, -2.0 * (fxx * iy2 + fyy * ix2));  // f_xx D_yy g + f_yy D_xx g
      add(l, m - 1, fxx * iy2);
      add(l, m + 1, fxx * iy2);
      add(l - 1, m, fyy * ix2);
      add(l + 1, m, fyy * ix2);
      for (int b = -1; b <= 0; ++b)  // the cell with corners (l+a … l+a+1, m+b … m+b+1)
        for (int a = -1; a <= 0; ++a) {
          const int x0 = l + a, y0 = m + b, x1 = x0 + 1, y1 = y0 + 1;
          const double w =
              -0.5 * ixy2 * (at(x1, y1) - at(x1, y0) - at(x0, y1) + at(x0, y0));  // −½ c_f
          add(x1, y1, w);
          add(x1, y0, -w);
          add(x0, y1, -w);
          add(x0, y0, w);
        }
    }
  Eigen::SparseMatrix<double> matrix(plate.size(), plate.size());
  matrix.setFromTriplets(entries.begin(), entries.end());  // sums duplicates, keeps zeros
  return matrix;
}

LinearlyImplicitPlate::LinearlyImplicitPlate(const VonKarmanPlate& plate,
                                             const StepParameters& params,
                                             const InitialState& start)
    : plate_(plate), k_(params.k) {
  checkStepParameters(params, false);
  if (params.sigma0 != 0.0 || params.sigma1 != 0.0)
    throw std::invalid_argument("loss sigma0 = " + formatNumber(params.sigma0) +
                                ", sigma1 = " + formatNumber(params.sigma1) +
                                ": the linearly implicit reference (83) is lossless only");
  checkInitialState(start, plate_.size());
  laplacian_ = secondDifference(plate_, true) + secondDifference(plate_, false);  // (76)
  biharmonic_ = laplacian_ * laplacian_;

  // (21): q^1 = q^0 + k M⁻¹p − k²/2 M⁻¹∇V(q^0).
  const Vector& minv = plate_.inverseMass();
  Vector grad(plate_.size()), scratch(plate_.size());
  fullGradient(plate_, start.q, grad, scratch);
  prev_ = start.q;
  curr_ = prev_ + k_ * minv.cwiseProduct(start.p) - 0.5 * k_ * k_ * minv.cwiseProduct(grad);

  // F^0 = the Airy function of q^0, DΔΔ F^0 = −(Eξ/2) ℓ(q^0, q^0) (79); F^1 from (83b).
  const PlatePhysics& p = plate_.physics();
  plate_.splitPotential(prev_);
  fPrev_ = plate_.airy();
  fCurr_.resize(plate_.size());
  plate_.bracket(curr_, prev_, scratch);
  scratch *= -p.young * p.thickness;
  plate_.solveBiharmonic(scratch, fCurr_);
  fCurr_ -= fPrev_;
}

void LinearlyImplicitPlate::step() {
  const PlatePhysics& p = plate_.physics();
  const double a = p.density * p.thickness / (k_ * k_);
  const double eXi = p.young * p.thickness;
  // Levels n+1, n become n+2, n+1: here q^n = curr_, q^{n−1} = prev_, likewise F.
  const Eigen::SparseMatrix<double> bracket = bracketMatrix(plate_, curr_);  // L = ℓ(q^n, ·)
  const Vector r = 2.0 * curr_ - prev_ - (p.rigidity() / a) * (biharmonic_ * curr_) +
                   (0.5 / a) * (bracket * fPrev_);
  const Eigen::SparseMatrix<double> system =
      biharmonic_ + (0.5 * eXi / a) * (bracket * bracket);  // DΔΔ + s L²
  if (!analysed_) {
    solver_.analyzePattern(system);
    analysed_ = true;
  }
  solver_.factorize(system);
  if (solver_.info() != Eigen::Success)
    throw std::runtime_error("linearly implicit plate (83): the factorisation failed at step " +
                             std::to_string(n_ + 1));
  const Vector rhs = -(biharmonic_ * fCurr_) - eXi * (bracket * r);
  fPrev_ = solver_.solve(rhs);                 // F^{n+1}, (83b)
  prev_ = r + (0.5 / a) * (bracket * fPrev_);  // q^{n+1}, (83a)
  prev_.swap(curr_);
  fPrev_.swap(fCurr_);
  ++n_;
}

Energy LinearlyImplicitPlate::energy() const {
  const PlatePhysics& p = plate_.physics();
  const double area = plate_.hx() * plate_.hy();
  const double airy = area / (2.0 * p.young * p.thickness) *
                      ((laplacian_ * fCurr_).squaredNorm() + (laplacian_ * fPrev_).squaredNorm());
  Vector kq(plate_.size());
  plate_.applyStiffness(prev_, kq);
  Energy e;
  e.kinetic = intervalKineticEnergy(plate_.inverseMass(), prev_, curr_, k_);
  e.potential = 0.5 * curr_.dot(kq) + 0.5 * airy;
  return e;
}

}  // namespace hamiltone
