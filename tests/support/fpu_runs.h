// Runs of the schemes on the FPU chain that several tests share.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "problems/fpu.h"
#include "schemes/marazzato.h"
#include "schemes/sav.h"
#include "schemes/stormer_verlet.h"

namespace hamiltone::testing {

// BDZ §4.1.1: M = 3 pairs, ω = 50.
inline FermiPastaUlam paperChain() { return FermiPastaUlam(3, 50.0); }

// The FPU chain with unequal masses m_i = 1 + i/2 (M ≠ I), to catch a lost M or M⁻¹.
struct WeightedChain {
  static constexpr bool hasStiffness = true;
  FermiPastaUlam chain = paperChain();
  Vector inverseMassVector =
      Vector::LinSpaced(chain.size(), 1.0, 1.0 + 0.5 * (chain.size() - 1)).cwiseInverse();
  Eigen::Index size() const { return chain.size(); }
  const Vector& inverseMass() const { return inverseMassVector; }
  void applyStiffness(const Vector& q, Vector& out) const { chain.applyStiffness(q, out); }
  // λmax(M^-½ K M^-½) <= λmax(K) / min(m) = ω²: a valid bound for (44).
  double stiffnessEigenvalueMax() const { return chain.stiffnessEigenvalueMax(); }
  double splitPotential(const Vector& q) const { return chain.splitPotential(q); }
  double splitGradient(const Vector& q, Vector& grad) const { return chain.splitGradient(q, grad); }
};

// q(0) = α e₄ and a momentum in every coordinate, p_i = α (i − 2.5) / 4.
inline InitialState movingStart(Eigen::Index n, double alpha) {
  InitialState s{Vector::Zero(n), Vector::Zero(n)};
  s.q[3] = alpha;
  for (Eigen::Index i = 0; i < n; ++i) s.p[i] = alpha * (static_cast<double>(i) - 2.5) / 4.0;
  return s;
}

// H(0) = ½ pᵀM⁻¹p + V(q) of a start.
template <class S>
double initialEnergy(const S& system, const FermiPastaUlam& chain, const InitialState& s) {
  return 0.5 * s.p.dot(system.inverseMass().cwiseProduct(s.p)) + chain.potential(s.q);
}

// Steps a scheme `steps` times; the history of q^n for n = 0..steps.
template <class Scheme>
std::vector<Vector> trajectory(Scheme& scheme, long steps) {
  std::vector<Vector> q;
  q.reserve(static_cast<size_t>(steps) + 1);
  q.push_back(scheme.q());
  for (long n = 0; n < steps; ++n) {
    scheme.step();
    q.push_back(scheme.q());
  }
  return q;
}

// Total energy at n = 0..steps.
template <class Scheme>
std::vector<double> energies(Scheme& scheme, long steps) {
  std::vector<double> h{scheme.energy().total()};
  for (long n = 0; n < steps; ++n) {
    scheme.step();
    h.push_back(scheme.energy().total());
  }
  return h;
}

// Relative energy deviation (51), its maximum over the run: max |H^{n+½} − H^{½}| / |H^{½}|.
inline double maxRelativeDeviation(const std::vector<double>& h) {
  double worst = 0.0;
  for (double e : h) worst = std::max(worst, std::abs(e - h.front()) / std::abs(h.front()));
  return worst;
}

inline long stepsFor(double duration, double k) { return std::lround(duration / k); }

}  // namespace hamiltone::testing
