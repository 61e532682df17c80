// The slow/fast models of [M §4.3]: the FPU chain's split and partition, the inhomogeneous wave's
// springs, exact solution and [M Fig. 16] convergence.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <string>
#include <vector>

#include "problems/inhomogeneous_wave.h"
#include "problems/slow_fast_fpu.h"
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

// The closed form λmax = 2ω² sin²((2m − 1)π/(2(2m + 1))) against a dense eigenvalue solve of the
// linear springs' Hessian (tridiag(−1, 2, −1) with a free last row, times ω²/2), m = 1 … 50.
TEST(SlowFastFermiPastaUlam, FastEigenvalueMaxMatchesADenseSolve) {
  for (const double omega : {1.0, std::sqrt(10.0), 50.0}) {
    for (int m = 1; m <= 50; ++m) {
      Eigen::MatrixXd k = Eigen::MatrixXd::Zero(m, m);
      for (int i = 0; i < m; ++i) {
        k(i, i) = (i == m - 1) ? 1.0 : 2.0;
        if (i > 0) k(i, i - 1) = k(i - 1, i) = -1.0;
      }
      const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(k, Eigen::EigenvaluesOnly);
      const double dense = 0.5 * omega * omega * solver.eigenvalues().maxCoeff();
      EXPECT_NEAR(SlowFastFermiPastaUlam(m, omega).fastEigenvalueMax(), dense, 1e-12 * dense)
          << "m = " << m << ", omega = " << omega;
    }
  }
  // Large m is O(1) work and tends to 2ω² (the Gershgorin bound 4 × ω²/2) from below.
  const double large = SlowFastFermiPastaUlam(1'000'000, 1.0).fastEigenvalueMax();
  EXPECT_LT(large, 2.0);
  EXPECT_GT(large, 2.0 - 1e-10);
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

// Max over the nodes of |q_j − u(x_j, t)|, u the exact solution for the printed start.
double maxError(const InhomogeneousWave& wave, const Vector& q, double t, WaveStart exactFor) {
  double error = 0.0;
  for (Eigen::Index j = 0; j < wave.size(); ++j)
    error = std::max(error, std::abs(q[j] - waveExactDisplacement(wave.position(j), t, exactFor)));
  return error;
}

// Max |u_numerical − u_exact| at time t, synchronous scheme at h = Δx/10; its force evaluations
// in *evaluations if given.
double synchronousError(double dx, double t, WaveStart start, WaveStart exactFor,
                        long* evaluations = nullptr) {
  const InhomogeneousWave wave(dx);
  const double h = dx / 10.0;
  Marazzato sync(WholeSystem{wave}, StepParameters{.k = h}, waveInitialState(wave, start),
                 QuadratureRule::midpoint);
  for (long n = 0; n < std::lround(t / h); ++n) sync.step();
  if (evaluations) *evaluations = sync.forceEvaluations();
  return maxError(wave, sync.q(), sync.time(), exactFor);
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

// The asynchronous run of [M Fig. 16] at a stable ratio: N = 1/Δx intervals, h_S = r Δx,
// h_F = h_S / K, the paper's start, midpoint rule, stepped to t = 0.5.
struct AsynchronousRun {
  double error;      // max |u − u_exact| at t = 0.5
  long evaluations;  // force evaluations, [M §4.3.1]
  double largest;    // max |q| over the coarse nodes (u⁰ peaks at 1e-2)
};

AsynchronousRun asynchronousRun(int intervals, double ratio, long k) {
  const InhomogeneousWave wave(1.0 / intervals);
  const double hS = ratio * wave.dx();
  AsynchronousMarazzato async(wave, hS / static_cast<double>(k), k,
                              waveInitialState(wave, WaveStart::paper), QuadratureRule::midpoint);
  double largest = 0.0;
  for (long n = 0; n < std::lround(0.5 / hS); ++n) {
    async.step();
    largest = std::max(largest, async.q().lpNorm<Eigen::Infinity>());
  }
  EXPECT_NEAR(async.time(), 0.5, 1e-12);
  return {maxError(wave, async.q(), async.time(), WaveStart::paper), async.forceEvaluations(),
          largest};
}

// [M Fig. 16], asynchronous. At the paper's h_S = Δx the scheme is unstable (see
// AsynchronousMarazzato.StableBelowTheResonanceRatio): the slow particles' 2h_S-periodic mode
// resonates with a fast mode once ω_F h_S reaches π, which no fast mode can when
// h_S/Δx < K sin(π/(2K))/c₁ = 0.156 (K = 10). So h_S = 0.15 Δx, h_F = 0.015 Δx (inside the fast
// CFL bound Δx/c₁), refined at fixed r and K. Measured at t = 0.5 (N = 1/Δx, evaluations):
//   N = 1200: 3.25e-3 (2.64e7), 1500: 2.41e-3 (4.13e7)  — pre-asymptotic, local order 0.67
//   N = 2400: 1.076e-3 (1.057e8), 3600: 4.76e-4 (2.377e8), 4800: 2.64e-4 (4.225e8)
//   (3000: 6.89e-4, local orders 1.00, 1.02; 8000: 9.39e-5 (1.17e9), too slow for here)
// Least-squares slope over N = 2400, 3600, 4800: −1.012 (error ∝ Δx², evaluations ∝ Δx⁻²);
// band [−1.2, −0.8] as for the synchronous test. The error is the spatial one: the synchronous
// run at h = Δx/10 on N = 2400 (1.088e-3) is within 2 % of it. 2.5–4 s (Release, 1 core).
// η = async / sync evaluations: 0.550 against the synchronous scheme at the same h_F
// (K (N/2 + 1) + N/2 − 1 springs per coarse step against K N), but 3.67 against the synchronous
// run at its own CFL step Δx/10 for the same error, ≈ (K + 1)/(20 r): below the resonance ratio
// the asynchronous scheme saves nothing on this problem.
TEST(InhomogeneousWave, AsynchronousErrorFallsAtFirstOrderInForceEvaluations) {
  constexpr double ratio = 0.15;  // h_S / Δx; N divisible by 3 makes 0.5/h_S = 10N/3 an integer
  constexpr long k = 10;
  ASSERT_LT(ratio, k * std::sin(M_PI / (2.0 * k)) / InhomogeneousWave::kFastSpeed);
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const std::vector<int> grids = {2400, 3600, 4800};
  std::vector<AsynchronousRun> runs;
  for (int n : grids) {
    runs.push_back(asynchronousRun(n, ratio, k));
    const AsynchronousRun& r = runs.back();
    ASSERT_TRUE(std::isfinite(r.error)) << n;
    EXPECT_LT(r.largest, 1.1e-2) << n;  // stable: no growth past the start's amplitude
    EXPECT_LT(r.error, 2e-3) << n;
    const long springsPerCoarseStep = k * (n / 2 + 1) + n / 2 - 1;
    EXPECT_EQ(r.evaluations, std::lround(10.0 * n / 3.0) * springsPerCoarseStep) << n;
    const double x = std::log(static_cast<double>(r.evaluations)), y = std::log(r.error);
    sx += x, sy += y, sxx += x * x, sxy += x * y;
  }
  const double count = static_cast<double>(grids.size());
  const double slope = (count * sxy - sx * sy) / (count * sxx - sx * sx);
  EXPECT_GE(slope, -1.2);
  EXPECT_LE(slope, -0.8);
  // η against the synchronous scheme at h_F, from the counts per coarse step (0.5504 at N = 2400).
  const int n0 = grids.front();
  const double etaSameStep = static_cast<double>(k * (n0 / 2 + 1) + n0 / 2 - 1) / (k * n0);
  EXPECT_NEAR(etaSameStep, 0.5504, 1e-4);
  // Against the synchronous run at Δx/10 on the same grid: the same error, 3.67 times the count.
  long syncEvaluations = 0;
  const double syncError =
      synchronousError(1.0 / n0, 0.5, WaveStart::paper, WaveStart::paper, &syncEvaluations);
  EXPECT_NEAR(runs.front().error / syncError, 1.0, 0.05);
  const double etaAtCfl = static_cast<double>(runs.front().evaluations) / syncEvaluations;
  EXPECT_NEAR(etaAtCfl, (k + 1) / (20.0 * ratio), 0.01);
  RecordProperty("slope", std::to_string(slope));
  RecordProperty("eta_same_step", std::to_string(etaSameStep));
  RecordProperty("eta_at_cfl", std::to_string(etaAtCfl));
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
