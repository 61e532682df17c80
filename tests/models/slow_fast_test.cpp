// The slow/fast models of [M §4.3]: the FPU chain's split and partition, the inhomogeneous wave's
// springs, exact solution and [M Fig. 16] convergence.
#include <gtest/gtest.h>

#include <cmath>

#include "models/inhomogeneous_wave.h"
#include "models/slow_fast_fpu.h"
#include "schemes/asynchronous_marazzato.h"

namespace hamiltone {
namespace {

// V_S + V_M + V_F is H's potential, and each gradient matches central differences of its part
// (h = 1e-6: error O(h²) ~ 1e-12 of forces O(1)).
template <class S, class Part, class Gradient>
void expectGradient(const S& s, const Vector& q, Part part, Gradient gradient) {
  Vector g = Vector::Zero(q.size());
  gradient(s, q, g);
  for (Eigen::Index i = 0; i < q.size(); ++i) {
    Vector a = q, b = q;
    a[i] += 1e-6;
    b[i] -= 1e-6;
    EXPECT_NEAR(g[i], (part(s, a) - part(s, b)) / 2e-6, 1e-6 * (1.0 + std::abs(g[i]))) << i;
  }
}

TEST(SlowFastFermiPastaUlam, SplitAndPartitionFollowThePaper) {
  const SlowFastFermiPastaUlam chain(3, std::sqrt(10.0));
  const Vector q = (Vector(6) << 0.3, -0.2, 0.5, 0.1, -0.4, 0.25).finished();
  EXPECT_NEAR(chain.slowPotential(q) + chain.mixedPotential(q) + chain.fastPotential(q),
              chain.potential(q), 1e-14);
  // q_1, q_2 fast; q_3 mixed; q_4…q_6 slow; V_M couples q_4.
  EXPECT_EQ(chain.fastParticles().size(), 2u);
  EXPECT_EQ(chain.mixedParticles()[0], 2);
  EXPECT_EQ(chain.slowParticles().front(), 3);
  EXPECT_EQ(chain.coupledSlowParticles()[0], 3);
  using C = SlowFastFermiPastaUlam;
  expectGradient(
      chain, q, [](const C& c, const Vector& x) { return c.fastPotential(x); },
      [](const C& c, const Vector& x, Vector& g) { c.addFastGradient(x, 1.0, g); });
  expectGradient(
      chain, q, [](const C& c, const Vector& x) { return c.mixedPotential(x); },
      [](const C& c, const Vector& x, Vector& g) { c.addMixedGradient(x, 1.0, g); });
  expectGradient(
      chain, q, [](const C& c, const Vector& x) { return c.slowPotential(x); },
      [](const C& c, const Vector& x, Vector& g) { c.addSlowGradient(x, 1.0, g); });
  // λmax of 5 × tridiag with a free end: 5 (2 − 2 cos(5π/7)) = 16.23, so h_F < 0.496 s.
  EXPECT_NEAR(chain.fastEigenvalueMax(), 5.0 * (2.0 - 2.0 * std::cos(5.0 * M_PI / 7.0)), 1e-12);
}

TEST(InhomogeneousWave, SpringsAndPartition) {
  const InhomogeneousWave wave(0.125);  // N = 8: nodes 1…3 fast, 4 mixed, 5…7 slow
  EXPECT_EQ(wave.size(), 7);
  EXPECT_EQ(wave.fastParticles().size(), 3u);
  EXPECT_EQ(wave.mixedParticles()[0], 3);
  EXPECT_EQ(wave.slowParticles().size(), 3u);
  EXPECT_EQ(wave.fastInteractions() + wave.mixedInteractions() + wave.slowInteractions(), 8);
  const Vector q = Vector::LinSpaced(7, 0.1, 0.7).array().sin();
  using W = InhomogeneousWave;
  expectGradient(
      wave, q, [](const W& w, const Vector& x) { return w.fastPotential(x); },
      [](const W& w, const Vector& x, Vector& g) { w.addFastGradient(x, 1.0, g); });
  expectGradient(
      wave, q, [](const W& w, const Vector& x) { return w.mixedPotential(x); },
      [](const W& w, const Vector& x, Vector& g) { w.addMixedGradient(x, 1.0, g); });
  expectGradient(
      wave, q, [](const W& w, const Vector& x) { return w.slowPotential(x); },
      [](const W& w, const Vector& x, Vector& g) { w.addSlowGradient(x, 1.0, g); });
  EXPECT_THROW(InhomogeneousWave(0.3), std::invalid_argument);
  EXPECT_THROW(InhomogeneousWave(1.0 / 7.0), std::invalid_argument);  // interface not a node
}

// At t = 0 the exact solution is u⁰ (the k = 0 term; the images lie outside the domain).
TEST(InhomogeneousWave, ExactSolutionStartsAtTheInitialDisplacement) {
  for (WaveStart start : {WaveStart::paper, WaveStart::rightGoing})
    for (double x = 0.0005; x < 1.0; x += 0.001)
      EXPECT_NEAR(waveExactDisplacement(x, 0.0, start), waveInitialDisplacement(x), 1e-17) << x;
}

// Max |u_numerical − u_exact| at time t, synchronous scheme at h = Δx/10.
double synchronousError(double dx, double t, WaveStart start, WaveStart exactFor) {
  const InhomogeneousWave wave(dx);
  const double h = dx / 10.0;
  Marazzato sync(WholeSystem{wave}, StepParameters{.k = h}, waveInitialState(wave, start),
                 QuadratureRule::midpoint);
  for (long n = 0; n < std::lround(t / h); ++n) sync.step();
  double error = 0.0;
  for (Eigen::Index j = 0; j < wave.size(); ++j)
    error = std::max(error, std::abs(sync.q()[j] - waveExactDisplacement(wave.position(j),
                                                                         sync.time(), exactFor)));
  return error;
}

// At t = 0.02 (the pulse has not reached the interface) a fine run follows the exact solution for
// the printed v⁰ = −u⁰' to 5e-7 (5e-5 of the amplitude, the O(Δx²) dispersion), while the
// paper's purely right-going formula is off by 4.5e-3: its v⁰ would have to be −10 u⁰'.
TEST(InhomogeneousWave, ExactSolutionMatchesAFineSynchronousRun) {
  EXPECT_LT(synchronousError(5e-4, 0.02, WaveStart::paper, WaveStart::paper), 2e-6);
  EXPECT_GT(synchronousError(5e-4, 0.02, WaveStart::paper, WaveStart::rightGoing), 1e-3);
  EXPECT_LT(synchronousError(5e-4, 0.02, WaveStart::rightGoing, WaveStart::rightGoing), 2e-6);
}

// [M Fig. 16], synchronous: the error at t = 0.5 against force evaluations N ∝ Δx⁻² falls at
// order 1 (Δx²) once the pulse transmitted into the slow part (ten times narrower) is resolved:
// 1.5e-3 at Δx = 5e-4, 3.9e-4 at 2.5e-4 (coarser grids are pre-asymptotic: 5.9e-3 at 4e-3,
// 3.9e-3 at 1e-3). Order log(e₁/e₂)/log(N₂/N₁) in [0.8, 1.2].
TEST(InhomogeneousWave, SynchronousErrorFallsAtFirstOrderInForceEvaluations) {
  const double coarse = synchronousError(5e-4, 0.5, WaveStart::paper, WaveStart::paper);
  const double fine = synchronousError(2.5e-4, 0.5, WaveStart::paper, WaveStart::paper);
  const double order = std::log(coarse / fine) / std::log(4.0);
  EXPECT_GE(order, 0.8);
  EXPECT_LE(order, 1.2);
}

// The asynchronous scheme's count per coarse step is K (N/2 + 1) + N/2 − 1 springs against the
// synchronous K N: about half (0.552 at K = 10, N = 500), as [M §4.3.2] says.
TEST(InhomogeneousWave, AsynchronousNeedsAboutHalfTheForceEvaluations) {
  const InhomogeneousWave wave(2e-3);
  const InitialState start = waveInitialState(wave, WaveStart::paper);
  AsynchronousMarazzato async(wave, 2e-4, 10, start, QuadratureRule::midpoint);
  Marazzato sync(WholeSystem{wave}, StepParameters{.k = 2e-4}, start, QuadratureRule::midpoint);
  for (int n = 0; n < 25; ++n) async.step();
  for (int n = 0; n < 250; ++n) sync.step();
  EXPECT_EQ(async.forceEvaluations(), 25 * (10 * 251 + 249));
  EXPECT_EQ(sync.forceEvaluations(), 250 * 500);
  EXPECT_NEAR(static_cast<double>(async.forceEvaluations()) / sync.forceEvaluations(), 0.552, 1e-3);
}

}  // namespace
}  // namespace hamiltone
