// No scheme allocates while stepping or reporting energy: Eigen's EIGEN_RUNTIME_NO_MALLOC guard,
// armed in this binary (see tests/CMakeLists.txt), aborts on any heap allocation through Eigen.
#include <gtest/gtest.h>

#include <numbers>

#include "models/hammer.h"
#include "support/fpu_runs.h"

namespace hamiltone {
namespace {

template <class Scheme>
void stepWithoutAllocating(Scheme& scheme) {
  double sink = 0.0;
  Eigen::internal::set_is_malloc_allowed(false);
  for (int n = 0; n < 1000; ++n) {
    scheme.step();
    sink += scheme.energy().total() + scheme.dissipated();
  }
  Eigen::internal::set_is_malloc_allowed(true);
  EXPECT_TRUE(std::isfinite(sink));
}

FermiPastaUlam chain() { return FermiPastaUlam(50, 50.0); }
InitialState start() { return fpuInitialState(chain(), 10.0); }

TEST(NoAllocation, GuardIsArmed) {
  EXPECT_DEATH(
      {
        Eigen::internal::set_is_malloc_allowed(false);
        Vector v(100);
        v.setOnes();
      },
      "heap allocation is forbidden");
}

TEST(NoAllocation, StormerVerlet) {
  StormerVerlet<FermiPastaUlam> s(chain(), {.k = 1e-3, .sigma0 = 1.0}, start());
  stepWithoutAllocating(s);
}

TEST(NoAllocation, NonSplitSav) {
  NonSplitSav<FermiPastaUlam> s(chain(), {.k = 1e-3, .sigma0 = 1.0, .epsilon = 1.0}, start());
  stepWithoutAllocating(s);
}

TEST(NoAllocation, SplitSav) {
  SplitSav<FermiPastaUlam> s(chain(), {.k = 1e-3, .sigma0 = 1.0, .epsilon = 1.0}, start());
  stepWithoutAllocating(s);
}

// The struck string with both losses: the stencils, the hammer contact and the σ1 operator.
// Störmer–Verlet must resolve the longitudinal wave, so it runs on the longitudinal grid.
void strikeWithoutAllocating(GridRule rule, auto makeScheme) {
  StringPhysics physics;
  physics.inertia = std::numbers::pi * std::pow(1.063e-3, 4) / 64.0;
  const double k = 1.0 / 48000.0;
  const HammeredString system(NonlinearString(physics, gridSegments(physics, rule, k, 1e-3, 1.0)),
                              HammerFelt{});
  InitialState start{Vector::Zero(system.size()), Vector::Zero(system.size())};
  start.q[system.hammerIndex()] = -1e-4;
  start.p[system.hammerIndex()] = 0.03;
  auto scheme = makeScheme(system, StepParameters{.k = k, .sigma0 = 1.0, .sigma1 = 1e-3}, start);
  stepWithoutAllocating(scheme);
}

TEST(NoAllocation, SchemesOnTheStruckString) {
  strikeWithoutAllocating(GridRule::transverse,
                          [](auto&&... a) { return SplitSav<HammeredString>(a...); });
  strikeWithoutAllocating(GridRule::longitudinal,
                          [](auto&&... a) { return StormerVerlet<HammeredString>(a...); });
}

TEST(NoAllocation, MarazzatoWithEveryQuadrature) {
  for (QuadratureRule rule :
       {QuadratureRule::midpoint, QuadratureRule::gaussLegendre2, QuadratureRule::gaussLegendre3,
        QuadratureRule::gaussLegendre5, QuadratureRule::lobatto3, QuadratureRule::lobatto5}) {
    Marazzato<FermiPastaUlam> s(chain(), {.k = 1e-3}, start(), rule);
    stepWithoutAllocating(s);
    Eigen::internal::set_is_malloc_allowed(false);
    const double d = s.discreteEnergy();
    Eigen::internal::set_is_malloc_allowed(true);
    EXPECT_GT(d, 0.0);
  }
}

}  // namespace
}  // namespace hamiltone
