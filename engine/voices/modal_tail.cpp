#include "voices/modal_tail.h"

#include <cmath>
#include <numbers>

namespace hamiltone {

void ModalTail::Grid::prepare(int segments, double spacing, double rhoA) {
  modes = segments - 1;
  keep(modes);
  mass = rhoA * spacing;
  // Past the modes, zeros to a whole register: recursions of 0 on 0 that stay 0.
  for (std::vector<double>* x : {&levels[0], &levels[1], &c1, &c2})
    x->assign(registers(modes), 0.0);
  for (std::vector<double>* x : {&kappa, &gamma}) x->assign(modes, 0.0);
  sinTheta.assign(modes + kMaxLanes, 0.0);  // θ_i = π i / M, padded for the kernel's last lanes
  twoCos.assign(modes + kMaxLanes, 0.0);
  for (int i = 1; i <= modes; ++i) {
    sinTheta[i - 1] = std::sin(std::numbers::pi * i / segments);
    twoCos[i - 1] = 2.0 * std::cos(std::numbers::pi * i / segments);
  }
}

// out_i = sqrt(2/M) Σ_{t=1…terms} in_t sin(π i t / M) for i = 1 … M − 1 (in_t at in[t − 1]): the
// sine transform (DST-I), its own inverse — node values to modes with every node, the kept modes
// back to node values.
void ModalTail::Grid::sineSum(const Kernels& kernels, const double* in, int terms,
                              double* out) const noexcept {
  kernels.sineSums(modes, terms, in, sinTheta.data(), twoCos.data(), std::sqrt(2.0 / (modes + 1)),
                   out);
}

// Mode m's share of (41) with the loss's correction (linear_loss.h): with Δ = a^{n+1} − a^n,
// m0 (½ Δ²/k² − σ1/(2k) γ Δ² + ½ κ a^{n+1} a^n), m0 the grid's mass per node.
double ModalTail::Grid::modeEnergy(int m, double k, double sigma1) const noexcept {
  const double a = now()[m], aNext = next()[m], d = aNext - a;
  return mass *
         (0.5 * d * d / (k * k) - 0.5 * sigma1 / k * gamma[m] * d * d + 0.5 * kappa[m] * aNext * a);
}

void ModalTail::prepare(const NonlinearString& string, double k,
                        const std::array<std::vector<double>, kProbes>& probes, Eigen::Index last,
                        Eigen::Index second) {
  const double rhoA = string.physics().linearDensity();
  k_ = k;
  endStiffness_ = string.physics().young * string.physics().area / string.longitudinalSpacing();
  u_.prepare(string.segments(), string.spacing(), rhoA);
  v_.prepare(string.grid().longitudinal, string.longitudinalSpacing(), rhoA);
  for (int p = 0; p < kProbes; ++p) {
    weights_[p].assign(registers(u_.modes), 0.0);
    if (p != kPull) u_.sineSum(*kernels_, probes[p].data(), u_.modes, weights_[p].data());
  }
  // φ_m(j) of every mode of a grid at its node j.
  auto nodeWeights = [&](const Grid& g, Eigen::Index j, std::vector<double>& out) {
    std::vector<double> unit(g.modes, 0.0);
    out.assign(g.modes, 0.0);
    if (g.modes == 0) return;
    unit[j] = 1.0;
    g.sineSum(*kernels_, unit.data(), g.modes, out.data());
  };
  nodeWeights(u_, last, lastNode_);
  nodeWeights(u_, second, secondNode_);
  nodeWeights(v_, v_.modes - 1, vEnd_);
  vEnd_.resize(registers(v_.modes), 0.0);
  setCoefficients(string, 0.0, 0.0);
}

// κ_m, γ_m: M⁻¹K and M⁻¹C of mode m. On u, (βT0 λ + EI λ²)/ρA (transverseEigenvalue) and w_u λ,
// λ = (4/h²) sin²(πm/2M) the eigenvalue of −D2; on v, at EA, EA λ_v/ρA and w_v0 + w_v1 λ_v.
void ModalTail::setCoefficients(const NonlinearString& string, double sigma0, double sigma1) {
  const double k = k_, kk = k * k, up = 1.0 + sigma0 * k, down = 1.0 - sigma0 * k;
  const double cs = 2.0 * sigma1 * k;
  sigma1_ = sigma1;
  const NonlinearString::LossWeights& w = string.lossWeights();
  auto fill = [&](Grid& g, auto kappaOf, auto gammaOf) {
    const int segments = g.modes + 1;
    for (int m = 1; m <= g.modes; ++m) {
      const double s = std::sin(m * std::numbers::pi / (2.0 * segments));
      g.kappa[m - 1] = kappaOf(m, s);
      g.gamma[m - 1] = gammaOf(s);
      g.c1[m - 1] = (2.0 - kk * g.kappa[m - 1] - cs * g.gamma[m - 1]) / up;
      g.c2[m - 1] = (down - cs * g.gamma[m - 1]) / up;
    }
  };
  const double h = string.spacing(), hv = string.longitudinalSpacing();
  const StringPhysics& p = string.physics();
  fill(
      u_, [&](int m, double) { return string.transverseEigenvalue(m); },
      [&](double s) { return w.transverse * 4.0 / (h * h) * s * s; });
  fill(
      v_,
      [&](int, double s) { return p.young * p.area / p.linearDensity() * 4.0 / (hv * hv) * s * s; },
      [&](double s) { return w.longitudinalConstant + w.longitudinal * 4.0 / (hv * hv) * s * s; });
  forceScale_ = kk / (u_.mass * up);
  takeResidual();
}

void ModalTail::setPull(double c1, double c2) noexcept {
  for (int m = 0; m < u_.modes; ++m) weights_[kPull][m] = c1 * lastNode_[m] + c2 * secondNode_[m];
  probeAll();
  takeResidual();
}

// A dropped mode still gives way to a force held on it: statically, by P_m f / (ρA h κ_m) (the
// recursion's fixed point), which the pull reads as −w P_m² / (ρA h κ_m) of the bridge at w. Σ over
// the dropped modes of P_m² / (ρA h κ_m) is that softness as a stiffness taken off the coupling's
// own (BridgeCoupling::selfStiffness): the string's end as stiff as with all its modes, wherever
// the bridge moves slowly beside them — the residual flexibility of a truncated modal system.
void ModalTail::takeResidual() noexcept {
  double r = 0.0;
  for (int m = u_.kept; m < u_.modes; ++m) {
    const double p = weights_[kPull][m];
    r += p * p / (u_.mass * u_.kappa[m]);
  }
  residual_ = r;
}

void ModalTail::enter(const Vector& q, const Vector& qNext) noexcept {
  const int nu = u_.modes;
  // The padding at zero again: a non-finite force (a runaway the guard then resets) leaves
  // 0 · ∞ there, which the probes would read.
  for (Grid* g : {&u_, &v_})
    for (std::vector<double>& level : g->levels)
      std::fill(level.begin() + g->modes, level.end(), 0.0);
  u_.sineSum(*kernels_, q.data(), u_.modes, u_.now());
  u_.sineSum(*kernels_, qNext.data(), u_.modes, u_.next());
  v_.sineSum(*kernels_, q.data() + nu, v_.modes, v_.now());
  v_.sineSum(*kernels_, qNext.data() + nu, v_.modes, v_.next());
  u_.keep(u_.modes);
  v_.keep(v_.modes);
  probeAll();
  takeResidual();
}

// The probes at both levels from the kept modes alone.
void ModalTail::probeAll() noexcept {
  // The eight sums of u side by side (each in the order of m), not one after another: eight
  // chains of additions at once.
  std::array<double, kProbes> now{}, next{};
  const double* a = u_.now();
  const double* aNext = u_.next();
  for (int m = 0; m < u_.kept; ++m)
    for (int p = 0; p < kProbes; ++p) {
      now[p] += weights_[p][m] * a[m];
      next[p] += weights_[p][m] * aNext[m];
    }
  now_ = now;
  next_ = next;
  vLast_ = vLastNext_ = 0.0;
  for (int m = 0; m < v_.kept; ++m) {
    vLast_ += vEnd_[m] * v_.now()[m];
    vLastNext_ += vEnd_[m] * v_.next()[m];
  }
}

void ModalTail::leave(Vector& q, Vector& qNext) const noexcept {
  const int nu = u_.modes;
  u_.sineSum(*kernels_, u_.now(), u_.kept, q.data());
  u_.sineSum(*kernels_, u_.next(), u_.kept, qNext.data());
  v_.sineSum(*kernels_, v_.now(), v_.kept, q.data() + nu);
  v_.sineSum(*kernels_, v_.next(), v_.kept, qNext.data() + nu);
}

double ModalTail::energy() const noexcept {
  double e = 0.0;
  for (const Grid* g : {&u_, &v_})
    for (int m = 0; m < g->kept; ++m) e += g->modeEnergy(m, k_, sigma1_);
  return e;
}

double ModalTail::truncate(double floor) noexcept {
  const double budget = floor * energy();
  double dropped = 0.0;
  if (budget <= 0.0) return dropped;
  for (Grid* g : {&u_, &v_}) {
    while (g->kept > 0) {
      const int from = (g->kept - 1) / kMaxLanes * kMaxLanes;  // the last register's first mode
      double e = 0.0;
      for (int m = from; m < g->kept; ++m) e += g->modeEnergy(m, k_, sigma1_);
      if (dropped + e >= budget) break;
      dropped += e;
      for (int m = from; m < g->kept; ++m) g->now()[m] = g->next()[m] = 0.0;
      g->keep(from);
    }
  }
  probeAll();
  takeResidual();
  return dropped;
}

void ModalTail::restore() noexcept {
  u_.keep(u_.modes);  // the dropped modes were set to rest
  v_.keep(v_.modes);
  takeResidual();
}

}  // namespace hamiltone
