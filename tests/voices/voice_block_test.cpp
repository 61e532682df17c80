// QuietDetector on tones of known decay: a voice is freed 50 ms after its level falls under both
// −80 dB of its loudest since the strike and the absolute floor — whichever is lower — and not
// before; the fade over those 50 ms only ever lowers the output; a negative floor never frees.
#include "voices/voice_block.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace hamiltone {
namespace {

constexpr double kRate = 48000.0;

// a·e^{−t/τ}·cos(2π·100 Hz·t), in blocks of 64, until the detector frees the voice: the time it
// did (NaN: not within `seconds`). `louder` is set when the fade left a sample louder than it was.
double freedAt(QuietDetector& quiet, double a, double tau, double seconds, bool& louder) {
  std::vector<float> left(64), right(64);
  for (long block = 0; block * 64 < seconds * kRate; ++block) {
    for (int i = 0; i < 64; ++i) {
      const double t = (block * 64 + i) / kRate;
      left[i] =
          static_cast<float>(a * std::exp(-t / tau) * std::cos(2 * std::numbers::pi * 100 * t));
      right[i] = 0.5f * left[i];
    }
    const std::vector<float> before = left;
    const bool free = quiet.update(left, right, 64);
    for (int i = 0; i < 64; ++i) louder = louder || std::abs(left[i]) > std::abs(before[i]);
    if (free) return (block + 1) * 64 / kRate;
  }
  return NAN;
}

// The level a·e^{−t/τ} crosses `bound` at τ·ln(a / bound). The last peak above it comes at most a
// half period (5 ms) before, the follower falls through the bound within 0.5 ms after (a peak is
// at most e^{5 ms/τ} over it), and the block rounds up by 1.3 ms: the voice goes 50 ms (the hold)
// after, from 5 ms early to 2 ms late.
void expectFreedAfter(double freed, double a, double tau, double bound) {
  const double quietFrom = tau * std::log(a / bound) + QuietDetector::kHoldS;
  EXPECT_GE(freed, quietFrom - 0.005);
  EXPECT_LE(freed, quietFrom + 0.002);
}

// A loud tone: the floor (1e-5) is above −80 dB of its peak (5e-5) and sets when it goes.
TEST(QuietDetector, ALoudToneGoesUnderTheFloor) {
  QuietDetector quiet;
  quiet.prepare(kRate);
  bool louder = false;
  const double freed = freedAt(quiet, 0.5, 0.2, 4.0, louder);
  expectFreedAfter(freed, 0.5, 0.2, QuietDetector::kFloor);
  EXPECT_FALSE(louder);
}

// A soft tone: −80 dB of its own peak (1e-7) is under the floor and sets when it goes.
TEST(QuietDetector, ASoftToneGoesAtEightyDecibelsUnderItsPeak) {
  QuietDetector quiet;
  quiet.prepare(kRate);
  bool louder = false;
  const double freed = freedAt(quiet, 1e-3, 0.2, 4.0, louder);
  expectFreedAfter(freed, 1e-3, 0.2, QuietDetector::kLevel * 1e-3);
  EXPECT_FALSE(louder);
}

// The floor a voice is given replaces the default (here under −80 dB of the peak, so it sets
// when the voice goes); a negative one keeps the voice.
TEST(QuietDetector, TheFloorIsTheVoicesAndNegativeNeverFrees) {
  QuietDetector quiet;
  quiet.prepare(kRate);
  quiet.setFloor(1e-6);
  bool louder = false;
  expectFreedAfter(freedAt(quiet, 0.5, 0.2, 4.0, louder), 0.5, 0.2, 1e-6);
  quiet.reset();  // keeps the floor
  expectFreedAfter(freedAt(quiet, 0.5, 0.2, 4.0, louder), 0.5, 0.2, 1e-6);
  quiet.setFloor(-1.0);
  quiet.reset();
  EXPECT_TRUE(std::isnan(freedAt(quiet, 0.5, 0.2, 6.0, louder)));
}

// A strike starts the loudest over: a soft note struck as a loud one's sound has died away is
// measured against its own peak. Measured against the loud one's 0.5 it would go at 5e-5, 26 dB
// before its own −80 dB.
TEST(QuietDetector, AStrikeMeasuresTheNewNoteFromItsOwnPeak) {
  QuietDetector quiet;
  quiet.prepare(kRate);
  quiet.setFloor(INFINITY);  // the relative bound alone
  std::vector<float> left(64), right(64);
  left[0] = 0.5f;  // a click of 0.5, then 130 ms of silence: the follower falls to 7.5e-4
  for (int block = 0; block < 98; ++block, left[0] = 0.0f) quiet.update(left, right, 64);
  quiet.strike();
  bool louder = false;
  const double freed = freedAt(quiet, 1e-3, 0.2, 4.0, louder);
  expectFreedAfter(freed, 1e-3, 0.2, QuietDetector::kLevel * 1e-3);
}

}  // namespace
}  // namespace hamiltone

namespace hamiltone {
namespace {

// Quiet for the 50 ms hold, then loud again a moment later (the beat of two unison strings can
// do it): the voice is free from the sample the hold ends, whether that sample's block ends
// quiet or loud. Blocks of 100 and one block of the whole signal agree on where, and on every
// sample. (The check once looked only at a block's end: the single block, ending loud, kept the
// voice; a G2 then ended 0.5 s apart in blocks of 100 and 256.)
TEST(QuietDetector, TheVoiceIsFreedWhereTheHoldEndsWhateverTheBlocks) {
  const long n = 24000;
  std::vector<float> signal(n, 1e-7f);
  for (long i = 0; i < 1000; ++i) signal[i] = (i % 2 == 0) ? 0.5f : -0.5f;
  auto run = [&](long block, long& freed) {
    QuietDetector quiet;
    quiet.prepare(kRate);
    std::vector<float> left = signal, right(n, 0.0f);
    freed = -1;
    for (long start = 0; start < n && freed < 0; start += block) {
      const long count = std::min(block, n - start);
      if (quiet.update(std::span(left).subspan(start, count),
                       std::span(right).subspan(start, count), count))
        freed = start + quiet.freedAt();
    }
    return left;
  };
  long bySample = 0, inBlocks = 0, whole = 0;
  run(1, bySample);  // where the hold ends: the follower's 20 ms release from 0.5, then 50 ms
  ASSERT_GT(bySample, 1000 + std::lround(QuietDetector::kHoldS * kRate));
  ASSERT_LT(bySample, n - 1000);
  for (long i = bySample + 200; i < n; ++i) signal[i] = 0.5f;  // loud again after it
  const std::vector<float> a = run(100, inBlocks), b = run(n, whole);
  EXPECT_EQ(inBlocks, bySample);
  EXPECT_EQ(whole, bySample);
  // The same samples up to the free one (after it the caller calls no more: the voice is reset).
  for (long i = 0; i <= bySample; ++i) ASSERT_EQ(a[i], b[i]) << i;
  for (long i = bySample; i < n; ++i) ASSERT_EQ(b[i], 0.0f) << i;
}

}  // namespace
}  // namespace hamiltone
