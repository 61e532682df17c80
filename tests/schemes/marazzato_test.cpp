// Marazzato et al.'s scheme (22) on FPU: the pseudo-energy (13) is exact when the quadrature
// integrates ∇V along the free flight exactly, second order in k otherwise; (17) >= (13) by (18).
#include <gtest/gtest.h>

#include "support/fpu_runs.h"

namespace hamiltone {
namespace {

using testing::maxRelativeDeviation;
using testing::paperChain;
using testing::stepsFor;

double pseudoEnergyDeviation(QuadratureRule rule, double k, double alpha) {
  const FermiPastaUlam chain = paperChain();
  Marazzato<FermiPastaUlam> scheme(chain, {.k = k}, fpuInitialState(chain, alpha), rule);
  return maxRelativeDeviation(testing::energies(scheme, stepsFor(1.0, k)));
}

// FPU's ∇V is cubic in q, so cubic in t along the free flight: every rule of degree >= 3
// integrates it exactly and Theorem 1 applies. Roundoff: a few ulps per step, 1000 steps.
TEST(Marazzato, ExactQuadratureConservesThePseudoEnergy) {
  for (QuadratureRule rule :
       {QuadratureRule::gaussLegendre2, QuadratureRule::gaussLegendre3,
        QuadratureRule::gaussLegendre5, QuadratureRule::lobatto3, QuadratureRule::lobatto5})
    for (double alpha : {10.0, 50.0})
      EXPECT_LE(pseudoEnergyDeviation(rule, 1e-3, alpha), 1e-12)
          << name(rule) << " alpha " << alpha;
}

// With the mid-point rule the quadrature error is O(k³) per step, so (14): O(k²) overall.
TEST(Marazzato, MidpointPseudoEnergyErrorFallsFourfoldPerHalving) {
  const double coarse = pseudoEnergyDeviation(QuadratureRule::midpoint, 1e-3, 10.0);
  const double fine = pseudoEnergyDeviation(QuadratureRule::midpoint, 5e-4, 10.0);
  EXPECT_GT(coarse, 1e-8);
  EXPECT_NEAR(coarse / fine, 4.0, 0.6);
}

TEST(Marazzato, StartsAtTheExactEnergyAndTheDiscreteEnergyBoundsThePseudoEnergy) {
  const FermiPastaUlam chain = paperChain();
  const double alpha = 10.0;
  Marazzato<FermiPastaUlam> scheme(chain, {.k = 1e-3}, fpuInitialState(chain, alpha),
                                   QuadratureRule::gaussLegendre2);
  // [M 7] makes H̃^0 = H(0) exactly (Theorem 1).
  EXPECT_DOUBLE_EQ(scheme.energy().total(), std::pow(alpha, 4) + 2500.0 * alpha * alpha / 4.0);
  for (long n = 0; n < 1000; ++n) {
    scheme.step();
    // (18): H^n − H̃^n = ⅛ |M^{−½} [p]^n|² >= 0, and O(k²) small.
    const double gap = scheme.discreteEnergy() - scheme.energy().total();
    ASSERT_GE(gap, -1e-12 * scheme.energy().total()) << "step " << n;
    ASSERT_LE(gap, 1e-2 * scheme.energy().total()) << "step " << n;
  }
}

// [M 7] with momentum and unequal masses: H̃^0 = H(0) exactly; the pseudo-energy then stays
// exact under GL2 (so M⁻¹ is in both updates), and the gap to (17) is exactly (18).
TEST(Marazzato, MovingStartWithUnequalMasses) {
  const testing::WeightedChain system;
  const InitialState start = testing::movingStart(system.size(), 10.0);
  Marazzato<testing::WeightedChain> scheme(system, {.k = 1e-3}, start,
                                           QuadratureRule::gaussLegendre2);
  const double exact = testing::initialEnergy(system, system.chain, start);
  EXPECT_NEAR(scheme.energy().total(), exact, 1e-15 * exact);
  for (int n = 0; n < 1000; ++n) {
    scheme.step();
    ASSERT_NEAR(scheme.energy().total(), exact, 1e-12 * exact) << "step " << n;
    const Vector jump = scheme.p() - scheme.pPrevious();  // [p]^n
    const double gap = 0.125 * jump.dot(system.inverseMass().cwiseProduct(jump));
    ASSERT_NEAR(scheme.discreteEnergy() - scheme.energy().total(), gap, 1e-12 * exact);
  }
}

TEST(Marazzato, IsLossless) {
  const FermiPastaUlam chain = paperChain();
  EXPECT_THROW(Marazzato<FermiPastaUlam>(chain, {.k = 1e-3, .sigma0 = 1.0},
                                         fpuInitialState(chain, 1.0), QuadratureRule::midpoint),
               std::invalid_argument);
}

}  // namespace
}  // namespace hamiltone
