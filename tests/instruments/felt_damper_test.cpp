// A damper's felt as dashpots on a few nodes of the string (SavScheme::setPointDamper, (D1)): the
// damped nonlinear string keeps its energy balance to roundoff, with the hammer on it too, each
// mode decays at the rate its shape at the felt gives it, and a mode with a node under the felt is
// not damped at all.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "instruments/hammer.h"
#include "instruments/string_tuning.h"
#include "schemes/sav.h"

namespace hamiltone {
namespace {

constexpr double kRate = 48000.0;
constexpr double kStep = 1.0 / kRate;
constexpr double kPi = std::numbers::pi;

StringPhysics c3() {
  StringPhysics p;
  p.inertia = kPi * std::pow(1.063e-3, 4) / 64.0;
  return p;
}

SplitSav<HammeredString> stringWithMode(const StepParameters& params, int mode, double amplitude,
                                        StringGrid grid) {
  HammeredString system(NonlinearString(c3(), grid), HammerFelt{});
  InitialState start{Vector::Zero(system.size()), Vector::Zero(system.size())};
  const int m = system.string().segments();
  for (int j = 1; j < m; ++j) start.q[j - 1] = amplitude * std::sin(mode * kPi * j / m);
  start.q[system.hammerIndex()] = -0.02;  // the hammer parked clear of the string
  return SplitSav<HammeredString>(system, params, start);
}

// The energy's decay rate (of the amplitude) over steps n0 … n1.
double decayRate(SplitSav<HammeredString>& s, long n0, long n1) {
  double e0 = 0.0;
  for (long n = 0; n < n1; ++n) {
    if (n == n0) e0 = s.energy().total();
    s.step();
  }
  return std::log(e0 / s.energy().total()) / (2.0 * (n1 - n0) * kStep);
}

// A hard displacement (geometrically exact regime), σ0 and σ1 on, and a felt of 3 kg/s on two
// nodes, one lifted, the other pressed a million times harder: H + dissipated is constant to
// roundoff, and the string stays bounded however hard the felt (the damper only takes energy).
TEST(FeltDamper, DampedNonlinearStringKeepsItsEnergyBalanceToRoundoff) {
  const StepParameters params{.k = kStep, .sigma0 = 0.5, .sigma1 = 2e-5, .epsilon = 0.01};
  const StringPhysics p = c3();
  const StringGrid grid = stringGrid(p, GridRule::twoGrid, kStep, params.sigma1, 1.0, 1.5);
  auto s = stringWithMode(params, 1, 0.01, grid);
  const int m = s.system().string().segments();
  const double start = s.energy().total();
  double worst = 0.0;
  for (int n = 0; n < 9600; ++n) {
    if (n == 100) {
      s.setPointDamper(0, m / 5, 3.0);
      s.setPointDamper(1, m / 5 + 2, 3.0);
    }
    if (n == 4000) s.setPointDamper(1, m / 5 + 2, 0.0);
    if (n == 6000) s.setPointDamper(0, m / 5, 1e6);  // a felt that all but pins the node
    s.step();
    worst = std::max(worst, std::abs(s.energy().total() + s.dissipated() - start));
  }
  EXPECT_GT(s.dissipated(), 0.5 * start);  // the felt took most of it
  EXPECT_LT(worst, 1e-12 * start);
  EXPECT_LE(s.energy().total(), start);
}

// The hammer strikes through the felt (two parts of the potential loaded: the multi-part
// Woodbury step, not the kernels' one-part pass): the balance holds to roundoff there too. σ0 is
// left out: its (1 ± σ0k) factors round the flying hammer's position every step (bridge_test.cpp).
TEST(FeltDamper, StrikingThroughTheFeltKeepsTheBalance) {
  const StepParameters params{.k = kStep, .sigma1 = 2e-5, .epsilon = 0.01};
  const StringGrid grid = stringGrid(c3(), GridRule::twoGrid, kStep, params.sigma1, 1.0, 1.5);
  auto s = stringWithMode(params, 1, 0.0, grid);
  const Eigen::Index w = s.system().hammerIndex();
  const double start = s.system().contactDisplacement(s.q()) - 1e-4;
  s.setCoordinate(w, start, start + 5.0 * kStep);  // 5 m/s
  s.resetPsi(1);
  const Eigen::Index strike = std::lround(0.12 * s.system().string().segments()) - 1;
  for (int m = 0; m < 4; ++m) s.setPointDamper(m, strike - 2 + m, 2.0);
  const double before = s.energy().total();
  double worst = 0.0, contact = 0.0;
  for (int n = 0; n < 2400; ++n) {
    s.step();
    contact += s.system().compression(s.q()) > 0.0;
    worst = std::max(worst, std::abs(s.energy().total() + s.dissipated() - before));
  }
  EXPECT_GT(contact, 20);                   // the hammer was on the string …
  EXPECT_GT(s.dissipated(), 0.1 * before);  // … and the felt took its share
  EXPECT_LT(worst, 1e-12 * before);
}

// Two slots on one coordinate act as one dashpot of their summed resistance; a resistance that
// is not > 0 (negative, NaN) lifts its slot.
TEST(FeltDamper, SlotsOnOneNodeAddAndBadResistancesLift) {
  const StepParameters params{.k = kStep, .epsilon = 0.0};
  const StringGrid grid{.transverse = 64, .longitudinal = 1};
  auto twice = stringWithMode(params, 1, 1e-4, grid), once = twice;
  twice.setPointDamper(0, 20, 0.3);
  twice.setPointDamper(3, 20, 0.5);
  twice.setPointDamper(1, 30, -2.0);
  twice.setPointDamper(2, 31, std::nan(""));
  once.setPointDamper(0, 20, 0.8);
  for (int n = 0; n < 4800; ++n) {
    twice.step();
    once.step();
  }
  EXPECT_TRUE(std::isfinite(twice.energy().total()));
  EXPECT_NEAR(twice.energy().total(), once.energy().total(), 1e-12 * once.energy().total());
  EXPECT_NEAR(twice.dissipated(), once.dissipated(), 1e-12 * once.dissipated());
  EXPECT_LT(once.energy().total(), 0.9 * (once.energy().total() + once.dissipated()));
}

// Small amplitude, no other loss: a dashpot r at x_m takes from mode n, of modal mass ρAL/2,
//   σ_n = r Σ_m sin²(nπ x_m/L) / (ρ A L)                                                  (D2)
// to first order in r (the felt's reflection of the mode is second order: r²). With the felt at
// L/4 and L/2, mode 4 has a node under both and rings on undamped — the partial that a damper
// set on its node lets over-ring (tuners move the felt off it) — while modes 1 … 3 decay at (D2).
TEST(FeltDamper, ModesDecayAtTheirShapeUnderTheFelt) {
  const StepParameters params{.k = kStep, .epsilon = 0.0, .trackDissipation = false};
  const StringPhysics p = c3();
  const StringGrid grid{.transverse = 64, .longitudinal = 1};
  const double r = 0.05;
  for (int mode = 1; mode <= 4; ++mode) {
    auto s = stringWithMode(params, mode, 1e-7, grid);
    s.setPointDamper(0, 64 / 4 - 1, r);  // u_16 at L/4: index 15
    s.setPointDamper(1, 64 / 2 - 1, r);  // u_32 at L/2
    const double expected =
        r * (std::pow(std::sin(mode * kPi / 4), 2) + std::pow(std::sin(mode * kPi / 2), 2)) /
        (p.linearDensity() * p.length);
    const double measured = decayRate(s, 2400, 2400 + 48000 / 2);
    std::printf("mode %d: sigma %.5f 1/s measured, %.5f by (D2)\n", mode, measured, expected);
    if (mode == 4)
      EXPECT_LT(std::abs(measured), 1e-6);
    else
      EXPECT_NEAR(measured, expected, 0.01 * expected);
  }
}

}  // namespace
}  // namespace hamiltone
