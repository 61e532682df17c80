// The plate's stencils (DΔ, ℓ of (78)), the exact Airy solve by dense 2-D DST-I, and V', ∇V' (81).
#include "models/plate.h"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

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
  // Coefficient-wise (lazy) products: at these sizes Eigen's blocked GEMM costs more in setup
  // than the arithmetic, and lazy products never allocate.
  half_.noalias() = sx_.lazyProduct(r);
  spectral_.noalias() = half_.lazyProduct(sy_);
  spectral_.array() *= inverseSquared_.array();
  half_.noalias() = sx_.lazyProduct(spectral_);
  out.noalias() = half_.lazyProduct(sy_);
}

// (78): ℓ(f,g) = D_xx f D_yy g + D_yy f D_xx g − ½ Σ_± D_{x±}D_{y±} f · D_{x±}D_{y±} g, each
// mixed difference taken at the point with values beyond the edges zero.
void VonKarmanPlate::bracket(const Vector& f, const Vector& g, Vector& out) const {
  const double cx = 1.0 / (hx_ * hx_), cy = 1.0 / (hy_ * hy_), cxy = 1.0 / (hx_ * hy_);
  auto at = [&](const Vector& v, int l, int m) {
    return (l < 0 || l >= nx_ || m < 0 || m >= ny_) ? 0.0
                                                    : v[l + static_cast<Eigen::Index>(nx_) * m];
  };
  for (int m = 0; m < ny_; ++m)
    for (int l = 0; l < nx_; ++l) {
      auto second = [&](const Vector& v, double& xx, double& yy) {
        const double c = at(v, l, m);
        xx = cx * (at(v, l - 1, m) - 2.0 * c + at(v, l + 1, m));
        yy = cy * (at(v, l, m - 1) - 2.0 * c + at(v, l, m + 1));
      };
      auto mixed = [&](const Vector& v, int dx, int dy) {  // D_{x±}D_{y±}: dx, dy = +1 or −1
        const int l1 = l + (dx > 0 ? 1 : -1), m1 = m + (dy > 0 ? 1 : -1);
        const double d = at(v, l1, m1) - at(v, l1, m) - at(v, l, m1) + at(v, l, m);
        return cxy * d;  // the sign of D_{x−} and of D_{y−} cancel in pairs in each product
      };
      double fxx, fyy, gxx, gyy;
      second(f, fxx, fyy);
      second(g, gxx, gyy);
      double cross = 0.0;
      for (int dx : {1, -1})
        for (int dy : {1, -1}) cross += mixed(f, dx, dy) * mixed(g, dx, dy);
      out[l + static_cast<Eigen::Index>(nx_) * m] = fxx * gyy + fyy * gxx - 0.5 * cross;
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

int plateSegments(const PlatePhysics& p, double length, double k, double factor) {
  if (!(factor >= 1.0) || !std::isfinite(factor))
    throw std::invalid_argument("grid factor = " + formatNumber(factor) + ": must be >= 1");
  const double h =
      factor * 2.0 * std::sqrt(k) * std::pow(p.rigidity() / (p.density * p.thickness), 0.25);
  const double segments = std::floor(length / h);
  if (!(segments >= 2.0))
    throw std::invalid_argument("plate side " + formatNumber(length) +
                                " m is shorter than two grid "
                                "spacings h = " +
                                formatNumber(h) + " m at k = " + formatNumber(k) +
                                " s (bound (84)); use a smaller time step");
  if (segments > 2000.0)
    throw std::invalid_argument("the plate grid would have " + formatNumber(segments) +
                                " segments per side; expected at most 2000");
  return static_cast<int>(segments);
}

}  // namespace hamiltone
