// Strings ending on a moving bridge: the coupled strings, bridge and coupling conserve their energy
// to roundoff, a resistive bridge drains a string at the rate of the impedance ratio, and unison
// strings on it decay in two stages (Weinreich).
#include "instruments/bridge.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "instruments/hammer.h"
#include "instruments/string_tuning.h"
#include "schemes/sav.h"

namespace hamiltone {
namespace {

constexpr double kRate = 48000.0;
constexpr double kStep = 1.0 / kRate;

StringPhysics c3(double tension = 759.0) {
  StringPhysics p;
  p.tension = tension;
  p.inertia = std::numbers::pi * std::pow(1.063e-3, 4) / 64.0;
  return p;
}

// A key's strings on one bridge, stepped as the voice steps them: each string takes the bridge's
// w^n as a force on its last two nodes, then the bridge takes the strings' pull at q^n.
struct BridgedStrings {
  std::vector<SplitSav<HammeredString>> strings;
  std::vector<BridgeCoupling> couplings;
  Bridge bridge;
  double sinAngle = 0.0;  // the bridge's angle α: the strings' tension change drives it

  BridgedStrings(const std::vector<StringPhysics>& physics, StringGrid grid, StepParameters params,
                 const BridgePhysics& bridgePhysics, const std::vector<Vector>& start) {
    double added = 0.0;
    for (size_t s = 0; s < physics.size(); ++s) {
      HammeredString system(NonlinearString(physics[s], grid), HammerFelt{});
      InitialState rest{Vector::Zero(system.size()), Vector::Zero(system.size())};
      if (!start.empty()) rest.q.head(start[s].size()) = start[s];
      rest.q[system.hammerIndex()] = -0.02;
      strings.emplace_back(system, params, rest);
      couplings.emplace_back(strings.back().system().string());
      added += couplings.back().selfStiffness();
    }
    bridge.prepare(bridgePhysics, params.k, added);
    sinAngle = std::sin(bridgePhysics.angle);
  }

  void strike(size_t s, double speed) {
    auto& scheme = strings[s];
    const Eigen::Index w = scheme.system().hammerIndex();
    const double start = scheme.system().contactDisplacement(scheme.q()) - 1e-4;
    scheme.setCoordinate(w, start, start + speed * kStep);
    scheme.resetPsi(1);
  }

  // Returns the strings' summed tension change at the bridge, N.
  double step() {
    const double w = bridge.current();
    double pull = 0.0, tension = 0.0;
    for (size_t s = 0; s < strings.size(); ++s) {
      const BridgeCoupling& c = couplings[s];
      strings[s].setPointForce(0, c.lastIndex(), c.forceOnLast(w));
      strings[s].setPointForce(1, c.secondIndex(), c.forceOnSecond(w));
      strings[s].step();
      pull += c.forceOnBridge(strings[s].q(), w);
      tension += strings[s].system().string().endTension();
    }
    bridge.step(pull, -sinAngle * tension);
    return tension;
  }

  // H^{n+½} of everything, and what the losses took.
  double energy(double wBefore) const {
    double e = bridge.energy();
    for (size_t s = 0; s < strings.size(); ++s)
      e += strings[s].energy().total() +
           couplings[s].energy(strings[s].q(), strings[s].qNext(), wBefore, bridge.current());
    return e;
  }
  double dissipated() const {
    double d = bridge.dissipated();
    for (const auto& s : strings) d += s.dissipated();
    return d;
  }
  double stringEnergy() const {
    double e = 0.0;
    for (const auto& s : strings) e += s.energy().total();
    return e;
  }
};

StringGrid gridFor(const StringPhysics& p, double sigma1) {
  return stringGrid(p, GridRule::twoGrid, kStep, sigma1, 1.0, 1.5);
}

// The coupled energy with the nonlinear string, the felt, the string's σ1 loss and a bridge with
// mass, spring and resistance: H + what the losses took is constant to roundoff over a hard strike.
TEST(BridgedStrings, CoupledEnergyIsConservedToRoundoff) {
  // σ0 is left out: its (1 ± σ0k) factors round the flying hammer's position (centimetres, moving
  // 0.1 mm a step) every step, a drift of 1e-9 of the energy that is there with the bridge off.
  const StepParameters params{.k = kStep, .sigma1 = 2e-5, .epsilon = 0.01};
  const std::vector<StringPhysics> physics{c3(759.0), c3(760.0), c3(758.2)};
  const StringGrid grid = gridFor(physics[0], params.sigma1);
  ASSERT_GT(grid.transverse, grid.longitudinal);  // two grids, as the voice's default
  BridgedStrings key(physics, grid, params, {.mass = 0.02, .stiffness = 2e5, .resistance = 40.0},
                     {});
  for (size_t s = 0; s < 3; ++s) key.strike(s, 4.0 + s);
  double w = key.bridge.current();
  key.step();
  const double start = key.energy(w) + key.dissipated();
  double worst = 0.0, moved = 0.0;
  for (int n = 0; n < 4800; ++n) {
    w = key.bridge.current();
    key.step();
    worst = std::max(worst, std::abs(key.energy(w) + key.dissipated() - start));
    moved = std::max(moved, std::abs(key.bridge.current()));
  }
  EXPECT_GT(moved, 1e-7);                     // the bridge is driven
  EXPECT_GT(key.dissipated(), 1e-3 * start);  // and the losses act
  EXPECT_LT(worst, 1e-11 * start);
}

// With the bridge at an angle the strings' tension change drives it too, from outside the coupled
// balance (bridge.h): H + what the losses took − what the drive gave is constant to roundoff.
TEST(BridgedStrings, TheLongitudinalDriveKeepsTheBalanceWithItsWork) {
  const StepParameters params{.k = kStep, .sigma1 = 2e-5, .epsilon = 0.01};
  const std::vector<StringPhysics> physics{c3(759.0), c3(760.0), c3(758.2)};
  const StringGrid grid = gridFor(physics[0], params.sigma1);
  BridgedStrings key(physics, grid, params,
                     {.mass = 0.02, .stiffness = 2e5, .resistance = 40.0, .angle = 0.1}, {});
  for (size_t s = 0; s < 3; ++s) key.strike(s, 4.0 + s);
  double w = key.bridge.current();
  key.step();
  const double start = key.energy(w) + key.dissipated() - key.bridge.supplied();
  double worst = 0.0, pulled = 0.0;
  for (int n = 0; n < 4800; ++n) {
    w = key.bridge.current();
    pulled = std::max(pulled, std::abs(key.step()));
    worst =
        std::max(worst, std::abs(key.energy(w) + key.dissipated() - key.bridge.supplied() - start));
  }
  EXPECT_GT(pulled, 1.0);                                    // N: the strings pull hard
  EXPECT_GT(std::abs(key.bridge.supplied()), 1e-9 * start);  // and the drive does work
  EXPECT_LT(worst, 1e-11 * start);
}

// The longitudinal precursor: a struck string's tension change reaches the bridge at c_L =
// sqrt(E/ρ), some 15 times sooner than its transverse wave (at c_T = sqrt(T0/ρA)). With the bridge
// at an angle it moves within the longitudinal travel time, (1 − x0/L) L / c_L plus a coarse
// cell's worth; on a level bridge it stays exactly still until the transverse disturbance gets
// there, which on the stiff string's explicit scheme is the stencil's reach, two fine cells a step
// (the stiff string's fastest, shortest waves: still five times later).
TEST(BridgedStrings, TheLongitudinalPulseReachesTheBridgeBeforeTheTransverseWave) {
  const StepParameters params{.k = kStep, .epsilon = 0.01};
  const StringPhysics p = c3();
  const StringGrid grid = gridFor(p, 0.0);
  const BridgePhysics level{.mass = 0.02, .stiffness = 2e5, .resistance = 40.0};
  BridgePhysics tilted = level;
  tilted.angle = 1.0 * std::numbers::pi / 180.0;
  const double distance = (1.0 - HammerFelt{}.position) * p.length;
  const double cL = std::sqrt(p.young / p.density);
  const double cT = std::sqrt(p.tension / p.linearDensity());
  const double cell = p.length / grid.longitudinal;
  // When the bridge first moves (1 s: not within 10 ms), and which way: w < 0, towards the board
  // (u and w are positive away from it).
  struct Motion {
    double time;
    bool towardsBoard;
  };
  auto firstMotion = [&](const BridgePhysics& bridge) {
    BridgedStrings key({p}, grid, params, bridge, {});
    key.strike(0, 4.0);
    for (int n = 0; n < static_cast<int>(0.01 * kRate); ++n) {
      key.step();
      const double w = key.bridge.displacement();
      if (w != 0.0) return Motion{n * kStep, w < 0.0};
    }
    return Motion{1.0, false};
  };
  const Motion tiltedFirst = firstMotion(tilted);
  const double longitudinal = tiltedFirst.time, transverse = firstMotion(level).time;
  std::printf(
      "bridge moves after %.3f ms tilted (first towards the board: %s), %.3f ms level; "
      "(1 - x0/L) L/c_L %.3f ms, /c_T %.3f ms\n",
      1e3 * longitudinal, tiltedFirst.towardsBoard ? "yes" : "no", 1e3 * transverse,
      1e3 * distance / cL, 1e3 * distance / cT);
  EXPECT_LT(longitudinal, (distance + cell) / cL);
  EXPECT_TRUE(tiltedFirst.towardsBoard);  // the strike stretches the string: it presses down
  EXPECT_GE(transverse, std::floor(distance / (2.0 * p.length / grid.transverse)) * kStep);
  EXPECT_GT(transverse, 4.0 * longitudinal);
}

// Measured amplitude decay rate of the string energy's envelope between t0 and t1.
template <class Run>
double decayRate(Run&& run, double t0, double t1) {
  const long n0 = std::lround(t0 * kRate), n1 = std::lround(t1 * kRate);
  double e0 = 0.0, e1 = 0.0;
  for (long n = 0; n <= n1; ++n) {
    const double e = run();
    if (n == n0) e0 = e;
    if (n == n1) e1 = e;
  }
  return std::log(e0 / e1) / (2.0 * (t1 - t0));  // energy ∝ exp(−2σt)
}

Vector firstMode(const NonlinearString& s, double amplitude) {
  Vector u(s.transverseSize());
  for (Eigen::Index j = 0; j < u.size(); ++j)
    u[j] = amplitude * std::sin(std::numbers::pi * (j + 1) / s.segments());
  return u;
}

// The tension change is quadratic in the transverse amplitude (the longitudinal motion is driven
// by the square of the slope; Etchenique, Collin & Moore 2015 measured it so, docs/instrument-
// data.md §3.7): a string started in its first mode at twice the amplitude pulls on the bridge
// four times as hard, to a part in a thousand (the higher orders of the amplitude).
TEST(BridgedStrings, TheTensionChangeIsQuadraticInTheAmplitude) {
  const StepParameters params{.k = kStep, .epsilon = 0.01};
  const StringPhysics p = c3();
  const StringGrid grid = gridFor(p, 0.0);
  const NonlinearString probe(p, grid);
  const BridgePhysics tilted{.mass = 0.02, .stiffness = 2e5, .resistance = 40.0, .angle = 0.02};
  auto rms = [&](double amplitude) {
    BridgedStrings key({p}, grid, params, tilted, {firstMode(probe, amplitude)});
    double sum = 0.0;
    const int steps = static_cast<int>(0.01 * kRate);
    for (int n = 0; n < steps; ++n) {
      const double t = key.step();
      sum += t * t;
    }
    return std::sqrt(sum / steps);
  };
  const double small = rms(1e-3), large = rms(2e-3);
  std::printf("tension change RMS %.4g N at 1 mm, %.4g N at 2 mm: ratio %.5f\n", small, large,
              large / small);
  EXPECT_NEAR(large / small, 4.0, 4.0 * 1e-3);
}

// A lossless string on a bridge that is nearly a pure resistance R (ωM ≪ R, no spring): each
// reflection keeps 1 − 4Z0/R of the wave's energy, Z0 = sqrt(T0 ρA), once per period, so the
// amplitude decays at σ = 2 Z0 f0 / R. Two strings in phase push the bridge twice as hard: 2σ;
// in antiphase it stays still and they keep ringing (Weinreich 1977).
TEST(BridgedStrings, AResistiveBridgeDrainsAtTheImpedanceRatio) {
  const StepParameters params{.k = kStep, .epsilon = 0.0, .trackDissipation = false};
  const StringPhysics p = c3();
  const StringGrid grid = gridFor(p, 0.0);
  const BridgePhysics resistive{.mass = 0.01, .stiffness = 0.0, .resistance = 1000.0};
  const NonlinearString probe(p, grid);
  const Vector mode = firstMode(probe, 1e-5);  // small: the linear string
  const double f0 = schemePartial(probe, kStep, 1);
  const double z0 = std::sqrt(p.tension * p.linearDensity());
  const double sigma = 2.0 * z0 * f0 / resistive.resistance;

  auto rate = [&](const std::vector<Vector>& start) {
    BridgedStrings key(std::vector<StringPhysics>(start.size(), p), grid, params, resistive, start);
    return decayRate(
        [&] {
          key.step();
          return key.stringEnergy() + key.bridge.energy();
        },
        0.2, 1.2);
  };
  const double one = rate({mode});
  EXPECT_NEAR(one, sigma, 0.05 * sigma);
  EXPECT_NEAR(rate({mode, mode}), 2.0 * sigma, 0.1 * sigma);
  EXPECT_LT(rate({mode, -mode}), 0.01 * sigma);
}

// Two strings a cent apart, struck in phase, one a little softer (amplitudes 1 and 0.8): the
// in-phase part (0.9 of the amplitude, 0.81 of the energy) decays at 2σ — the prompt sound — and
// leaves the antiphase part (0.1), which hardly moves the bridge: the aftersound, far slower (its
// rate set by the mistuning). The two-stage decay of a piano's unisons (Weinreich 1977). The
// strings are lossless, so every drop is the bridge's.
TEST(BridgedStrings, DetunedUnisonsDecayInTwoStages) {
  const StepParameters params{.k = kStep, .epsilon = 0.0, .trackDissipation = false};
  const StringPhysics low = c3(759.0);
  const StringPhysics high = c3(759.0 * std::pow(2.0, 2.0 * 1.0 / 1200.0));  // f ∝ sqrt(T0)
  const StringGrid grid = gridFor(low, 0.0);
  const BridgePhysics resistive{.mass = 0.01, .stiffness = 0.0, .resistance = 300.0};
  const NonlinearString probe(low, grid);
  const Vector mode = firstMode(probe, 1e-5);
  BridgedStrings key({low, high}, grid, params, resistive, {mode, 0.8 * mode});
  std::vector<double> energy;  // every 10 ms
  for (int n = 0; n < static_cast<int>(6.0 * kRate); ++n) {
    key.step();
    if (n % 480 == 0) energy.push_back(key.stringEnergy() + key.bridge.energy());
  }
  auto dbPerS = [&](double t0, double t1) {
    const size_t a = std::lround(t0 * 100.0), b = std::lround(t1 * 100.0);
    return 10.0 * std::log10(energy[a] / energy[b]) / (t1 - t0);
  };
  const double prompt = dbPerS(0.0, 0.2);
  const double after = dbPerS(3.0, 5.0);
  const double f0 = schemePartial(probe, kStep, 1);
  const double inPhase = 20.0 * std::log10(std::exp(1.0)) * 4.0 *
                         std::sqrt(low.tension * low.linearDensity()) * f0 /
                         resistive.resistance;  // 2σ in dB/s
  EXPECT_NEAR(prompt, inPhase, 0.1 * inPhase);
  EXPECT_LT(after, prompt / 10.0);
  EXPECT_GT(after, 0.0);
}

TEST(Bridge, RefusesAMassTooLightForTheExplicitCoupling) {
  Bridge b;
  EXPECT_THROW(b.prepare({.mass = 0.0, .stiffness = 0.0, .resistance = 1.0}, kStep, 1e5),
               std::invalid_argument);
  try {
    b.prepare({.mass = 1e-6, .stiffness = 0.0, .resistance = 1.0}, kStep, 1e6);
    FAIL() << "a 1 mg bridge under 1e6 N/m at 48 kHz was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("bridge_mass_kg"), std::string::npos) << e.what();
  }
  EXPECT_THROW(b.prepare({.mass = 1.0, .stiffness = -1.0, .resistance = 1.0}, kStep, 0.0),
               std::invalid_argument);
  EXPECT_THROW(b.prepare({.mass = 1.0, .stiffness = 0.0, .resistance = NAN}, kStep, 0.0),
               std::invalid_argument);
  // An angle drives a motion only the resistance ends (bridge.h: w_D reaches no string).
  try {
    b.prepare({.mass = 1.0, .stiffness = 1e5, .resistance = 0.0, .angle = 0.01}, kStep, 0.0);
    FAIL() << "a tilted bridge without resistance was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("bridge_resistance_kg_s"), std::string::npos) << e.what();
  }
  for (double angle : {-0.01, 0.2, double(NAN)}) {  // rad; 0.2 rad is 11.5°, past the 10° allowed
    try {
      b.prepare({.mass = 1.0, .stiffness = 0.0, .resistance = 1.0, .angle = angle}, kStep, 0.0);
      FAIL() << "a bridge angle of " << angle << " rad was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("bridge_angle_deg"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace hamiltone
