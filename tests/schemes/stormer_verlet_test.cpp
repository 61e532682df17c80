// Störmer–Verlet (20): under V' ≡ 0 the split scheme (38) is exactly Störmer–Verlet (BDZ §3.5),
// and then SV conserves (41) with ψ = 0.
#include <gtest/gtest.h>

#include "support/fpu_runs.h"

namespace hamiltone {
namespace {

using testing::paperChain;
using testing::stepsFor;

// The FPU chain with its quartic springs removed: K of (53), V' ≡ 0.
struct HarmonicChain {
  static constexpr bool hasStiffness = true;
  FermiPastaUlam chain = paperChain();
  Eigen::Index size() const { return chain.size(); }
  const Vector& inverseMass() const { return chain.inverseMass(); }
  void applyStiffness(const Vector& q, Vector& out) const { chain.applyStiffness(q, out); }
  double stiffnessEigenvalueMax() const { return chain.stiffnessEigenvalueMax(); }
  double splitPotential(const Vector&) const { return 0.0; }
  double splitGradient(const Vector&, Vector& grad) const {
    grad.setZero();
    return 0.0;
  }
};

InitialState harmonicStart() {
  InitialState s{Vector::Zero(6), Vector::Zero(6)};
  s.q << 0.3, -0.2, 0.0, 1.0, 0.5, -0.7;
  s.p << 1.0, 0.0, -2.0, 0.0, 3.0, 0.5;
  return s;
}

// The two updates differ only in the order of roundoff-level operations; for a linear,
// stable system those differences grow at most linearly in n. 1e-14 of the amplitude over
// 200 steps (10 periods of the ω = 50 mode) leaves room for that.
void expectSplitSavIsStormerVerlet(double sigma0) {
  const StepParameters params{.k = 1e-3, .sigma0 = sigma0};
  StormerVerlet<HarmonicChain> sv(HarmonicChain{}, params, harmonicStart());
  SplitSav<HarmonicChain> sav(HarmonicChain{}, params, harmonicStart());
  double scale = 0.0, worst = 0.0;
  for (long n = 0; n < 200; ++n) {
    scale = std::max(scale, sv.q().cwiseAbs().maxCoeff());
    worst = std::max(worst, (sav.q() - sv.q()).cwiseAbs().maxCoeff());
    sv.step();
    sav.step();
  }
  EXPECT_LE(worst / scale, 1e-14) << "sigma0 " << sigma0;
  EXPECT_NEAR(sav.energy().total(), sv.energy().total(), 1e-14 * sv.energy().total());
}

TEST(StormerVerlet, IsTheSplitSchemeWhenTheSplitPotentialVanishes) {
  expectSplitSavIsStormerVerlet(0.0);
  expectSplitSavIsStormerVerlet(3.0);
}

// With V' ≡ 0 the loss balance (50) holds for SV as for (38): energy + dissipated is constant.
TEST(StormerVerlet, LinearLossBalanceCloses) {
  StormerVerlet<HarmonicChain> sv(HarmonicChain{}, {.k = 1e-3, .sigma0 = 2.0}, harmonicStart());
  const double h0 = sv.energy().total();
  double worst = 0.0;
  for (int n = 0; n < 1000; ++n) {
    sv.step();
    worst = std::max(worst, std::abs(sv.energy().total() + sv.dissipated() - h0) / h0);
  }
  EXPECT_LE(worst, 1e-12);
  EXPECT_GT(sv.dissipated(), 0.9 * h0);
}

TEST(StormerVerlet, ConservesTheLinearEnergyExactly) {
  StormerVerlet<HarmonicChain> sv(HarmonicChain{}, {.k = 1e-2}, harmonicStart());
  const auto h = testing::energies(sv, stepsFor(2.0, 1e-2));
  EXPECT_LE(testing::maxRelativeDeviation(h), 1e-13);
}

// On the nonlinear chain SV's reported energy — (41) with ψ = 0, plus V'(q^n) — is not conserved.
// V'(q^n) sits half a step off the interval [t^n, t^{n+1}] the rest belongs to, so its
// deviation is first order in k: it halves when k halves.
TEST(StormerVerlet, NonlinearEnergyIsNotConserved) {
  const FermiPastaUlam chain = paperChain();
  auto deviation = [&](double k) {
    StormerVerlet<FermiPastaUlam> sv(chain, {.k = k}, fpuInitialState(chain, 10.0));
    return testing::maxRelativeDeviation(testing::energies(sv, stepsFor(1.0, k)));
  };
  const double coarse = deviation(1e-3), fine = deviation(5e-4);
  EXPECT_GT(coarse, 1e-4);
  EXPECT_NEAR(coarse / fine, 2.0, 0.2);
}

TEST(StormerVerlet, RejectsAGaugeShift) {
  const FermiPastaUlam chain = paperChain();
  EXPECT_THROW(StormerVerlet<FermiPastaUlam>(chain, {.k = 1e-3, .epsilon = 1.0},
                                             fpuInitialState(chain, 1.0)),
               std::invalid_argument);
}

}  // namespace
}  // namespace hamiltone
