// The SAV schemes (27) and (38) on FPU: exact energy conservation (41)/(36), the loss balance (50),
// the stability bound (44), and unconditional stability of (27) where Störmer–Verlet blows up.
#include <gtest/gtest.h>

#include "support/energy_checks.h"
#include "support/fpu_runs.h"

namespace hamiltone {
namespace {

using testing::energies;
using testing::maxRelativeDeviation;
using testing::paperChain;
using testing::stepsFor;

// Relative energy deviation (51) over 1 s at k = 1e-3, ω = 50 (BDZ Fig. 2). The update is O(1)
// flops per coordinate per step, so roundoff in H stays at a few ulps per step and grows at
// most like a random walk: ~1e-16 · sqrt(1000) ≪ 1e-12.
template <class Scheme>
void expectConservesEnergy(double alpha) {
  const FermiPastaUlam chain = paperChain();
  Scheme scheme(chain, {.k = 1e-3}, fpuInitialState(chain, alpha));
  const auto h = energies(scheme, stepsFor(1.0, 1e-3));
  EXPECT_LE(maxRelativeDeviation(h), 1e-12) << "alpha " << alpha;
}

// The conserved H^{½} is the physical H(0) to at least second order, from a start with momentum
// in every coordinate and unequal masses: the start (21) is O(k²) accurate and ψ^{½} is taken at
// q(k/2) + O(k³), so the gap falls at least fourfold per halving (measured 3.97–4.00, and 13.4 for
// (27) at α = 100, where its k² terms nearly cancel); a first-order ψ^{½}, sqrt(2V'(q^0)), would
// only halve it.
template <template <class> class Scheme>
void expectStartsAtThePhysicalEnergy(double alpha) {
  const testing::WeightedChain system;
  const InitialState start = testing::movingStart(system.size(), alpha);
  const double exact = testing::initialEnergy(system, system.chain, start);
  auto gap = [&](double k) {
    return std::abs(Scheme<testing::WeightedChain>(system, {.k = k}, start).energy().total() -
                    exact);
  };
  EXPECT_GE(gap(1e-4) / gap(5e-5), 3.8) << "alpha " << alpha;
  EXPECT_LT(gap(1e-4), 1e-3 * exact);
}

TEST(SplitSav, ConservesEnergyExactly) {
  for (double alpha : {10.0, 50.0, 100.0}) expectConservesEnergy<SplitSav<FermiPastaUlam>>(alpha);
}

TEST(NonSplitSav, ConservesEnergyExactly) {
  for (double alpha : {10.0, 50.0, 100.0})
    expectConservesEnergy<NonSplitSav<FermiPastaUlam>>(alpha);
}

TEST(SplitSav, ConservedEnergyIsThePhysicalOneToSecondOrder) {
  for (double alpha : {10.0, 100.0}) expectStartsAtThePhysicalEnergy<SplitSav>(alpha);
}

TEST(NonSplitSav, ConservedEnergyIsThePhysicalOneToSecondOrder) {
  for (double alpha : {10.0, 100.0}) expectStartsAtThePhysicalEnergy<NonSplitSav>(alpha);
}

TEST(SplitSav, ConservesEnergyWithUnequalMassesAndMomentum) {
  const testing::WeightedChain system;
  SplitSav<testing::WeightedChain> scheme(system, {.k = 1e-3},
                                          testing::movingStart(system.size(), 30.0));
  EXPECT_LE(maxRelativeDeviation(energies(scheme, 1000)), 1e-12);
}

TEST(SplitSav, GaugeShiftKeepsConservationAndIsExcludedFromTheReportedEnergy) {
  const FermiPastaUlam chain = paperChain();
  SplitSav<FermiPastaUlam> plain(chain, {.k = 1e-3}, fpuInitialState(chain, 10.0));
  SplitSav<FermiPastaUlam> shifted(chain, {.k = 1e-3, .epsilon = 1.0},
                                   fpuInitialState(chain, 10.0));
  const auto h = energies(shifted, 1000);
  EXPECT_LE(maxRelativeDeviation(h), 1e-12);
  // ψ²/2 − ε still starts at V'(q^{½}): the two energies agree to roundoff of ψ²/2 ≈ V' + ε.
  EXPECT_NEAR(h.front(), plain.energy().total(), 1e-12 * h.front());
}

// Loss (49)–(50): H^{n+½} − H^{n−½} = −σ0/(2k) ‖q^{n+1} − q^{n−1}‖² <= 0, exactly.
template <class Scheme>
void expectBalancedLoss() {
  const FermiPastaUlam chain = paperChain();
  Scheme scheme(chain, {.k = 1e-3, .sigma0 = 2.0}, fpuInitialState(chain, 50.0));
  const testing::Balance b = testing::runBalance(scheme, 1000);
  EXPECT_LE(b.worstIncrease, 1e-14);
  EXPECT_LE(b.worstBalance, 1e-12);
  // The loss is real: with σ0 = 2/s the energy falls by about e^{−2σ0 t} ≈ e^{−4} in 1 s.
  EXPECT_LT(b.final, 0.1 * b.initial);
  EXPECT_GT(scheme.dissipated(), 0.9 * b.initial);
}

TEST(SplitSav, LossNeverAddsEnergyAndTheBalanceCloses) {
  expectBalancedLoss<SplitSav<FermiPastaUlam>>();
}

TEST(NonSplitSav, LossNeverAddsEnergyAndTheBalanceCloses) {
  expectBalancedLoss<NonSplitSav<FermiPastaUlam>>();
}

TEST(SplitSav, RejectsTimeStepsBeyondTheBound44) {
  const FermiPastaUlam chain = paperChain();  // (54): k <= 2/ω = 0.04
  EXPECT_NO_THROW(SplitSav<FermiPastaUlam>(chain, {.k = 0.04}, fpuInitialState(chain, 1.0)));
  EXPECT_THROW(SplitSav<FermiPastaUlam>(chain, {.k = std::nextafter(0.04, 1.0)},
                                        fpuInitialState(chain, 1.0)),
               std::invalid_argument);
  try {
    SplitSav<FermiPastaUlam>(chain, {.k = 0.041}, fpuInitialState(chain, 1.0));
    FAIL() << "k = 0.041 > 2/ω accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("(44)"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("0.04"), std::string::npos) << e.what();
  }
  // The non-split scheme has no bound (37).
  EXPECT_NO_THROW(NonSplitSav<FermiPastaUlam>(chain, {.k = 0.5}, fpuInitialState(chain, 1.0)));
}

TEST(SavScheme, RejectsInvalidParameters) {
  const FermiPastaUlam chain = paperChain();
  const InitialState start = fpuInitialState(chain, 1.0);
  using Scheme = SplitSav<FermiPastaUlam>;
  EXPECT_THROW(Scheme(chain, {.k = 0.0}, start), std::invalid_argument);
  EXPECT_THROW(Scheme(chain, {.k = -1e-3}, start), std::invalid_argument);
  EXPECT_THROW(Scheme(chain, {.k = NAN}, start), std::invalid_argument);
  EXPECT_THROW(Scheme(chain, {.k = 1e-3, .sigma0 = -1.0}, start), std::invalid_argument);
  EXPECT_THROW(Scheme(chain, {.k = 1e-3, .sigma0 = 1000.0}, start), std::invalid_argument);
  EXPECT_THROW(Scheme(chain, {.k = 1e-3, .epsilon = -1.0}, start), std::invalid_argument);
  EXPECT_THROW(Scheme(chain, {.k = 1e-3}, InitialState{Vector::Zero(4), Vector::Zero(4)}),
               std::invalid_argument);
}

// Bound (37): ‖p^{n+½}‖ <= sqrt(2 λmax(M) H). At α = 100 the quartic springs have frequencies of
// order sqrt(12 α²) ≈ 350 rad/s, so Störmer–Verlet's linear limit k < 2/ω_max is ≈ 6e-3;
// at k = 1e-2 it blows up while (27) stays bounded and conserves its energy.
TEST(NonSplitSav, StaysBoundedWhereStormerVerletDiverges) {
  const FermiPastaUlam chain = paperChain();
  const double k = 1e-2;
  const InitialState start = fpuInitialState(chain, 100.0);

  StormerVerlet<FermiPastaUlam> sv(chain, {.k = k}, start);
  const double sv0 = sv.energy().total();
  bool diverged = false;
  for (long n = 0; n < stepsFor(1.0, k) && !diverged; ++n) {
    sv.step();
    const double h = sv.energy().total();
    diverged = !std::isfinite(h) || h > 10.0 * sv0;
  }
  EXPECT_TRUE(diverged);

  NonSplitSav<FermiPastaUlam> sav(chain, {.k = k}, start);
  const double h0 = sav.energy().total();
  double worst = 0.0;
  for (long n = 0; n < stepsFor(1.0, k); ++n) {
    sav.step();
    const double h = sav.energy().total();
    worst = std::max(worst, std::abs(h - h0) / h0);
    const double p = (sav.qNext() - sav.q()).norm() / k;                // ‖p^{n+½}‖ with M = I
    ASSERT_LE(p, std::sqrt(2.0 * h0) * (1.0 + 1e-12)) << "step " << n;  // (37), H = H^{½}
  }
  EXPECT_LE(worst, 1e-12);
}

}  // namespace
}  // namespace hamiltone
