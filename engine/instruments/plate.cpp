// The plate's stencils (DΔ, ℓ of (78)), the exact Airy solve by dense 2-D DST-I, and V', ∇V' (81).
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
  sx_ = dst1(nx_);
  sy_ = dst1(ny_);
  inverseSquared_.resize(nx_, ny_);
  for (int i = 0; i < nx_; ++i)
    for (int j = 0; j < ny_; ++j)
      inverseSquared_(i, j) = 1.0 / std::pow(laplacianEigenvalue(i + 1, j + 1), 2);
  airy_.setZero(n);
  work_.setZero(n);
  lap_.setZero(n);
  spectral_.setZero(nx_, ny_);
  half_.setZero(nx_, ny_);
  padF_.setZero(static_cast<Eigen::Index>(nx_ + 2) * (ny_ + 2));
  padG_.setZero(padF_.size());
  cellF_.setZero(static_cast<Eigen::Index>(nx_ + 1) * (ny_ + 1));
  cellG_.setZero(cellF_.size());
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

void VonKarmanPlate::laplacian(const Vector& f, Vector& out) const {
  const double cx = 1.0 / (hx_ * hx_), cy = 1.0 / (hy_ * hy_);
  for (int m = 0; m < ny_; ++m)
    for (int l = 0; l < nx_; ++l) {
      const Eigen::Index i = l + static_cast<Eigen::Index>(nx_) * m;
      const double c = f[i];
      const double w = l > 0 ? f[i - 1] : 0.0, e = l + 1 < nx_ ? f[i + 1] : 0.0;
      const double s = m > 0 ? f[i - nx_] : 0.0, nn = m + 1 < ny_ ? f[i + nx_] : 0.0;
      out[i] = cx * (w - 2.0 * c + e) + cy * (s - 2.0 * c + nn);
    }
}

void VonKarmanPlate::applyStiffness(const Vector& q, Vector& out) const {
  laplacian(q, lap_);
  laplacian(lap_, out);
  out *= physics_.rigidity() * hx_ * hy_;
}

void VonKarmanPlate::applyLossOperator(const Vector& a, const Vector& b, Vector& out) const {
  work_ = a - b;
  laplacian(work_, out);
  out *= -physics_.density * physics_.thickness * hx_ * hy_;
}

void VonKarmanPlate::solveBiharmonic(const Vector& rhs, Vector& f) const {
  const Eigen::Map<const Eigen::MatrixXd> r(rhs.data(), nx_, ny_);
  Eigen::Map<Eigen::MatrixXd> out(f.data(), nx_, ny_);
  // Eigen's blocked products: at 30 × 30 twice as fast as coefficient-wise ones; their blocking
  // buffers live on the stack at these sizes (the no-allocation test covers the plate).
  half_.noalias() = sx_ * r;
  spectral_.noalias() = half_ * sy_;
  spectral_.array() *= inverseSquared_.array();
  half_.noalias() = sx_ * spectral_;
  out.noalias() = half_ * sy_;
}

// (78): ℓ(f,g) = D_xx f D_yy g + D_yy f D_xx g − ½ Σ_± D_{x±}D_{y±} f · D_{x±}D_{y±} g. On arrays
// padded with the zero boundary, each mixed difference at a point is a cell difference
// c(l, m) = f(l+1, m+1) − f(l+1, m) − f(l, m+1) + f(l, m) of one of the four cells around it, so
// both are computed once per array and the point loop has no branch.
void VonKarmanPlate::bracket(const Vector& f, const Vector& g, Vector& out) const {
  const int px = nx_ + 2;  // padded row length
  const int cx = nx_ + 1;  // cells per row
  auto pad = [&](const Vector& v, Vector& padded, Vector& cells) {
    for (int m = 0; m < ny_; ++m)
      for (int l = 0; l < nx_; ++l) padded[(l + 1) + px * (m + 1)] = v[l + nx_ * m];
    for (int m = 0; m <= ny_; ++m)
      for (int l = 0; l <= nx_; ++l) {
        const double* p = padded.data() + l + px * m;
        cells[l + cx * m] = p[px + 1] - p[1] - p[px] + p[0];
      }
  };
  pad(f, padF_, cellF_);
  pad(g, padG_, cellG_);
  const double ix2 = 1.0 / (hx_ * hx_), iy2 = 1.0 / (hy_ * hy_),
               ixy2 = 1.0 / (hx_ * hy_ * hx_ * hy_);
  for (int m = 0; m < ny_; ++m) {
    const double* fp = padF_.data() + 1 + px * (m + 1);  // the point (l, m) at fp[l]
    const double* gp = padG_.data() + 1 + px * (m + 1);
    const double* fc = cellF_.data() + cx * m;  // cells (l−1 … l, m−1 … m) at fc[l], fc[l+1], …
    const double* gc = cellG_.data() + cx * m;
    double* o = out.data() + nx_ * m;
#pragma omp simd
    for (int l = 0; l < nx_; ++l) {
      const double fxx = (fp[l - 1] - 2.0 * fp[l] + fp[l + 1]) * ix2;
      const double fyy = (fp[l - px] - 2.0 * fp[l] + fp[l + px]) * iy2;
      const double gxx = (gp[l - 1] - 2.0 * gp[l] + gp[l + 1]) * ix2;
      const double gyy = (gp[l - px] - 2.0 * gp[l] + gp[l + px]) * iy2;
      // cells around point (l, m): (l−1, m−1) … (l, m), i.e. fc[l], fc[l+1], fc[l+cx], fc[l+1+cx]
      const double cross = fc[l] * gc[l] + fc[l + 1] * gc[l + 1] + fc[l + cx] * gc[l + cx] +
                           fc[l + 1 + cx] * gc[l + 1 + cx];
      o[l] = fxx * gyy + fyy * gxx - 0.5 * cross * ixy2;
    }
  }
}

double VonKarmanPlate::airyAndPotential(const Vector& q) const {
  bracket(q, q, work_);
  work_ *= -0.5 * physics_.young * physics_.thickness;  // DΔΔ F = −(Eξ/2) ℓ(q, q)   (79)
  solveBiharmonic(work_, airy_);
  laplacian(airy_, lap_);
  return hx_ * hy_ / (2.0 * physics_.young * physics_.thickness) * lap_.squaredNorm();  // (81)
}

double VonKarmanPlate::splitPotential(const Vector& q) const { return airyAndPotential(q); }

double VonKarmanPlate::splitGradient(const Vector& q, Vector& grad) const {
  const double v = airyAndPotential(q);
  bracket(q, airy_, grad);
  grad *= -hx_ * hy_;  // ∇V' = −hx hy ℓ(q, F)
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
  return segmentsAlong(length, h, k, 2000.0, "plate side", "bound (84)");
}

}  // namespace hamiltone
