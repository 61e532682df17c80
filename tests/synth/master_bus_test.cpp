// The master bus's limiter as a stage of its own: transparent below its ceiling, never above it,
// with the attack, hold and release it specifies, meters that count what it did, and the same
// output for the same input; and the bus around it (volume, DC blocker, non-finite guard).
#include "synth/master_bus.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

namespace hamiltone {
namespace {

constexpr double kRate = 48000.0;
constexpr double kCeiling = PeakLimiter::kCeiling;

struct Limited {
  std::vector<double> out, gain;
};

// Both channels carry `in`; the right one negated, so the link is seen to take the larger |x|.
Limited limit(PeakLimiter& limiter, const std::vector<double>& in) {
  Limited run;
  for (double x : in) {
    double l = x, r = -0.5 * x;
    limiter.process(l, r);
    run.out.push_back(l);
    run.gain.push_back(limiter.gain());
  }
  return run;
}

std::vector<double> sine(double amplitude, double hz, double seconds) {
  std::vector<double> x(static_cast<size_t>(seconds * kRate));
  for (size_t n = 0; n < x.size(); ++n)
    x[n] = amplitude * std::sin(2.0 * std::numbers::pi * hz * static_cast<double>(n) / kRate);
  return x;
}

// A level `before` for `n0` frames, then `during` for `n1`, then `after` for `n2`.
std::vector<double> steps(double before, long n0, double during, long n1, double after, long n2) {
  std::vector<double> x(n0, before);
  x.insert(x.end(), n1, during);
  x.insert(x.end(), n2, after);
  return x;
}

// Below the ceiling the gain is exactly 1: every sample comes out bit for bit as it went in, and
// the meters show nothing done (a 27.5 Hz and a 4 kHz sine up to 0.1 dB under the ceiling).
TEST(PeakLimiter, BelowTheCeilingIsBitTransparent) {
  for (double hz : {27.5, 4000.0}) {
    PeakLimiter limiter;
    limiter.prepare(kRate);
    const double amplitude = kCeiling * std::pow(10.0, -0.1 / 20.0);
    const std::vector<double> in = sine(amplitude, hz, 1.0);
    const Limited run = limit(limiter, in);
    for (size_t n = 0; n < in.size(); ++n) ASSERT_EQ(run.out[n], in[n]) << hz << " Hz, frame " << n;
    EXPECT_EQ(limiter.gain(), 1.0);
    EXPECT_EQ(limiter.overFrames(), 0);
    EXPECT_EQ(limiter.limitedFrames(), 0);
    EXPECT_EQ(limiter.deepestReductionDb(), 0.0);
    EXPECT_NEAR(limiter.peakIn(), amplitude, 1e-6);
  }
}

// A step from −6 dB below the ceiling to +12 dB above it: the first frame over it already comes
// out at the ceiling (attack 0 frames), no frame exceeds it (no overshoot, not by one rounding),
// and it is held there while the step lasts.
TEST(PeakLimiter, HoldsAStepAtTheCeilingWithInstantAttackAndNoOvershoot) {
  PeakLimiter limiter;
  limiter.prepare(kRate);
  const long n0 = 4800, n1 = 9600;
  const double loud = 4.0 * kCeiling;  // +12 dB
  const Limited run = limit(limiter, steps(0.5 * kCeiling, n0, loud, n1, 0.0, 0));
  for (long n = 0; n < n0; ++n) ASSERT_EQ(run.gain[n], 1.0);
  for (long n = n0; n < n0 + n1; ++n) {
    ASSERT_LE(std::abs(run.out[n]), kCeiling) << "frame " << n;
    ASSERT_NEAR(std::abs(run.out[n]), kCeiling, 1e-15) << "frame " << n;
  }
  EXPECT_EQ(limiter.overFrames(), n1);
  EXPECT_NEAR(limiter.deepestReductionDb(), 20.0 * std::log10(4.0), 1e-9);
  EXPECT_EQ(limiter.peakIn(), loud);
}

// After the step the gain stays put for kHoldS, then 1 − gain decays as exp(−t/kReleaseS): the
// hold measured to the frame, the time constant to within a frame, and the gain exactly 1 again
// once within kSnap of it, after ln((1 − g0)/kSnap) time constants.
TEST(PeakLimiter, HoldsThenReleasesWithItsTimeConstant) {
  PeakLimiter limiter;
  limiter.prepare(kRate);
  const long n0 = 480, n1 = 480, n2 = static_cast<long>(2.0 * kRate);
  const Limited run = limit(limiter, steps(0.1, n0, 2.0 * kCeiling, n1, 0.1, n2));
  const double g0 = 0.5;
  const long end = n0 + n1;  // the first frame after the step
  const long hold = std::lround(PeakLimiter::kHoldS * kRate);
  EXPECT_EQ(limiter.holdFrames(), hold);
  for (long n = n0; n < end + hold; ++n) ASSERT_DOUBLE_EQ(run.gain[n], g0) << "frame " << n;
  EXPECT_GT(run.gain[end + hold], g0);  // the release begins right after the hold
  long tau = end + hold;
  while ((1.0 - run.gain[tau]) > (1.0 - g0) / std::numbers::e) ++tau;
  const double measured = static_cast<double>(tau - (end + hold) + 1) / kRate;
  EXPECT_NEAR(measured, PeakLimiter::kReleaseS, 1.0 / kRate);
  long back = end + hold;
  while (run.gain[back] < 1.0) ++back;
  const double expected = PeakLimiter::kReleaseS * std::log((1.0 - g0) / PeakLimiter::kSnap);
  EXPECT_NEAR(static_cast<double>(back - (end + hold)) / kRate, expected, 2.0 / kRate);
  EXPECT_EQ(limiter.limitedFrames(), back - n0);  // every frame it reduced, and no other
  EXPECT_EQ(limiter.overFrames(), n1);
  for (long n = back; n < end + n2; ++n) ASSERT_EQ(run.out[n], 0.1);
}

// A sine over the ceiling: whatever the crest, no frame leaves above it, and a louder input is
// not let through by the release (the release waits a frame rather than cross the ceiling).
TEST(PeakLimiter, NeverExceedsTheCeiling) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> level(0.0, 20.0);
  PeakLimiter limiter;
  limiter.prepare(kRate);
  std::vector<double> in = sine(3.0, 55.0, 0.5);
  for (int n = 0; n < 48000; ++n) in.push_back(level(random) * (n % 2 ? 1.0 : -1.0));
  const std::vector<double> swell = sine(1.5, 1000.0, 0.5);
  in.insert(in.end(), swell.begin(), swell.end());
  const Limited run = limit(limiter, in);
  for (size_t n = 0; n < in.size(); ++n) ASSERT_LE(std::abs(run.out[n]), kCeiling) << n;
  EXPECT_GT(limiter.overFrames(), 0);
  EXPECT_GT(limiter.deepestReductionDb(), 20.0 * std::log10(15.0 / kCeiling));
}

// The same input gives the same output, bit for bit, on a second limiter and after reset().
TEST(PeakLimiter, IsDeterministic) {
  std::vector<double> in = sine(2.0, 110.0, 0.3);
  const std::vector<double> quiet = sine(0.3, 440.0, 0.3);
  in.insert(in.end(), quiet.begin(), quiet.end());
  PeakLimiter a, b;
  a.prepare(kRate);
  b.prepare(kRate);
  const Limited first = limit(a, in), second = limit(b, in);
  a.reset();
  a.clearMeters();
  const Limited again = limit(a, in);
  EXPECT_EQ(first.out, second.out);
  EXPECT_EQ(first.out, again.out);
  EXPECT_EQ(a.limitedFrames(), b.limitedFrames());
  EXPECT_EQ(a.deepestGain(), b.deepestGain());
}

// The bus: a forte-level sine is untouched by the limiter; a signal far over the ceiling, with
// infinities and NaNs in it, leaves finite and at most the ceiling (as a float), and the meters
// show it.
TEST(MasterBus, LimitsOnlyWhatCrossesTheCeiling) {
  MasterBus bus;
  bus.prepare(kRate);
  std::vector<float> left(48000), right(48000);
  for (size_t n = 0; n < left.size(); ++n)
    left[n] = right[n] =
        static_cast<float>(0.5 * std::sin(2.0 * std::numbers::pi * 440.0 * n / kRate));
  bus.process(left, right);
  EXPECT_EQ(bus.limiter().limitedFrames(), 0);
  EXPECT_EQ(bus.limiterGain(), 1.0);

  std::mt19937 random(3);
  std::uniform_real_distribution<float> level(-50.0f, 50.0f);
  for (size_t n = 0; n < left.size(); ++n) {
    left[n] = level(random);
    right[n] = n % 1000 == 0 ? INFINITY : n % 1000 == 1 ? NAN : level(random);
  }
  bus.process(left, right);
  for (size_t n = 0; n < left.size(); ++n) {
    ASSERT_TRUE(std::isfinite(left[n]) && std::isfinite(right[n]));
    ASSERT_LE(std::abs(left[n]), static_cast<float>(kCeiling));
    ASSERT_LE(std::abs(right[n]), static_cast<float>(kCeiling));
  }
  EXPECT_EQ(bus.nonFinite(), 96);
  EXPECT_GT(bus.limiter().overFrames(), 0);
  EXPECT_GT(bus.limiter().deepestReductionDb(), 20.0 * std::log10(10.0 / kCeiling));
  EXPECT_GT(bus.limiter().peakIn(), 10.0);
}

}  // namespace
}  // namespace hamiltone
