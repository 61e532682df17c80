// Runs of the schemes on the FPU chain that several tests share.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "models/fpu.h"
#include "schemes/marazzato.h"
#include "schemes/sav.h"
#include "schemes/stormer_verlet.h"

namespace hamiltone::testing {

// BDZ §4.1.1: M = 3 pairs, ω = 50.
inline FermiPastaUlam paperChain() { return FermiPastaUlam(3, 50.0); }

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
