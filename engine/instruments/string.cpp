// The string's stiffness stencils and its split potential (65) with the gradient by the chain rule.
#include "instruments/string.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

#include "instruments/grid.h"
#include "schemes/linear_loss.h"
#include "util/format_number.h"

namespace hamiltone {

namespace {

void requirePositive(const char* name, double value, const char* unit) {
  if (!std::isfinite(value) || value <= 0.0)
    throw std::invalid_argument(std::string(name) + " = " + formatNumber(value) +
                                ": must be a finite number > 0 (" + unit + ")");
}

}  // namespace

NonlinearString::NonlinearString(const StringPhysics& p, StringGrid grid)
    : physics_(p), grid_(grid), segments_(grid.transverse) {
  requirePositive("density", p.density, "kg/m^3");
  requirePositive("area", p.area, "m^2");
  requirePositive("length", p.length, "m");
  requirePositive("young", p.young, "Pa");
  requirePositive("tension", p.tension, "N");
  if (!std::isfinite(p.inertia) || p.inertia < 0.0)
    throw std::invalid_argument("inertia = " + formatNumber(p.inertia) +
                                ": must be a finite number >= 0 (m^4)");
  if (p.young * p.area <= p.tension)
    throw std::invalid_argument("tension = " + formatNumber(p.tension) +
                                " N: must be below E*A = " + formatApprox(p.young * p.area) +
                                " N, or the split potential (65) is not >= 0");
  if (grid.transverse < 2)
    throw std::invalid_argument("segments = " + std::to_string(grid.transverse) + ": must be >= 2");
  if (grid.longitudinal < 1 || grid.transverse % grid.longitudinal != 0)
    throw std::invalid_argument("longitudinal segments = " + std::to_string(grid.longitudinal) +
                                ": must be >= 1 and divide the " + std::to_string(grid.transverse) +
                                " transverse segments");
  ratio_ = grid.transverse / grid.longitudinal;
  h_ = p.length / grid.transverse;
  hv_ = p.length / grid.longitudinal;
  const Eigen::Index nu = grid.transverse - 1, nv = grid.longitudinal - 1;
  inverseMass_.resize(nu + nv);
  inverseMass_.head(nu).setConstant(1.0 / (p.linearDensity() * h_));
  inverseMass_.tail(nv).setConstant(1.0 / (p.linearDensity() * hv_));
  work1_.setZero(grid.transverse);
  work2_.setZero(grid.transverse);
  work3_.setZero(grid.transverse + 1);
  for (Vector* w : {&cell1_, &cell2_, &cell3_}) w->setZero(grid.longitudinal);
  scratch_.setZero(grid.transverse + 1);
  if (ratio_ > 1 && grid.longitudinal > 1)
    forcesWork_.setZero(twoGridWork(grid.transverse, grid.longitudinal));
  d2_.setZero(nu);
  d2Prev_.setZero(nu);
}

void NonlinearString::applyStiffness(const Vector& q, Vector& out) const {
  const Eigen::Index n = segments_ - 1;
  const double invH2 = 1.0 / (h_ * h_);
  longitudinalStiffness(q, out);
  const double t = tensionScale_ * physics_.tension * h_;
  if (physics_.inertia == 0.0) {
    kernels_->secondDifference(q.data(), out.data(), n, -t * invH2);  // −βT0 h D2 u
    return;
  }
  // h (−βT0 D2 + EI D2²) u. D2² with D2 u = 0 at the ends is the simply supported biharmonic.
  const double ei = physics_.young * physics_.inertia * h_;
  kernels_->stiffStencil(q.data(), work1_.data(), out.data(), n, invH2, t, ei);
}

double NonlinearString::transverseEigenvalue(int m) const {
  return transverseEigenvalue(m, tensionScale_);
}

double NonlinearString::transverseEigenvalue(int m, double scale) const {
  const double s = std::sin(m * std::numbers::pi / (2.0 * segments_));
  const double rhoA = physics_.linearDensity();
  const double h2 = h_ * h_;
  return scale * physics_.tension / rhoA * 4.0 / h2 * s * s +
         physics_.young * physics_.inertia / rhoA * 16.0 / (h2 * h2) * s * s * s * s;
}

double NonlinearString::longitudinalEigenvalue(int m) const {
  const double s = std::sin(m * std::numbers::pi / (2.0 * grid_.longitudinal));
  return physics_.tension / physics_.linearDensity() * 4.0 / (hv_ * hv_) * s * s;
}

void NonlinearString::setTensionRange(double maxScale) {
  // An octave up is 4× the tension on an ideal string; 4 + 3B on a stiff one (the fundamental's
  // stiffness term does not scale), so the largest bend (12 semitones) needs a little over 4.
  if (!(maxScale >= 1.0 && maxScale <= 5.0))
    throw std::invalid_argument("tension scale range " + formatNumber(maxScale) +
                                ": must be between 1 and 5 (an octave of bend up, stiffness "
                                "included)");
  tensionScaleMax_ = maxScale;
  tensionScale_ = 1.0;
}

double NonlinearString::stiffnessEigenvalueMax() const {
  // At the largest β the range allows; >= the longitudinal eigenvalue, mode by mode.
  return transverseEigenvalue(segments_ - 1, tensionScaleMax_);
}

void NonlinearString::setLossWeights(const LossWeights& w) {
  const std::pair<const char*, double> weights[] = {
      {"transverse", w.transverse},
      {"longitudinalConstant", w.longitudinalConstant},
      {"longitudinal", w.longitudinal}};
  for (const auto& [name, x] : weights)
    if (!(std::isfinite(x) && x >= 0.0))
      throw std::invalid_argument(std::string("loss weight ") + name + " = " + formatNumber(x) +
                                  ": must be a finite number >= 0 (C = M(−Λ) must stay >= 0)");
  lossWeights_ = w;
}

namespace {

// −D2's top eigenvalue on a grid of m segments of h.
double topOfMinusD2(int m, double h) {
  const double s = std::sin((m - 1) * std::numbers::pi / (2.0 * m));
  return 4.0 / (h * h) * s * s;
}

}  // namespace

double NonlinearString::transverseLossTop() const {
  return lossWeights_.transverse * topOfMinusD2(segments_, h_);
}

double NonlinearString::longitudinalLossTop() const {
  return lossWeights_.longitudinalConstant +
         lossWeights_.longitudinal * topOfMinusD2(grid_.longitudinal, hv_);
}

double NonlinearString::lossOperatorEigenvalueMax() const {
  // The blocks are apart, so the largest is the larger block's.
  if (grid_.longitudinal < 2) return transverseLossTop();
  return std::max(transverseLossTop(), longitudinalLossTop());
}

double NonlinearString::maxStableStep(double sigma1) const {
  return blockStableStep(sigma1, physics_.tension);
}

double NonlinearString::linearisedMaxStableStep(double sigma1) const {
  return blockStableStep(sigma1, physics_.young * physics_.area);
}

double NonlinearString::blockStableStep(double sigma1, double vTension) const {
  const double u = hamiltone::maxStableStep(stiffnessEigenvalueMax(), transverseLossTop(), sigma1);
  if (grid_.longitudinal < 2) return u;
  const double vTop = vTension / physics_.tension * longitudinalEigenvalue(grid_.longitudinal - 1);
  return std::min(u, hamiltone::maxStableStep(vTop, longitudinalLossTop(), sigma1));
}

double NonlinearString::linearEndTension(const Vector& q) const {
  const int mv = grid_.longitudinal;
  // η_M = −v_{Mv−1}/h_v; EA / h_v depends on constants alone, so the product does not wait on it.
  return mv < 2 ? 0.0 : -q[segments_ - 1 + mv - 2] * (physics_.young * physics_.area / hv_);
}

void NonlinearString::applyLossOperator(const Vector& a, const Vector& b, Vector& out) const {
  const Eigen::Index nu = segments_ - 1;
  // M (−Λ) = −ρA h w D2 on each grid with its own h and weight, and ρA h_v w_v0 I on v.
  const double rhoA = physics_.linearDensity();
  kernels_->secondDifferenceOfDifference(a.data(), b.data(), out.data(), nu,
                                         -rhoA * lossWeights_.transverse / h_);
  longitudinalLoss(a, b, out);
}

// C(a − b) on v: ρA h_v (w_v1 (−D2)/h_v² + w_v0 I)(a − b) (none where Mv = 1).
void NonlinearString::longitudinalLoss(const Vector& a, const Vector& b, Vector& out) const {
  const Eigen::Index nu = segments_ - 1, nv = grid_.longitudinal - 1;
  if (nv == 0) return;
  const double rhoA = physics_.linearDensity();
  kernels_->secondDifferenceOfDifference(a.data() + nu, b.data() + nu, out.data() + nu, nv,
                                         -rhoA * lossWeights_.longitudinal / hv_);
  if (lossWeights_.longitudinalConstant > 0.0)
    out.segment(nu, nv) +=
        (rhoA * hv_ * lossWeights_.longitudinalConstant) * (a.segment(nu, nv) - b.segment(nu, nv));
}

void NonlinearString::applyStiffnessAndLoss(const Vector& q, const Vector& qPrev, bool prevKept,
                                            Vector& kq, Vector& cq) const {
  const Eigen::Index nu = segments_ - 1;
  if (physics_.inertia == 0.0) {  // the stiffness is a single second difference: nothing to share
    applyStiffness(q, kq);
    applyLossOperator(q, qPrev, cq);
    return;
  }
  const double invH2 = 1.0 / (h_ * h_);
  if (!prevKept) kernels_->secondDifference(qPrev.data(), d2Prev_.data(), nu, invH2);
  const double rhoA = physics_.linearDensity();
  kernels_->stiffLossStencil(q.data(), d2_.data(), d2Prev_.data(), kq.data(), cq.data(), nu, invH2,
                             tensionScale_ * physics_.tension * h_,
                             physics_.young * physics_.inertia * h_,
                             -rhoA * lossWeights_.transverse * h_);
  d2_.swap(d2Prev_);
  if (ratio_ > 1 && grid_.longitudinal <= kFewCoarseCells)
    return coarseStiffnessAndLoss(q, qPrev, kq, cq);
  longitudinalStiffness(q, kq);
  longitudinalLoss(q, qPrev, cq);
}

// longitudinalStiffness and longitudinalLoss in one sweep over the few coarse nodes of the two
// grids' shorter strings (Mv <= kFewCoarseCells: F3 and up), where two kernel calls and a vector
// expression cost more than the sweep (C5: 3.5 % of a key; on A0's 42 nodes the kernels are 2–4 %
// faster); the same operations, v = 0 beyond both ends.
void NonlinearString::coarseStiffnessAndLoss(const Vector& q, const Vector& qPrev, Vector& kq,
                                             Vector& cq) const {
  const Eigen::Index nu = segments_ - 1, nv = grid_.longitudinal - 1;
  if (nv == 0) return;
  const double* v = q.data() + nu;
  const double* w = qPrev.data() + nu;
  double* kv = kq.data() + nu;
  double* cv = cq.data() + nu;
  const double rhoA = physics_.linearDensity();
  const double stiffness = -(linearised_ ? physics_.young * physics_.area : physics_.tension) / hv_;
  const double loss = -rhoA * lossWeights_.longitudinal / hv_;
  // −T0 h_v D2 v and ρA w_v1 h_v (−D2)(v − w) at node j from its neighbours' values.
  auto node = [&](Eigen::Index j, double left, double right, double dLeft, double dRight) {
    kv[j] = stiffness * (left - 2.0 * v[j] + right);
    cv[j] = loss * (dLeft - 2.0 * (v[j] - w[j]) + dRight);
  };
  if (nv == 1) {
    node(0, 0.0, 0.0, 0.0, 0.0);
  } else {
    node(0, 0.0, v[1], 0.0, v[1] - w[1]);
#pragma omp simd
    for (Eigen::Index j = 1; j < nv - 1; ++j)
      node(j, v[j - 1], v[j + 1], v[j - 1] - w[j - 1], v[j + 1] - w[j + 1]);
    node(nv - 1, v[nv - 2], 0.0, v[nv - 2] - w[nv - 2], 0.0);
  }
  if (lossWeights_.longitudinalConstant > 0.0) {
    const double constant = rhoA * hv_ * lossWeights_.longitudinalConstant;
#pragma omp simd
    for (Eigen::Index j = 0; j < nv; ++j) cv[j] += constant * (v[j] - w[j]);  // ρA h_v w_v0 (v − w)
  }
}

// K q on v: −T0 h_v D2 v; the linear string's −EA h_v D2 v (none where Mv = 1).
void NonlinearString::longitudinalStiffness(const Vector& q, Vector& out) const {
  const Eigen::Index nu = segments_ - 1, nv = grid_.longitudinal - 1;
  if (nv == 0) return;
  const double vTension = linearised_ ? physics_.young * physics_.area : physics_.tension;
  kernels_->secondDifference(q.data() + nu, out.data() + nu, nv, -vTension / hv_);
}

namespace {

// One segment's share of (65): with ζ, η its strains, returns (s − 1)² and sets φ (s − 1)/s, the
// factor of ∂V'/∂ζ = c φ ζ and ∂V'/∂η = c φ (1 + η). s − 1 = (2η + η² + ζ²)/(s + 1): no
// cancellation at small strain.
inline double segmentExcess(double zeta, double eta, double& phi) {
  const double stretch = std::sqrt((1.0 + eta) * (1.0 + eta) + zeta * zeta);
  const double excess = (2.0 * eta + eta * eta + zeta * zeta) / (stretch + 1.0);
  phi = excess / stretch;
  return excess * excess;
}

}  // namespace

double NonlinearString::splitPotential(const Vector& q) const {
  return ratio_ == 1 ? singleGridPotential(q) : twoGridPotential(q);
}

double NonlinearString::splitGradient(const Vector& q, Vector& grad) const {
  return ratio_ == 1 ? singleGridGradient(q, grad) : twoGridGradient(q, grad);
}

// ζ_l = D₋u, η_l = D₋v on the M segments (u_0 = u_M = 0); V' = h (EA − T0)/2 Σ (s_l − 1)².
// The end segments are taken apart so the loop over the others has no branch and vectorises.
double NonlinearString::singleGridPotential(const Vector& q) const {
  const Eigen::Index m = segments_;
  const double* u = q.data();
  const double* v = q.data() + (m - 1);
  const double invH = 1.0 / h_;
  double phi;
  double sum = segmentExcess(u[0] * invH, v[0] * invH, phi) +
               segmentExcess(-u[m - 2] * invH, -v[m - 2] * invH, phi);
#pragma omp simd reduction(+ : sum)
  for (Eigen::Index l = 1; l < m - 1; ++l) {
    double f;
    sum += segmentExcess((u[l] - u[l - 1]) * invH, (v[l] - v[l - 1]) * invH, f);
  }
  return 0.5 * h_ * (physics_.young * physics_.area - physics_.tension) * sum;
}

namespace {

// u (or v) with its fixed ends, up[0] = up[M] = 0, so that ζ_l = (up[l+1] − up[l]) / h on every
// segment.
void padded(const double* u, Eigen::Index m, double* up) {
  up[0] = up[m] = 0.0;
  std::copy(u, u + m - 1, up + 1);
}

}  // namespace

// ∂V'/∂ζ_l = c φ_l ζ_l, ∂V'/∂η_l = c φ_l (1 + η_l), c = h (EA − T0); then
// ∇_u V' = D₋ᵀ(∂V'/∂ζ): (D₋ᵀ w)_j = (w_j − w_{j+1}) / h, likewise for v.
double NonlinearString::singleGridGradient(const Vector& q, Vector& grad) const {
  const Eigen::Index m = segments_;
  const double c = h_ * (physics_.young * physics_.area - physics_.tension);
  double* up = work3_.data();
  double* vp = scratch_.data();
  padded(q.data(), m, up);
  padded(q.data() + (m - 1), m, vp);
  const double invH = 1.0 / h_;
  const double sum = kernels_->singleGridForces(up, vp, m, invH, c, work1_.data(), work2_.data(),
                                                grad.data(), grad.data() + (m - 1));
  endTension_ = (physics_.tension * (vp[m] - vp[m - 1]) + work2_[m - 1]) * invH;  // bridge's chain
  return 0.5 * c * sum;
}

// ε_J = S_J − 1 into strain_J and 1/S_J into inverseStretch_J, S_J = sqrt((1 + η_J)² + Z_J)
// (docs/string-grids.md, "The strain of a cell").
void NonlinearString::cellStrains(const Vector& q, double* strain, double* inverseStretch) const {
  const Eigen::Index m = segments_;
  kernels_->cellStretches(q.data(), q.data() + (m - 1), grid_.longitudinal, ratio_, 1.0 / h_,
                          1.0 / hv_, forcesWork_.data(), strain, inverseStretch);
}

// One coarse cell (Mv = 1: the strings shorter than 2.1 √(E/ρ) k, the Kirchhoff–Carrier limit of
// SCHEMES §3b): v has no unknowns, so η = 0, S = sqrt(1 + Z) with Z = (1/M) Σ_l ζ_l² the mean
// square slope of the whole string, read from u in place (ζ of the end segments u_1/h and
// −u_{M−1}/h). Its sum's order is the compiler's (`omp simd`): the same on every kernel path of
// a build.
NonlinearString::OneCell NonlinearString::oneCell(const Vector& q) const {
  const Eigen::Index m = segments_;
  const double* u = q.data();
  const double invH = 1.0 / h_, invM = 1.0 / static_cast<double>(m);  // off the chain below
  const double first = u[0] * invH, last = u[m - 2] * invH;
  double sum = first * first + last * last;
#pragma omp simd reduction(+ : sum)
  for (Eigen::Index l = 1; l < m - 1; ++l) {
    const double zeta = (u[l] - u[l - 1]) * invH;
    sum += zeta * zeta;
  }
  const double mean = sum * invM;
  const double stretch = std::sqrt(1.0 + mean);
  // ε = S − 1 without cancellation, and ε/S: one division each after the root, side by side.
  return {mean / (stretch + 1.0), mean / ((stretch + 1.0) * stretch)};
}

// Its gradient, the two grids' with r = M and η = 0: ∂V'/∂ζ_l = c (ε/S) ζ_l, so
// ∇_u V' = D₋ᵀ(c (ε/S) ζ) = c (ε/S) (2u_j − u_{j−1} − u_{j+1}) / h²: with oneCell's, two sweeps
// where the cells' kernel takes a copy and three; the tension at the end, c M ε/(S h_v).
double NonlinearString::oneCellGradient(const Vector& q, Vector& grad) const {
  const Eigen::Index m = segments_;
  const double* u = q.data();
  double* gu = grad.data();
  // The constants' divisions first: the step waits on the chain from u through the cell's root to
  // the gradient, and a division by a constant on it would lengthen it.
  const double c = (physics_.young * physics_.area - physics_.tension) * h_;
  const double perH2 = 1.0 / (h_ * h_), perHv = static_cast<double>(m) / hv_;
  const OneCell cell = oneCell(q);
  const double weight = c * cell.strainOverStretch;
  const double f = weight * perH2;
  if (m == 2) {
    gu[0] = 2.0 * f * u[0];
  } else {
    gu[0] = f * (2.0 * u[0] - u[1]);
    gu[m - 2] = f * (2.0 * u[m - 2] - u[m - 3]);
#pragma omp simd
    for (Eigen::Index j = 1; j < m - 2; ++j) gu[j] = f * (2.0 * u[j] - u[j - 1] - u[j + 1]);
  }
  endTension_ = weight * perHv;
  return cellsPotential(cell.strain * cell.strain);
}

void NonlinearString::quasiStaticStretch(const Vector& q, double* v) const noexcept {
  const Eigen::Index m = segments_, mv = grid_.longitudinal;
  if (mv < 2) return;
  const double invH = 1.0 / h_;
  double* up = work3_.data();
  padded(q.data(), m, up);
  double* z = cell1_.data();
  double mean = 0.0;
  for (Eigen::Index j = 0; j < mv; ++j) {
    double sum = 0.0;
    for (Eigen::Index l = j * ratio_; l < (j + 1) * ratio_; ++l) {
      const double zeta = (up[l + 1] - up[l]) * invH;
      sum += zeta * zeta;
    }
    z[j] = sum / ratio_;
    mean += z[j];
  }
  mean /= static_cast<double>(mv);
  const double ea = physics_.young * physics_.area;
  const double scale = -(ea - physics_.tension) / (2.0 * ea);
  double position = 0.0;
  for (Eigen::Index j = 0; j < mv - 1; ++j) {
    position += hv_ * scale * (z[j] - mean);  // v_{J+1} = v_J + h_v η_J
    v[j] = position;
  }
}

// V' = (EA − T0)/2 Σ_J h_v ε_J², from Σ_J ε_J².
double NonlinearString::cellsPotential(double squaredStrains) const {
  return 0.5 * hv_ * (physics_.young * physics_.area - physics_.tension) * squaredStrains;
}

double NonlinearString::twoGridPotential(const Vector& q) const {
  if (grid_.longitudinal == 1) {
    const double strain = oneCell(q).strain;
    return cellsPotential(strain * strain);
  }
  double* strain = cell2_.data();
  cellStrains(q, strain, cell3_.data());
  double sum = 0.0;
  for (Eigen::Index j = 0; j < grid_.longitudinal; ++j) sum += strain[j] * strain[j];
  return cellsPotential(sum);
}

// With c = (EA − T0) h_u, ∂ε_J/∂ζ_l = ζ_l/(r S_J) and ∂ε_J/∂η_J = (1 + η_J)/S_J:
//   ∂V'/∂ζ_l = c (ε_J/S_J) ζ_l,  ∂V'/∂η_J = c r ε_J (1 + η_J)/S_J,
// then ∇_u V' = D₋ᵀ(∂V'/∂ζ) on the fine grid and ∇_v V' = D₋ᵀ(∂V'/∂η) on the coarse one, all in
// one kernel call.
double NonlinearString::twoGridGradient(const Vector& q, Vector& grad) const {
  const Eigen::Index m = segments_, mv = grid_.longitudinal;
  if (mv == 1) return oneCellGradient(q, grad);
  const double c = (physics_.young * physics_.area - physics_.tension) * h_;
  const TwoGridSums sums = kernels_->twoGridForces(
      q.data(), q.data() + (m - 1), mv, ratio_, 1.0 / h_, 1.0 / hv_, c, physics_.tension,
      forcesWork_.data(), grad.data(), grad.data() + (m - 1));
  endTension_ = sums.endTension;
  return cellsPotential(sums.squaredStrains);
}

double minimalSpacing(const StringPhysics& p, GridRule rule, double k, double sigma1) {
  const double c2 = p.tension / p.linearDensity();
  const double kappa2 = p.young * p.inertia / p.linearDensity();
  const double a = c2 * k * k + 4.0 * sigma1 * k;
  const double transverse = std::sqrt(0.5 * (a + std::sqrt(a * a + 16.0 * kappa2 * k * k)));
  if (rule != GridRule::longitudinal) return transverse;  // two grids: u's spacing
  return std::max(std::sqrt(p.young / p.density) * k, transverse);
}

int gridSegments(const StringPhysics& p, GridRule rule, double k, double sigma1, double factor) {
  if (!(factor >= 1.0) || !std::isfinite(factor))
    throw std::invalid_argument("grid factor = " + formatNumber(factor) + ": must be >= 1");
  const double h = factor * minimalSpacing(p, rule, k, sigma1);
  return segmentsAlong(
      p.length, h, k, 1e6, "length",
      rule == GridRule::longitudinal ? "h >= sqrt(E/rho) k" : "stiff-string bound (44)",
      factor > (rule == GridRule::transverse ? kOffTheBound : 1.0));
}

StringGrid stringGrid(const StringPhysics& p, GridRule rule, double k, double sigma1, double factor,
                      double tensionMargin) {
  if (rule != GridRule::twoGrid) {
    // On the bound (44) itself the top mode sits at the Nyquist frequency, and a strike leaves it
    // ringing: the transverse grid without a bend range (nothing else sizes it above the bound)
    // put A0 at velocity 127 above 19 kHz at −10 dB of its peak; 2 % coarser, −48 dB
    // (StringVoice.TheTransverseGridKeepsItsTopModeOffTheNyquistFrequency). The longitudinal grid
    // is far from (44); the two grids have their margin.
    if (rule == GridRule::transverse) factor = std::max(factor, kOffTheBound);
    const int m = gridSegments(p, rule, k, sigma1, factor);
    return {m, m};
  }
  if (!(tensionMargin >= 1.0) || !std::isfinite(tensionMargin))
    throw std::invalid_argument("tension margin = " + formatNumber(tensionMargin) +
                                ": must be a finite number >= 1 (times the tension)");
  StringPhysics design = p;
  design.tension *= tensionMargin;
  const int fine = gridSegments(design, GridRule::transverse, k, sigma1, factor);
  const double cL = std::sqrt(p.young / p.density);
  const double coarse = std::floor(p.length / (kLongitudinalGridFactor * cL * k));
  const int mv = static_cast<int>(std::clamp(coarse, 1.0, static_cast<double>(fine)));
  // u's grid rounded down to a multiple of Mv, or, where that loses more (Mv <= fine < 2 Mv, a
  // string whose c_L is under twice c_T), r = ceil(fine / Mv) with fewer, longer coarse cells:
  // either keeps u within the bound and v's Courant number below 1/1.05.
  const StringGrid down{fine / mv * mv, mv};
  const int r = (fine + mv - 1) / mv;
  const StringGrid up{fine / r * r, fine / r};
  return up.transverse > down.transverse ? up : down;
}

}  // namespace hamiltone
