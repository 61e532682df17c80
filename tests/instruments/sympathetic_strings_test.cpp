// The sympathetic strings on the soundboard (PianoBody): the coupled system's energy balance to
// roundoff, the strings' resonance through the board with the dampers lifted and down, exclusion
// of a played key, and the stability check (Y6).
#include "instruments/sympathetic_strings.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

#include "instruments/piano_body.h"

namespace hamiltone {
namespace {

constexpr double kRate = 48000.0;
constexpr double kPi = std::numbers::pi;
constexpr int kA0 = 21;

PianoBody preparedBody(std::vector<SympatheticKey> keys, const PianoBodySpec& spec = {}) {
  PianoBody body;
  body.prepare(spec, bridgeLine(21, 108, spec.board), keys);
  return body;
}

std::vector<SympatheticKey> lossless(std::vector<SympatheticKey> keys) {
  for (auto& k : keys) k.t60Low = k.t60High = std::numeric_limits<double>::infinity();
  return keys;
}

// Runs `steps` with a random force on a few keys for the first third; returns the worst
// |H + dissipated − supplied| over the largest of |H|, dissipated, supplied.
double balanceResidual(PianoBody& body, int steps, double* scaleOut = nullptr) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> force(0.0, 10.0);
  std::vector<double> f(body.keys(), 0.0);
  double scale = 0.0, worst = 0.0;
  for (int n = 0; n < steps; ++n) {
    for (int k : {5, 27, 39, 51, 80}) f[k] = n < steps / 3 ? force(rng) : 0.0;
    body.step(f);
    const double h = body.energy();
    scale = std::max({scale, std::abs(h), body.dissipated(), body.supplied()});
    worst = std::max(worst, std::abs(h + body.dissipated() - body.supplied()));
  }
  if (scaleOut) *scaleOut = scale;
  return worst / scale;
}

TEST(SympatheticStrings, PartialsAreTheStiffStrings) {
  const auto keys = grandSympatheticKeys();
  const PianoBody body = preparedBody(keys);
  const SympatheticStrings& s = body.strings();
  ASSERT_EQ(s.keys(), 88);
  for (int key : {0, 39, 60, 75, 87}) {
    ASSERT_GE(s.partials(key), 1);
    for (int n = 1; n <= s.partials(key); ++n) {
      const double expected = n * keys[key].f0 * std::sqrt(1 + keys[key].inharmonicityB * n * n);
      EXPECT_NEAR(s.partialHz(key, n), expected, 1e-12 * expected);
      EXPECT_LE(s.partialHz(key, n), 4500.0);
    }
  }
  EXPECT_EQ(s.partials(0), 16);  // A0: the cap
}

// Board + strings, dampers lifted, lossy: the balance of (S3) with (Y5) holds to roundoff.
TEST(SympatheticStrings, CoupledEnergyBalanceDampersLiftedToRoundoff) {
  PianoBody body = preparedBody(grandSympatheticKeys());
  for (int k = 0; k < body.keys(); ++k) body.setDamper(k, 0.0);
  double scale = 0;
  const double r = balanceResidual(body, 12000, &scale);
  std::printf("coupled balance residual %.3g of %.3g J\n", r, scale);
  EXPECT_LT(r, 1e-12);
  EXPECT_GT(body.strings().dissipated(), 0.0);
}

// Lossless board and strings: once the force stops, H_board + H_strings + H_c is constant.
TEST(SympatheticStrings, LosslessCoupledSystemConservesEnergyExactly) {
  PianoBodySpec spec;
  spec.board.lossFactor = 0.0;
  PianoBody body = preparedBody(lossless(grandSympatheticKeys()), spec);
  for (int k = 0; k < body.keys(); ++k) body.setDamper(k, 0.0);
  std::vector<double> f(body.keys(), 0.0);
  f[39] = 40.0;
  f[70] = -25.0;
  body.step(f);
  f.assign(body.keys(), 0.0);
  const double h0 = body.energy();
  double worst = 0.0;
  for (int n = 0; n < 20000; ++n) {
    body.step(f);
    worst = std::max(worst, std::abs(body.energy() - h0));
  }
  std::printf("lossless drift %.3g of %.3g J\n", worst / h0, h0);
  EXPECT_EQ(body.dissipated(), 0.0);
  EXPECT_GT(h0, 0.0);
  EXPECT_LT(worst, 1e-12 * h0);
}

// Excluding a key (a voice plays it) and bringing it back keeps the balance: the jump is booked.
TEST(SympatheticStrings, ExclusionKeepsTheBalance) {
  PianoBody body = preparedBody(grandSympatheticKeys());
  for (int k = 0; k < body.keys(); ++k) body.setDamper(k, 0.0);
  std::vector<double> f(body.keys(), 0.0);
  double scale = 0.0, worst = 0.0;
  for (int n = 0; n < 9000; ++n) {
    f[39] = n < 3000 ? 20.0 * std::sin(2 * kPi * 261.6 * n / kRate) : 0.0;
    if (n == 1500) body.setExcluded(39, true);
    if (n == 1600) body.setExcluded(51, true);
    if (n == 4000) body.setExcluded(39, false);
    body.step(f);
    const double h = body.energy();
    scale = std::max({scale, std::abs(h), body.dissipated(), body.supplied()});
    worst = std::max(worst, std::abs(h + body.dissipated() - body.supplied()));
  }
  EXPECT_TRUE(body.strings().excluded(51));
  EXPECT_EQ(body.strings().keyEnergy(51), 0.0);
  EXPECT_LT(worst, 1e-12 * scale);
}

// A body prepared again after keys left the coupling steps exactly as a fresh one: the runs of
// coupled keys the strings step are found anew (every key is coupled after prepare()).
TEST(SympatheticStrings, PreparedAgainStepsAsAFreshBody) {
  const std::vector<SympatheticKey> keys = grandSympatheticKeys();
  PianoBody reused = preparedBody(keys);
  for (int k = 0; k < reused.keys(); ++k) reused.setDamper(k, 0.0);
  for (int k = 10; k < 80; ++k) reused.setExcluded(k, true);  // runs: 0–9 and 80–87
  std::vector<double> f(reused.keys(), 0.0);
  for (int n = 0; n < 500; ++n) {
    f[5] = std::sin(0.02 * n);
    reused.step(f);
  }
  reused.prepare({}, bridgeLine(21, 108, SoundboardPhysics{}), keys);
  PianoBody fresh = preparedBody(keys);
  for (PianoBody* body : {&reused, &fresh})
    for (int k = 0; k < body->keys(); ++k) body->setDamper(k, 0.0);
  std::fill(f.begin(), f.end(), 0.0);
  for (int n = 0; n < 2000; ++n) {
    f[39] = n < 1000 ? 20.0 * std::sin(2 * kPi * 261.6 * n / kRate) : 0.0;
    reused.step(f);
    fresh.step(f);
  }
  EXPECT_GT(fresh.strings().keyEnergy(45), 0.0);  // a key the old runs left out rings
  EXPECT_EQ(reused.strings().keyEnergy(45), fresh.strings().keyEnergy(45));
  EXPECT_EQ(reused.energy(), fresh.energy());
  double l = 0.0, r = 0.0, lf = 0.0, rf = 0.0;
  reused.output(l, r);
  fresh.output(lf, rf);
  EXPECT_EQ(l, lf);
  EXPECT_EQ(r, rf);
}

struct CoupledMode {
  double hz, sigma;
};

// Dampers down, one key played by a voice (excluded): the damped keys fall asleep once quiet (the
// board's slowest modes take 2.5 s) and leave the board's products (points in use: the 20 keys
// without dampers; the voice's key is driven, not read), one wakes when its damper lifts, others
// when the board moves them again, and the balance holds through it all, the switches booked.
TEST(SympatheticStrings, QuietDampedKeysSleepAndWakeKeepingTheBalance) {
  PianoBody body = preparedBody(grandSympatheticKeys());
  const int c4 = 60 - kA0, c5 = 72 - kA0;
  for (int k = 0; k < body.keys(); ++k) body.setDamper(k, 1.0);
  body.setExcluded(c4, true);
  std::vector<double> f(body.keys(), 0.0);
  double scale = 0.0, worst = 0.0;
  bool sleptC5 = false;
  int fewest = body.keys();
  const int steps = static_cast<int>(3.0 * kRate), lift = static_cast<int>(2.5 * kRate);
  for (int n = 0; n < steps; ++n) {
    f[c4] = n < 6000 ? 20.0 * std::sin(2 * kPi * 261.6 * n / kRate) * std::exp(-n / 4000.0) : 0.0;
    if (n == lift) {
      sleptC5 = body.strings().asleep(c5);
      fewest = body.pointsInUse();
      body.setDamper(c5, 0.0);  // wakes it
    }
    body.step(f);
    const double h = body.energy();
    scale = std::max({scale, std::abs(h), body.dissipated(), body.supplied()});
    worst = std::max(worst, std::abs(h + body.dissipated() - body.supplied()));
  }
  std::printf("points in use after 2.5 s: %d, at 3 s %d; balance residual %.3g\n", fewest,
              body.pointsInUse(), worst / scale);
  EXPECT_TRUE(sleptC5);
  EXPECT_EQ(fewest, 20);  // F6 … C8
  EXPECT_FALSE(body.strings().asleep(c5));
  EXPECT_TRUE(body.strings().coupled(c5));
  EXPECT_EQ(body.pointsInUse(), 21);  // and C5
  EXPECT_LT(worst, 1e-12 * scale);
  // A force at a sleeping key (A0) moves the board: the damped keys it moves past the floor wake,
  // A0 among them, and once the board is quiet again they sleep; the balance holds throughout.
  ASSERT_TRUE(body.strings().asleep(0));
  const double suppliedBefore = body.supplied();
  int most = 0;
  bool wokeA0 = false;
  for (int n = 0; n < static_cast<int>(4.0 * kRate); ++n) {
    f[0] = n < 500 ? std::sin(0.01 * n) : 0.0;
    body.step(f);
    most = std::max(most, body.pointsInUse());
    wokeA0 = wokeA0 || body.strings().coupled(0);
    const double h = body.energy();
    scale = std::max({scale, std::abs(h), body.dissipated(), body.supplied()});
    worst = std::max(worst, std::abs(h + body.dissipated() - body.supplied()));
  }
  std::printf("A0 driven: %d points in use at most, %d 4 s later\n", most, body.pointsInUse());
  EXPECT_GT(most, 21);
  EXPECT_TRUE(wokeA0);
  EXPECT_EQ(body.pointsInUse(), 21);
  EXPECT_NE(body.supplied(), suppliedBefore);  // A0's force did work on the board
  EXPECT_LT(worst, 1e-12 * scale);
}

// A note from silence. Every damped key is asleep (dampers down, the board still); a voice takes
// C4 and strikes it, and its string's wave reaches the board 900 steps later (A0's takes ~760),
// past three of the body's looks. The strike wakes the keys and keeps them awake until the wave has
// come, so the board feels the load of every damped string as it does with none asleep (floor −1:
// they never sleep). When asleep keys woke only as their dampers lifted, the difference over the
// signal was −3.4 dB here (−7 dB in the synth, A0 struck hard after silence); the floor's share now
// stays below −40 dB.
TEST(SympatheticStrings, KeysAsleepBeforeANoteWakeWhenItsWaveArrives) {
  PianoBody sleeping = preparedBody(grandSympatheticKeys());
  PianoBody awake = preparedBody(grandSympatheticKeys());
  awake.setQuietFloor(-1.0);
  const int c4 = 60 - kA0;
  for (PianoBody* body : {&sleeping, &awake})
    for (int k = 0; k < body->keys(); ++k) body->setDamper(k, 1.0);
  std::vector<double> f(sleeping.keys(), 0.0);
  const int silent = 600, travel = 900, steps = silent + static_cast<int>(1.0 * kRate);
  double signal = 0.0, difference = 0.0;
  int fewest = sleeping.keys(), onArrival = 0;
  for (int n = 0; n < steps; ++n) {
    if (n == silent) {  // a voice takes C4 and strikes it
      fewest = sleeping.pointsInUse();
      sleeping.setExcluded(c4, true);
      awake.setExcluded(c4, true);
    }
    const int t = n - silent - travel;
    if (t == 0) onArrival = sleeping.pointsInUse();
    f[c4] = t >= 0 ? 20.0 * std::sin(2 * kPi * 261.6 * t / kRate) * std::exp(-t / 4000.0) : 0.0;
    sleeping.step(f);
    awake.step(f);
    double l1, r1, l2, r2;
    sleeping.output(l1, r1);
    awake.output(l2, r2);
    signal += l2 * l2 + r2 * r2;
    difference += (l1 - l2) * (l1 - l2) + (r1 - r2) * (r1 - r2);
  }
  const double db = 10.0 * std::log10(difference / signal);
  std::printf("points in use before the strike %d, as the wave arrives %d; difference %.1f dB\n",
              fewest, onArrival, db);
  EXPECT_EQ(fewest, 20);     // every damped key asleep: F6 … C8 alone
  EXPECT_EQ(onArrival, 87);  // all awake, C4 the voice's
  EXPECT_LT(db, -40.0);
}

// A board driven steadily at A0's point after silence (5 N at 55 Hz), no key struck: the keys it
// moves wake and, at this drive, stay awake — a key that follows the board does not sleep because
// it hardly rings (the following energy keeps it in), so the points in use settle and do not flip
// from look to look. (w is read at one instant: a key near the threshold could still sleep at a
// zero crossing; here none is.)
TEST(SympatheticStrings, KeysTheBoardMovesStayAwake) {
  PianoBody body = preparedBody(grandSympatheticKeys());
  for (int k = 0; k < body.keys(); ++k) body.setDamper(k, 1.0);
  std::vector<double> f(body.keys(), 0.0);
  const int silent = 600, settle = static_cast<int>(0.1 * kRate);
  int flips = 0, last = -1, fewest = body.keys();
  for (int n = 0; n < silent + static_cast<int>(0.6 * kRate); ++n) {
    const int t = n - silent;
    if (t == 0) fewest = body.pointsInUse();
    f[0] = t >= 0 ? 5.0 * std::sin(2 * kPi * 55.0 * t / kRate) : 0.0;
    body.step(f);
    if (t >= settle && n % 256 == 0) {
      if (last >= 0 && body.pointsInUse() != last) ++flips;
      last = body.pointsInUse();
    }
  }
  std::printf("points in use: %d before, %d driven; %d changes after 0.1 s\n", fewest, last, flips);
  EXPECT_EQ(fewest, 20);
  EXPECT_GT(last, 40);
  EXPECT_EQ(flips, 0);
}

// |Σ_n a_n e^{−iωn/fs}| over [from, to) with a Hann window: the partial's component at hz.
double component(const std::vector<double>& a, int from, int to, double hz) {
  std::complex<double> sum = 0.0;
  const double step = 2 * kPi * hz / kRate;
  for (int n = from; n < to; ++n) {
    const double hann = 0.5 - 0.5 * std::cos(2 * kPi * (n - from) / (to - from));
    sum += hann * a[n] * std::polar(1.0, -step * n);
  }
  return std::abs(sum);
}

// The coupled first partial of key `key`: ring the board at the key's point, wait 0.5 s for the
// board's modes to die down (σ = ηω/2), then find the partial's spectral peak within ±3 % of the
// string's frequency (1 Hz scan, golden-section refinement) and its decay from the peak's height
// in two windows 0.25 s apart. The partial also follows the board quasi-statically (its slow
// lowest modes, the undamped treble strings), which a zero-crossing count would mistake for it.
// The other keys' dampers are down.
CoupledMode coupledMode(PianoBody& body, int key) {
  std::vector<double> f(body.keys(), 0.0);
  f[key] = 100.0;
  body.step(f);
  f[key] = 0.0;
  const int start = static_cast<int>(0.5 * kRate), mid = static_cast<int>(0.75 * kRate),
            end = static_cast<int>(1.0 * kRate);
  std::vector<double> a(end);
  for (int n = 0; n < end; ++n) {
    body.step(f);
    a[n] = body.strings().partialAmplitude(key, 1);
  }
  body.reset();
  const double nominal = body.strings().partialHz(key, 1);
  double best = nominal, bestValue = 0.0;
  for (double hz = 0.97 * nominal; hz <= 1.03 * nominal; hz += 1.0)
    if (const double v = component(a, start, end, hz); v > bestValue) best = hz, bestValue = v;
  double lo = best - 1.0, hi = best + 1.0;
  const double g = (std::sqrt(5.0) - 1) / 2;
  for (int i = 0; i < 40; ++i) {
    const double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
    if (component(a, start, end, x1) > component(a, start, end, x2))
      hi = x2;
    else
      lo = x1;
  }
  const double hz = (lo + hi) / 2;
  const double early = component(a, start, mid, hz), late = component(a, mid, end, hz);
  return {hz, std::log(early / late) / ((mid - start) / kRate)};
}

struct DrivenResponse {
  double energy;     // the receiver's string energy, mean over the drive's last 0.25 s, J
  double partial;    // its first partial's component at the drive's frequency, same window
  double afterward;  // its string energy 0.25 s after the drive stops, J
};

// A 2.5 s sinusoid of `hz` at key `driven`'s bridge point, then 0.25 s of silence.
DrivenResponse drive(PianoBody& body, int driven, int receiver, double hz) {
  std::vector<double> f(body.keys(), 0.0), partial;
  const int steps = static_cast<int>(2.5 * kRate), tail = static_cast<int>(0.25 * kRate);
  double sum = 0.0;
  for (int n = 0; n < steps + tail; ++n) {
    f[driven] = n < steps ? std::sin(2 * kPi * hz * n / kRate) : 0.0;
    body.step(f);
    partial.push_back(body.strings().partialAmplitude(receiver, 1));
    if (n >= steps - tail && n < steps) sum += body.strings().keyEnergy(receiver);
  }
  const DrivenResponse r{sum / tail, component(partial, steps - tail, steps, hz),
                         body.strings().keyEnergy(receiver)};
  body.reset();
  return r;
}

// C4's bridge point forced at C5's coupled fundamental, the other dampers down. Were the board a
// resistance, the first partial's amplitude would go as 1/σ, σ the coupled mode's decay rate (the
// string's own loss plus the board's share, measured lifted; the damper adds its σ), and lifted
// over damped would be 20 log10(σ_damped/σ_lifted) (printed). Here a board mode at 517.7 Hz,
// with shape 0.65 at C5's point, makes the coupled mode a hybrid and the contrast smaller: the
// test asks only for > 6 dB while driven. When the drive stops (C4 released) the damped string dies
// in its 0.37 s while the lifted one rings on: ≥ 20 dB more energy 0.25 s later. C#5, whose
// partials miss the frequency, holds ≥ 20 dB less energy than C5 beside it on the bridge.
TEST(SympatheticStrings, StringsRingInSympathyWithDampersLifted) {
  PianoBody body = preparedBody(grandSympatheticKeys());
  const int c4 = 60 - kA0, c5 = 72 - kA0, cs5 = 73 - kA0;
  for (int k = 0; k < body.keys(); ++k) body.setDamper(k, 1.0);
  const double sigmaDamper = body.strings().partialDecayRate(c5, 1);
  body.setDamper(c5, 0.0);
  body.setDamper(cs5, 0.0);
  const double sigmaOwn = body.strings().partialDecayRate(c5, 1);
  const CoupledMode lifted = coupledMode(body, c5);
  const double hz = lifted.hz;
  EXPECT_NEAR(hz, body.strings().partialHz(c5, 1), 0.01 * hz);  // the board pulls it a little
  const DrivenResponse up = drive(body, c4, c5, hz);
  const DrivenResponse neighbour = drive(body, c4, cs5, hz);
  body.setDamper(c5, 1.0);
  const DrivenResponse down = drive(body, c4, c5, hz);
  // The board's share of the lifted decay, σ_lifted − σ_own, is the same with the damper on.
  const double dampedSigma = sigmaDamper + lifted.sigma - sigmaOwn;
  const double expectedDb = 20 * std::log10(dampedSigma / lifted.sigma);
  const double partialDb = 20 * std::log10(up.partial / down.partial);
  const double energyDb = 10 * std::log10(up.energy / down.energy);
  const double afterDb = 10 * std::log10(up.afterward / down.afterward);
  const double neighbourDb = 10 * std::log10(up.energy / neighbour.energy);
  std::printf(
      "C5 coupled %.3f Hz (string %.3f), sigma lifted %.3f damped %.3f 1/s; driven, lifted over "
      "damped: partial 1 %.1f dB (sigma ratio %.1f dB), key energy %.1f dB; 0.25 s after: "
      "%.1f dB; C5/C#5 %.1f dB\n",
      hz, body.strings().partialHz(c5, 1), lifted.sigma, dampedSigma, partialDb, expectedDb,
      energyDb, afterDb, neighbourDb);
  EXPECT_GT(partialDb, 6.0);
  EXPECT_GT(energyDb, 6.0);
  EXPECT_GE(afterDb, 20.0);
  EXPECT_GE(neighbourDb, 20.0);
}

// A damper adds its rate to every partial's own, as a voice's does (releasedSigma0): contact c
// adds c ln(1000)/damperT60 exactly, so it never lets a string ring longer than lifted — the
// preset's "1000 s: no damper" once made the undamped treble ring at 0.06 dB/s with the pedal up.
TEST(SympatheticStrings, ADamperOnlyAddsLoss) {
  const auto keys = grandSympatheticKeys();
  PianoBody body = preparedBody(keys);
  for (int key = 0; key < body.keys(); ++key) {
    std::vector<double> own;
    body.setDamper(key, 0.0);
    for (int n = 1; n <= body.strings().partials(key); ++n)
      own.push_back(body.strings().partialDecayRate(key, n));
    for (double c : {0.25, 1.0}) {
      body.setDamper(key, c);
      const double added =
          std::isinf(keys[key].damperT60) ? 0.0 : c * 6.907755278982137 / keys[key].damperT60;
      for (int n = 1; n <= body.strings().partials(key); ++n)
        ASSERT_DOUBLE_EQ(body.strings().partialDecayRate(key, n), own[n - 1] + added)
            << "key " << key << " partial " << n << " contact " << c;
    }
    EXPECT_EQ(body.strings().damped(key), !std::isinf(keys[key].damperT60)) << "key " << key;
  }
}

TEST(SympatheticStrings, StabilityConditionIsChecked) {
  auto keys = grandSympatheticKeys();
  keys[87].tension = 1e9;  // a string as stiff as a wall on the bridge
  PianoBody body;
  const PianoBodySpec spec;
  try {
    body.prepare(spec, bridgeLine(21, 108, spec.board), keys);
    ADD_FAILURE() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("must be < 2 for stability"));
  }
}

TEST(SympatheticStrings, InvalidKeysAreRefusedByName) {
  const PianoBodySpec spec;
  const auto points = bridgeLine(21, 108, spec.board);
  auto keys = grandSympatheticKeys();
  keys[10].length = -1.0;
  PianoBody body;
  try {
    body.prepare(spec, points, keys);
    ADD_FAILURE();
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("key 10 length = -1"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("> 0"));
  }
  keys = grandSympatheticKeys();
  keys.pop_back();
  EXPECT_THROW(body.prepare(spec, points, keys), std::invalid_argument);
  PianoBodySpec high = spec;
  high.sympatheticMaxHz = 13000.0;  // above fs/4
  try {
    body.prepare(high, points, grandSympatheticKeys());
    ADD_FAILURE();
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("maxHz = 13000: must be in (0, 12000)"));
  }
}

}  // namespace
}  // namespace hamiltone
