// Pitch: the simulated partials are the closed-form ones, the tuning puts every key on pitch, the
// stiff string is inharmonic as theory says, and the pitch rises with amplitude (BDZ Fig. 4–5).
#include "instruments/string_tuning.h"

#include <gtest/gtest.h>

#include "instruments/piano_scale.h"
#include "schemes/sav.h"
#include "schemes/stormer_verlet.h"
#include "support/energy_checks.h"
#include "support/modal.h"

namespace hamiltone {
namespace {

using testing::cents;
using testing::modalAmplitude;
using testing::modeShape;
using testing::zeroCrossingFrequency;

StringPhysics c3() {
  StringPhysics p;
  p.inertia = std::numbers::pi * std::pow(1.063e-3, 4) / 64.0;
  return p;
}

// Frequencies of modes 1 … count of a string started in a small sum of its modes (1 µm each:
// the geometric nonlinearity shifts them by ~(1e-6/L)² EA/T0 ~ 1e-10, far below 0.1 cent).
std::vector<double> simulatedPartials(const NonlinearString& string, double k, int count,
                                      double seconds) {
  const int segments = string.segments();
  InitialState start{Vector::Zero(string.size()), Vector::Zero(string.size())};
  for (int m = 1; m <= count; ++m) start.q += modeShape(string.size(), segments, m, 1e-6);
  SplitSav<NonlinearString> scheme(string, {.k = k}, start);
  std::vector<std::vector<double>> modes(count);
  for (long n = 0; n < std::lround(seconds / k); ++n) {
    for (int m = 1; m <= count; ++m)
      modes[m - 1].push_back(modalAmplitude(scheme.q(), segments, m));
    scheme.step();
  }
  std::vector<double> f;
  for (const auto& x : modes) f.push_back(zeroCrossingFrequency(x, k));
  return f;
}

TEST(StringPitch, SimulatedPartialsAreTheClosedFormOnes) {
  const double k = 1.0 / 48000.0;
  const NonlinearString string(c3(), gridSegments(c3(), GridRule::transverse, k, 0.0, 1.0));
  const auto f = simulatedPartials(string, k, 10, 0.5);
  for (int m = 1; m <= 10; ++m)
    EXPECT_NEAR(cents(f[m - 1], schemePartial(string, k, m)), 0.0, 0.1) << "partial " << m;
}

// Every key's string (RT-425 geometry, tension solved) sounds its equal-tempered pitch, measured
// on the simulation, at both common audio rates; on the two grids (the voices' default) at every
// key of the 88 at 48 kHz: the fundamental depends on u's grid alone, whose linear part is the
// transverse grid's.
void expectOnPitch(GridRule rule, double rate, int note) {
  const double k = 1.0 / rate;
  const double target = equalTemperament(note);
  const TunedString tuned =
      tuneString(pianoString(note), TuneBy::tension, rule, k, 0.0, 1.0, target, 1.5);
  const NonlinearString string(tuned.physics, tuned.grid);
  EXPECT_NEAR(cents(schemePartial(string, k, 1), target), 0.0, 1e-6) << note;
  EXPECT_LT(tuned.physics.tension, tuned.physics.young * tuned.physics.area) << note;
  // 40 periods at least, and a few tenths of a second at most.
  const double seconds = std::max(40.0 / target, 0.1);
  const double f = simulatedPartials(string, k, 1, seconds)[0];
  EXPECT_NEAR(cents(f, target), 0.0, 1.0) << "note " << note << " at " << rate << " Hz";
}

TEST(StringPitch, TuningPutsEveryKeyOnPitch) {
  for (double rate : {44100.0, 48000.0})
    for (int note : {21, 36, 48, 60, 72, 84, 96, 108}) {
      expectOnPitch(GridRule::transverse, rate, note);
      expectOnPitch(GridRule::twoGrid, rate, note);
    }
  for (int note = 21; note <= 108; ++note) expectOnPitch(GridRule::twoGrid, 48000.0, note);
}

TEST(StringPitch, TuningByLengthWorksToo) {
  const double k = 1.0 / 48000.0, target = equalTemperament(48);
  const TunedString tuned =
      tuneString(c3(), TuneBy::length, GridRule::transverse, k, 0.0, 1.0, target);
  EXPECT_EQ(tuned.physics.tension, 759.0);
  EXPECT_NEAR(cents(schemePartial(NonlinearString(tuned.physics, tuned.grid), k, 1), target), 0.0,
              1e-6);
}

TEST(StringPitch, TuningRefusesTheImpossible) {
  const double k = 1.0 / 48000.0;
  EXPECT_THROW(tuneString(c3(), TuneBy::tension, GridRule::transverse, k, 0.0, 1.0, 30000.0),
               std::invalid_argument);  // above Nyquist
  StringPhysics weak = c3();
  weak.young = 1e6;  // EA ≈ 0.9 N: no tension below it reaches 131 Hz
  EXPECT_THROW(tuneString(weak, TuneBy::tension, GridRule::transverse, k, 0.0, 1.0, 130.8),
               std::invalid_argument);
}

// Stiff-string partials n f0 sqrt(1 + B n²)/sqrt(1 + B), B = π² E I / (T0 L²), on a fine grid
// (16× oversampled), where the scheme's dispersion is far below 2 cents.
TEST(StringPitch, PartialsFollowTheStiffStringInharmonicity) {
  const double k = 1.0 / (48000.0 * 16.0);
  const StringPhysics p = c3();
  const NonlinearString string(p, gridSegments(p, GridRule::transverse, k, 0.0, 1.0));
  const double b =
      std::numbers::pi * std::numbers::pi * p.young * p.inertia / (p.tension * p.length * p.length);
  const double f1 = schemePartial(string, k, 1);
  for (int n = 2; n <= 10; ++n) {
    const double theory = n * std::sqrt(1.0 + b * n * n) / std::sqrt(1.0 + b);
    EXPECT_NEAR(cents(schemePartial(string, k, n) / f1, theory), 0.0, 2.0) << "partial " << n;
  }
  // And it is inharmonic: partial 10 sits well above 10 f1 (B ≈ 1e-4: ~ +8 cents).
  EXPECT_GT(cents(schemePartial(string, k, 10) / f1, 10.0), 5.0);
}

// BDZ Fig. 4–5: the fundamental rises with amplitude. At α = 300 the string is stretched by
// ~(π α sqrt(A) / 2L)² ≈ 5 % on average, which raises the effective tension from 759 N by
// E A · 5 % ≈ 9 kN: the fundamental more than doubles; at α = 1 it is the linear one.
TEST(StringPitch, FundamentalRisesWithAmplitude) {
  const double k = 2.6e-7;
  const StringPhysics p;  // the paper's C3, no stiffness
  const NonlinearString string(p, gridSegments(p, GridRule::longitudinal, k, 0.0, 1.05));
  auto fundamental = [&](double alpha) {
    const Vector u = modeShape(string.size(), string.segments(), 1, alpha * std::sqrt(p.area));
    SplitSav<NonlinearString> scheme(string, {.k = k}, {u, Vector::Zero(string.size())});
    std::vector<double> x;
    const Eigen::Index middle = string.segments() / 2 - 1;
    for (long n = 0; n < std::lround(0.03 / k); ++n) {
      x.push_back(scheme.q()[middle]);
      scheme.step();
    }
    return zeroCrossingFrequency(x, k);
  };
  const double linear = fundamental(1.0), loud = fundamental(300.0);
  EXPECT_NEAR(cents(linear, schemePartial(string, k, 1)), 0.0, 1.0);
  EXPECT_GT(loud / linear, 2.0);
}

// SCHEMES §3b at 48 kHz: the stiff C3 started in its first mode at α = 10 (9.4 mm) rises 20.8
// cents above its linear pitch on the converged string (Störmer–Verlet on the longitudinal grid at
// 960 kHz). The two grids with a gauge shift of the voices' default size (0.017 J, a tenth of a
// hardest C3 strike) rise the same within 1 % (measured 1.000); with ε = 0, where g's direction
// is undefined at rest, at 0.41 of it — why the default is not 0. The transverse grid: 0.002.
// Pitches from zero crossings of u(L/2) over 0.3 s (39 periods: a few millicents).
TEST(StringPitch, TwoGridsRiseWithAmplitudeLikeTheConvergedString) {
  const StringPhysics p = c3();
  auto rise = [&](GridRule rule, double rate, double epsilon, bool reference) {
    const double k = 1.0 / rate;
    const NonlinearString string(p, stringGrid(p, rule, k, 0.0, reference ? 1.05 : 1.0, 1.5));
    const int m = string.segments();
    const Eigen::Index middle = m / 2 - 1;
    auto pitch = [&](double alpha) {
      const InitialState start{modeShape(string.size(), m, 1, alpha * std::sqrt(p.area)),
                               Vector::Zero(string.size())};
      std::vector<double> x;
      auto run = [&](auto scheme) {
        for (long n = 0; n < std::lround(0.3 * rate); ++n) {
          x.push_back(scheme.q()[middle]);
          scheme.step();
        }
      };
      if (reference)
        run(StormerVerlet<NonlinearString>(string, {.k = k}, start));
      else
        run(SplitSav<NonlinearString>(string, {.k = k, .epsilon = epsilon}, start));
      return zeroCrossingFrequency(x, k);
    };
    return cents(pitch(10.0), pitch(0.01));
  };
  const double converged = rise(GridRule::longitudinal, 960000.0, 0.0, true);
  EXPECT_NEAR(converged, 20.8, 0.5);
  EXPECT_NEAR(rise(GridRule::twoGrid, 48000.0, 0.017, false) / converged, 1.0, 0.01);
  EXPECT_LT(rise(GridRule::twoGrid, 48000.0, 0.0, false) / converged, 0.6);
  EXPECT_LT(rise(GridRule::transverse, 48000.0, 0.0, false) / converged, 0.01);
}

// BDZ Fig. 5: on a fixed grid, (38) converges to the Störmer–Verlet reference as k falls,
// second order: the least-squares slope of the error of u(L/2, t) over 2 ms against k = 4e-7,
// 2e-7, 1e-7 is 2.27 (ratios 6.4, then 3.7: the coarsest step is not yet asymptotic), asserted in
// [1.8, 2.4]; a first-order error, or a start error that does not vanish with k, falls outside.
TEST(StringPitch, SplitSchemeConvergesToTheReferenceAtSecondOrder) {
  const StringPhysics p;
  const NonlinearString string(p, 300);  // h = 4.2 mm: SV needs c_L k < h, k < 8e-7
  const Vector u = modeShape(string.size(), 300, 1, 30.0 * std::sqrt(p.area));
  const InitialState start{u, Vector::Zero(string.size())};
  const Eigen::Index middle = 149;
  auto probe = [&](auto scheme, double k) {
    std::vector<double> x;
    for (long n = 0; n <= std::lround(2e-3 / k); ++n) {
      x.push_back(scheme.q()[middle]);
      scheme.step();
    }
    return x;
  };
  const double kRef = 2.5e-8;
  const auto ref = probe(StormerVerlet<NonlinearString>(string, {.k = kRef}, start), kRef);
  auto error = [&](double k) {
    const auto x = probe(SplitSav<NonlinearString>(string, {.k = k}, start), k);
    const long stride = std::lround(k / kRef);
    double e = 0.0, norm = 0.0;
    for (size_t n = 0; n < x.size(); ++n) {
      e += std::pow(x[n] - ref[n * stride], 2);
      norm += ref[n * stride] * ref[n * stride];
    }
    return std::sqrt(e / norm);
  };
  std::vector<double> logK, logError;
  for (double k : {4e-7, 2e-7, 1e-7}) {
    logK.push_back(std::log(k));
    logError.push_back(std::log(error(k)));
  }
  const double order = testing::leastSquaresSlope(logK, logError);
  ::testing::Test::RecordProperty("order", std::to_string(order));
  EXPECT_GE(order, 1.8);
  EXPECT_LE(order, 2.4);
}

}  // namespace
}  // namespace hamiltone
