// The variable-step scheme (48) on FPU: agreement with (27)/(38) at a constant step, exact
// conservation of (36) for any step sequence, second order under a smoothly varying step, and
// refusal of a step that is not a finite number > 0.
#include "schemes/variable_step_sav.h"

#include <gtest/gtest.h>

#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "support/energy_checks.h"
#include "support/fpu_runs.h"

namespace hamiltone {
namespace {

using testing::maxRelativeDeviation;
using testing::paperChain;

// The FPU chain with K moved into V' ((46) with K₀ = 0): the split scheme (38) then quadratises
// the whole V, as (48) does.
struct UnsplitChain {
  static constexpr bool hasStiffness = false;
  FermiPastaUlam chain = paperChain();
  mutable Vector kq = Vector::Zero(chain.size());
  Eigen::Index size() const { return chain.size(); }
  const Vector& inverseMass() const { return chain.inverseMass(); }
  void applyStiffness(const Vector&, Vector& out) const { out.setZero(); }
  double stiffnessEigenvalueMax() const { return 0.0; }
  double splitPotential(const Vector& q) const { return chain.potential(q); }
  double splitGradient(const Vector& q, Vector& grad) const {
    return fullGradient(chain, q, grad, kq);
  }
};

// Energies (36) after each of the steps, the first (the start (21)) included.
template <class Scheme>
std::vector<double> energies(Scheme& scheme, const std::vector<double>& steps) {
  std::vector<double> h;
  for (double k : steps) {
    scheme.step(k);
    h.push_back(scheme.energy().total());
  }
  return h;
}

// Largest |q^n − q_ref^n| over a run, relative to the largest |q_ref|. After m + 1 steps (48)
// holds q^{m+1}, which (38)/(27) hold as qNext() after m: both begin with the start (21).
template <class Constant, class System>
double constantStepGap(const System& system, const InitialState& start, double k, int steps) {
  Constant reference(system, {.k = k}, start);
  VariableStepSav<System> scheme(system, start);
  scheme.step(k);
  double gap = 0.0, scale = 0.0;
  for (int n = 0; n < steps; ++n) {
    gap = std::max(gap, (scheme.q() - reference.qNext()).cwiseAbs().maxCoeff());
    scale = std::max(scale, reference.qNext().cwiseAbs().maxCoeff());
    EXPECT_NEAR(scheme.energy().total(), reference.energy().total(),
                1e-12 * std::abs(reference.energy().total()))
        << "step " << n;
    scheme.step(k);
    reference.step();
  }
  return gap / scale;
}

// With k^n = k^{n±½} = k, (48) is (47) ≡ (27) written in p: the same q^n but for roundoff, which
// the chaotic α = 100 chain amplifies over 1000 steps from 1e-16 to ~6e-14 (measured).
TEST(VariableStepSav, ConstantStepIsTheNonSplitScheme) {
  const FermiPastaUlam chain = paperChain();
  EXPECT_LE((constantStepGap<NonSplitSav<FermiPastaUlam>>(chain, fpuInitialState(chain, 100.0),
                                                          1e-3, 1000)),
            1e-12);
}

// With K = 0 the split scheme (38) is (27), so a constant step gives SplitSav too.
TEST(VariableStepSav, ConstantStepIsTheSplitSchemeWhenKIsZero) {
  const UnsplitChain system;
  EXPECT_LE((constantStepGap<SplitSav<UnsplitChain>>(system, fpuInitialState(system.chain, 100.0),
                                                     1e-3, 1000)),
            1e-12);
}

// (36) is conserved whatever the steps: the update is O(1) flops per coordinate, so roundoff in H
// grows at most like a random walk of ulps, ~1e-16 · sqrt(1000) ≪ 1e-12.
TEST(VariableStepSav, ConservesEnergyForRandomSteps) {
  const FermiPastaUlam chain = paperChain();
  std::mt19937 rng(20220048);
  std::uniform_real_distribution<double> u(0.5e-3, 1.5e-3);
  std::vector<double> steps(1000);
  for (double& k : steps) k = u(rng);
  VariableStepSav<FermiPastaUlam> scheme(chain, fpuInitialState(chain, 100.0));
  EXPECT_LE(maxRelativeDeviation(energies(scheme, steps)), 1e-12);
  EXPECT_GT(scheme.time(), 0.9);  // about 1 s was run
}

TEST(VariableStepSav, ConservesEnergyForAlternatingSteps) {
  const FermiPastaUlam chain = paperChain();
  std::vector<double> steps(1000);
  for (size_t n = 0; n < steps.size(); ++n) steps[n] = n % 2 ? 1.5e-3 : 0.5e-3;
  VariableStepSav<FermiPastaUlam> scheme(chain, fpuInitialState(chain, 100.0));
  EXPECT_LE(maxRelativeDeviation(energies(scheme, steps)), 1e-12);
  EXPECT_NEAR(scheme.time(), 1.0, 1e-12);
}

// No bound like (44): (37) holds for every step, here alternating 1e-4 with 5e-2 — beyond the
// split scheme's 2/ω = 0.04 and far beyond Störmer–Verlet's ≈ 6e-3 at α = 100. H still moves
// by roundoff only (measured 1.6e-13).
TEST(VariableStepSav, StaysBoundedForStepsBeyondTheSplitBound) {
  const FermiPastaUlam chain = paperChain();
  VariableStepSav<FermiPastaUlam> scheme(chain, fpuInitialState(chain, 100.0));
  scheme.step(1e-4);
  const double h0 = scheme.energy().total();
  double worst = 0.0;
  for (int n = 0; n < 1000; ++n) {
    scheme.step(n % 2 ? 1e-4 : 5e-2);
    worst = std::max(worst, std::abs(scheme.energy().total() - h0) / h0);
    ASSERT_LE(scheme.p().norm(), std::sqrt(2.0 * h0) * (1.0 + 1e-12)) << "step " << n;  // (37)
  }
  EXPECT_LE(worst, 1e-12);
}

// Second order with k^n = k (1 + 0.3 sin(2π n / N)), N = T / k: the steps sum to T (the sine sums
// to zero over its period) and follow the same smooth profile in time as k halves. Reference:
// Störmer–Verlet at k = T / 2^20, whose error is ~(2^-20 / 2^-11)² ≈ 4e-6 of the finest error.
TEST(VariableStepSav, ConvergesToSecondOrderUnderASmoothlyVaryingStep) {
  const FermiPastaUlam chain = paperChain();
  const InitialState start = fpuInitialState(chain, 50.0);
  const double duration = 0.25;
  StormerVerlet<FermiPastaUlam> reference(chain, {.k = duration / (1 << 20)}, start);
  for (int n = 0; n < (1 << 20); ++n) reference.step();

  std::vector<double> logK, logError;
  for (int steps = 256; steps <= 2048; steps *= 2) {
    VariableStepSav<FermiPastaUlam> scheme(chain, start);
    const double k = duration / steps;
    for (int n = 0; n < steps; ++n)
      scheme.step(k * (1.0 + 0.3 * std::sin(2.0 * std::numbers::pi * n / steps)));
    ASSERT_NEAR(scheme.time(), duration, 1e-13);
    logK.push_back(std::log(k));
    logError.push_back(std::log((scheme.q() - reference.q()).norm() / reference.q().norm()));
  }
  const double slope = testing::leastSquaresSlope(logK, logError);
  EXPECT_GE(slope, 1.8);
  EXPECT_LE(slope, 2.2);
}

TEST(VariableStepSav, RefusesAStepThatIsNotPositiveAndNamesIt) {
  const FermiPastaUlam chain = paperChain();
  VariableStepSav<FermiPastaUlam> scheme(chain, fpuInitialState(chain, 10.0));
  for (int n = 0; n < 3; ++n) scheme.step(1e-3);
  const Vector q = scheme.q();
  const double h = scheme.energy().total();
  for (double k : {0.0, -2e-3, double(NAN), double(INFINITY)}) {
    try {
      scheme.step(k);
      FAIL() << "k = " << k << " accepted";
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("k = " + formatNumber(k)), std::string::npos) << what;
      EXPECT_NE(what.find("step 3"), std::string::npos) << what;
    }
  }
  // Refused steps leave the state as it was.
  EXPECT_EQ(scheme.stepIndex(), 3);
  EXPECT_EQ(scheme.q(), q);
  EXPECT_EQ(scheme.energy().total(), h);
  EXPECT_THROW(VariableStepSav<FermiPastaUlam>(chain, fpuInitialState(chain, 1.0), -1.0),
               std::invalid_argument);
  EXPECT_THROW(
      VariableStepSav<FermiPastaUlam>(chain, InitialState{Vector::Zero(4), Vector::Zero(4)}),
      std::invalid_argument);
}

}  // namespace
}  // namespace hamiltone
