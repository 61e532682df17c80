// The plate's stencils (DΔ, ℓ of (78)), the exact Airy solve by dense 2-D DST-I, and V', ∇V' (81),
// on the kernels' loops.
#include "instruments/plate.h"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "instruments/grid.h"
#include "util/format_number.h"

namespace hamiltone {

namespace {

void requirePositive(const char* name, double value, const char* unit) {
  if (!std::isfinite(value) || value <= 0.0)
    throw std::invalid_argument(std::string(name) + " = " + formatNumber(value) +
                                ": must be a finite number > 0 (" + unit + ")");
}

// Orthonormal DST-I of size n: S_ab = sqrt(2/(n+1)) sin(π a b/(n+1)); S = Sᵀ = S⁻¹.
Eigen::MatrixXd dst1(int n) {
  Eigen::MatrixXd s(n, n);
  const double c = std::sqrt(2.0 / (n + 1));
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b)
      s(a, b) = c * std::sin(std::numbers::pi * (a + 1) * (b + 1) / (n + 1));
  return s;
}

}  // namespace

VonKarmanPlate::VonKarmanPlate(const PlatePhysics& p, int segmentsX, int segmentsY) : physics_(p) {
  requirePositive("young", p.young, "Pa");
  requirePositive("density", p.density, "kg/m^3");
  requirePositive("thickness", p.thickness, "m");
  requirePositive("lx", p.lx, "m");
  requirePositive("ly", p.ly, "m");
  if (!(p.poisson > -1.0 && p.poisson < 0.5))
    throw std::invalid_argument("poisson = " + formatNumber(p.poisson) +
                                ": must be between -1 and 0.5 (an isotropic solid)");
  if (segmentsX < 2 || segmentsY < 2)
    throw std::invalid_argument("the plate grid needs at least 2 segments per side, got " +
                                std::to_string(segmentsX) + " x " + std::to_string(segmentsY));
  nx_ = segmentsX - 1;
  ny_ = segmentsY - 1;
  hx_ = p.lx / segmentsX;
  hy_ = p.ly / segmentsY;
  const Eigen::Index n = static_cast<Eigen::Index>(nx_) * ny_;
  inverseMass_ = Vector::Constant(n, 1.0 / (p.density * p.thickness * hx_ * hy_));
  px_ = nx_ + 2;
  rows_ = (nx_ + 7) / 8 * 8;
  const int halfX = (nx_ + 1) / 2, halfY = (ny_ + 1) / 2;
  halfRows_ = (halfX + 7) / 8 * 8;
  const Eigen::MatrixXd sx = dst1(nx_), sy = dst1(ny_);
  sxEven_.setZero(halfRows_, (nx_ + 1) / 2);
  sxOdd_.setZero(halfRows_, nx_ / 2);
  for (int a = 0; a < halfX; ++a) {
    for (int e = 0; e < sxEven_.cols(); ++e) sxEven_(a, e) = sx(a, 2 * e);
    for (int o = 0; o < sxOdd_.cols(); ++o) sxOdd_(a, o) = sx(a, 2 * o + 1);
  }
  syEven_.setZero((ny_ + 1) / 2, halfY);
  syOdd_.setZero(ny_ / 2, halfY);
  for (int j = 0; j < halfY; ++j) {
    for (int e = 0; e < syEven_.rows(); ++e) syEven_(e, j) = sy(2 * e, j);
    for (int o = 0; o < syOdd_.rows(); ++o) syOdd_(o, j) = sy(2 * o + 1, j);
  }
  evenX_.setZero(halfRows_, ny_);
  oddX_.setZero(halfRows_, ny_);
  evenY_.setZero(rows_, halfY);
  oddY_.setZero(rows_, halfY);
  inverseSquared_.setZero(rows_, ny_);
  for (int i = 0; i < nx_; ++i)
    for (int j = 0; j < ny_; ++j)
      inverseSquared_(i, j) = 1.0 / std::pow(laplacianEigenvalue(i + 1, j + 1), 2);
  airy_.setZero(n);
  work_.setZero(n);
  spectral_.setZero(rows_, ny_);
  half_.setZero(rows_, ny_);
  const Eigen::Index bordered = px_ * (ny_ + 2);
  for (Vector* v : {&paddedQ_, &cellsQ_, &paddedF_, &cellsF_, &paddedOut_}) v->setZero(bordered);
}

double VonKarmanPlate::laplacianEigenvalue(int i, int j) const {
  const double sx = std::sin(i * std::numbers::pi / (2.0 * (nx_ + 1)));
  const double sy = std::sin(j * std::numbers::pi / (2.0 * (ny_ + 1)));
  return 4.0 / (hx_ * hx_) * sx * sx + 4.0 / (hy_ * hy_) * sy * sy;
}

double VonKarmanPlate::stiffnessEigenvalueMax() const {
  const double d = physics_.rigidity() / (physics_.density * physics_.thickness);
  return d * std::pow(laplacianEigenvalue(nx_, ny_), 2);
}

void VonKarmanPlate::pad(const double* v, Vector& padded) const {
  for (int m = 0; m < ny_; ++m) {
    const double* row = v + static_cast<Eigen::Index>(nx_) * m;
    double* p = padded.data() + 1 + px_ * (m + 1);
    for (int l = 0; l < nx_; ++l) p[l] = row[l];  // rows of ~30: a call to memmove costs more
  }
}

void VonKarmanPlate::unpad(const Vector& padded, double scale, Vector& out) const {
  for (int m = 0; m < ny_; ++m) {
    const double* row = padded.data() + 1 + px_ * (m + 1);
    double* o = out.data() + static_cast<Eigen::Index>(nx_) * m;
    for (int l = 0; l < nx_; ++l) o[l] = row[l] * scale;
  }
}

void VonKarmanPlate::laplacian(const Vector& f, Vector& out) const { scaledLaplacian(f, 1.0, out); }

void VonKarmanPlate::scaledLaplacian(const Vector& f, double scale, Vector& out) const {
  pad(f.data(), paddedF_);
  kernels_->gridLaplacian(paddedF_.data(), px_, ny_, 1.0 / (hx_ * hx_), 1.0 / (hy_ * hy_),
                          paddedOut_.data());
  unpad(paddedOut_, scale, out);
}

void VonKarmanPlate::applyStiffness(const Vector& q, Vector& out) const {
  const double cx = 1.0 / (hx_ * hx_), cy = 1.0 / (hy_ * hy_);
  pad(q.data(), paddedF_);
  kernels_->gridLaplacian(paddedF_.data(), px_, ny_, cx, cy, paddedOut_.data());
  kernels_->gridLaplacian(paddedOut_.data(), px_, ny_, cx, cy, paddedF_.data());
  unpad(paddedF_, physics_.rigidity() * hx_ * hy_, out);
}

void VonKarmanPlate::applyLossOperator(const Vector& a, const Vector& b, Vector& out) const {
  work_ = a - b;
  scaledLaplacian(work_, -physics_.density * physics_.thickness * hx_ * hy_, out);
}

void VonKarmanPlate::transformX(const double* r, long ld) const {
  const int high = nx_ / 2;  // rows nx − 1 down to ⌈nx/2⌉: from the half products' first ones
  kernels_->matrixProduct(sxEven_.data(), halfRows_, r, ld, 2, evenX_.data(), halfRows_, halfRows_,
                          sxEven_.cols(), ny_);
  kernels_->matrixProduct(sxOdd_.data(), halfRows_, r + 1, ld, 2, oddX_.data(), halfRows_,
                          halfRows_, sxOdd_.cols(), ny_);
  for (int j = 0; j < ny_; ++j) {
    const double* e = evenX_.col(j).data();
    const double* o = oddX_.col(j).data();
    double* h = half_.col(j).data();
    for (int a = 0; a < (nx_ + 1) / 2; ++a) h[a] = e[a] + o[a];
    for (int a = 0; a < high; ++a) h[nx_ - 1 - a] = e[a] - o[a];
  }
}

void VonKarmanPlate::transformY() const {
  const int low = (ny_ + 1) / 2, high = ny_ / 2;
  kernels_->matrixProduct(half_.data(), 2 * rows_, syEven_.data(), syEven_.rows(), 1, evenY_.data(),
                          rows_, rows_, syEven_.rows(), low);
  kernels_->matrixProduct(half_.data() + rows_, 2 * rows_, syOdd_.data(), syOdd_.rows(), 1,
                          oddY_.data(), rows_, rows_, syOdd_.rows(), low);
  for (int j = 0; j < low; ++j) spectral_.col(j) = evenY_.col(j) + oddY_.col(j);
  for (int j = 0; j < high; ++j) spectral_.col(ny_ - 1 - j) = evenY_.col(j) - oddY_.col(j);
}

void VonKarmanPlate::solveBiharmonic(const Vector& rhs, Vector& f) const { airySolve(rhs, f); }

double VonKarmanPlate::airySolve(const Vector& rhs, Vector& f) const {
  transformX(rhs.data(), nx_);  // R̂ = S_x R S_y
  transformY();
  // ‖DΔF‖² = Σ λ² F̂² = Σ R̂²/λ² (the transforms are orthonormal; F̂ = R̂/λ²)
  const double norm = (spectral_.array().square() * inverseSquared_.array()).sum();
  spectral_.array() *= inverseSquared_.array();  // F̂ = R̂ / λ²
  transformX(spectral_.data(), rows_);           // F = S_x F̂ S_y
  transformY();
  Eigen::Map<Eigen::MatrixXd>(f.data(), nx_, ny_) = spectral_.topRows(nx_);
  return norm;
}

// ℓ(f, g) of (78), on bordered copies: each mixed difference at a point is a cell difference of one
// of the four cells around it, so the cells are computed once per grid and the point loop has no
// branch. The state's copy and cells (paddedQ_, cellsQ_) serve both brackets of a gradient.
void VonKarmanPlate::padState(const Vector& q) const {
  pad(q.data(), paddedQ_);
  kernels_->gridCells(paddedQ_.data(), px_, ny_, cellsQ_.data());
}

void VonKarmanPlate::bracketOfState(const Vector& padded, const Vector& cells) const {
  const double ix2 = 1.0 / (hx_ * hx_), iy2 = 1.0 / (hy_ * hy_),
               ixy2 = 1.0 / (hx_ * hy_ * hx_ * hy_);
  kernels_->gridBracket(paddedQ_.data(), padded.data(), cellsQ_.data(), cells.data(), px_, ny_, ix2,
                        iy2, ixy2, paddedOut_.data());
}

void VonKarmanPlate::bracket(const Vector& f, const Vector& g, Vector& out) const {
  padState(f);
  pad(g.data(), paddedF_);
  kernels_->gridCells(paddedF_.data(), px_, ny_, cellsF_.data());
  bracketOfState(paddedF_, cellsF_);
  unpad(paddedOut_, 1.0, out);
}

double VonKarmanPlate::airyAndPotential(const Vector& q) const {
  padState(q);
  bracketOfState(paddedQ_, cellsQ_);
  // DΔΔ F = −(Eξ/2) ℓ(q, q)   (79)
  unpad(paddedOut_, -0.5 * physics_.young * physics_.thickness, work_);
  const double norm = airySolve(work_, airy_);
  pad(airy_.data(), paddedF_);  // F's bordered copy, for the gradient's bracket
  return hx_ * hy_ / (2.0 * physics_.young * physics_.thickness) * norm;  // (81)
}

double VonKarmanPlate::splitPotential(const Vector& q) const { return airyAndPotential(q); }

double VonKarmanPlate::splitGradient(const Vector& q, Vector& grad) const {
  const double v = airyAndPotential(q);
  kernels_->gridCells(paddedF_.data(), px_, ny_, cellsF_.data());
  bracketOfState(paddedF_, cellsF_);
  unpad(paddedOut_, -hx_ * hy_, grad);  // ∇V' = −hx hy ℓ(q, F)
  return v;
}

Vector plateFirstMode(const VonKarmanPlate& plate, double alpha) {
  Vector q(plate.size());
  const double a = alpha * plate.physics().thickness;
  for (int m = 0; m < plate.ny(); ++m)
    for (int l = 0; l < plate.nx(); ++l)
      q[l + static_cast<Eigen::Index>(plate.nx()) * m] =
          a * std::sin(std::numbers::pi * (l + 1) / (plate.nx() + 1)) *
          std::sin(std::numbers::pi * (m + 1) / (plate.ny() + 1));
  return q;
}

int plateSegments(const PlatePhysics& p, double length, double k, double factor, double sigma1) {
  if (!(factor >= 1.0) || !std::isfinite(factor))
    throw std::invalid_argument("grid factor = " + formatNumber(factor) + ": must be >= 1");
  const double kappa = std::sqrt(p.rigidity() / (p.density * p.thickness));
  const double a = 16.0 * k * k * kappa * kappa, b = 8.0 * sigma1 * k;
  const double xMax = (-b + std::sqrt(b * b + 4.0 * a)) / (2.0 * a);  // the largest 1/h²
  const double h = factor / std::sqrt(xMax);
  return segmentsAlong(length, h, k, 2000.0, "plate side", "bound (84)", factor > 1.0);
}

}  // namespace hamiltone
