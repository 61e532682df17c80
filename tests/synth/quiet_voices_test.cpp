// Silent voices free themselves in the synthesizer whether the key is held, kept by the pedal or
// released: each only once its sound is under −80 dB of its own peak and −100 dBFS, so the take
// differs from one where no voice is ever freed by less than that; and a key struck again after
// its voices were freed sounds as a strike from rest.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "support/synth_takes.h"
#include "support/test_instruments.h"
#include "synth/synth.h"

namespace hamiltone {
namespace {

using testing::cc;
using testing::off;
using testing::on;
using testing::peak;
using testing::prepared;
using testing::render;
using testing::Take;

constexpr double kRate = testing::kTakeRate;
constexpr int kBlock = 32;
const long kHold = std::lround(QuietDetector::kHoldS * kRate);

// RT-425 keys, one string each, centred (so each channel carries a key at the gain its floor
// assumes), 12 dB down (the floor holds after the instrument's gain) and decaying fast (T60 1 s,
// 0.5 s at 2 kHz): a held note is inaudible within seconds.
Instrument fastDecaying(int lowest, int highest) {
  Instrument piano = testing::pianoKeys(lowest, highest, 8);
  piano.panSpread = 0.0;
  piano.gainDb = -12.0;
  for (StringKey& key : piano.keys) {
    key.patch.t60Low = 1.0;
    key.patch.t60High = 0.5;
  }
  return piano;
}

float largestDifference(const Take& a, const Take& b) {
  float d = 0.0f;
  for (size_t i = 0; i < a.left.size(); ++i)
    d = std::max({d, std::abs(a.left[i] - b.left[i]), std::abs(a.right[i] - b.right[i])});
  return d;
}

// Plays `score` for `seconds` with voices freed and with none freed, and each of `notes` alone
// (with the score's controllers) with none freed. Each note's key must be freed within the take,
// and only once its own sound, from the start of the 50 ms fade on, is under its bound —
// min(−80 dB of its peak, −100 dBFS); the two takes then differ by less than the bounds' sum. The
// keys add linearly (the limiter stays idle: checked), so a key's own sound is its solo take.
void expectOnlySilenceCut(const Instrument& instrument, const std::vector<TimedMessage>& score,
                          const std::vector<int>& notes, double seconds) {
  // Sample by sample, to see each key's last sounding sample.
  Synth freeing = prepared({instrument}, kBlock);
  std::vector<long> freedAt(notes.size(), -1);
  const Take freed = render(freeing, score, seconds, 1, [&](long frames) {
    for (size_t k = 0; k < notes.size(); ++k)
      if (freedAt[k] < 0 && frames > kRate * 0.1 && !freeing.voice(0, notes[k])->sounding())
        freedAt[k] = frames;
  });
  Synth keeping = prepared({instrument}, kBlock, false);
  const Take kept = render(keeping, score, seconds, kBlock);
  ASSERT_LT(peak(kept), MasterBus::kCeiling);
  EXPECT_EQ(keeping.activeVoices(), static_cast<int>(notes.size()));

  double bounds = 0.0;
  for (size_t k = 0; k < notes.size(); ++k) {
    std::vector<TimedMessage> own;
    for (const TimedMessage& m : score)
      if ((m.message.kind() != midi::noteOn && m.message.kind() != midi::noteOff) ||
          m.message.data1 == notes[k])
        own.push_back(m);
    Synth alone = prepared({instrument}, kBlock, false);
    const Take solo = render(alone, own, seconds, kBlock);
    const double bound = std::min(QuietDetector::kLevel * peak(solo), QuietDetector::kFloor);
    bounds += bound;
    ASSERT_GE(freedAt[k], 0) << "note " << notes[k] << " never freed";
    // Its last sample was freedAt − 1, the last of the fade, which began kHold − 1 before.
    const size_t fadeFrom = freedAt[k] - kHold;
    EXPECT_LE(peak(solo, fadeFrom), bound) << "note " << notes[k];
    // And not long after the sound went under the bound: within the hold and 50 ms.
    size_t under = solo.left.size();
    while (under > 0 &&
           std::max(std::abs(solo.left[under - 1]), std::abs(solo.right[under - 1])) <= bound)
      --under;
    EXPECT_LE(freedAt[k], static_cast<long>(under) + kHold + std::lround(0.05 * kRate))
        << "note " << notes[k];
  }
  EXPECT_LE(largestDifference(freed, kept), bounds);
  EXPECT_EQ(freeing.activeVoices(), 0);
}

// F1 held for 3 s: freed while the key is still down. Struck softly, it peaks under 0.1, so its
// own −80 dB is under −100 dBFS and sets when it goes.
TEST(QuietVoices, AHeldLowNoteIsFreedOnlyOnceInaudible) {
  expectOnlySilenceCut(fastDecaying(29, 29), {{0.0, on(29, 20)}}, {29}, 3.0);
}

// A C major chord let go under the pedal, which stays down: freed while the pedal holds it.
// Struck mezzo-forte, each key peaks over 0.1: −100 dBFS sets when it goes.
TEST(QuietVoices, APedalledChordIsFreedOnlyOnceInaudible) {
  const std::vector<TimedMessage> score = {
      {0.0, cc(64, 127)}, {0.01, on(48, 90)}, {0.01, on(52, 80)}, {0.01, on(55, 70)},
      {0.3, off(48)},     {0.3, off(52)},     {0.3, off(55)}};
  expectOnlySilenceCut(fastDecaying(48, 55), score, {48, 52, 55}, 3.0);
}

// A held key freed by its silence and struck again starts from rest: the take is the strike of
// a fresh synthesizer (to roundoff: the master's DC blocker still holds 1e-14 of the first note).
TEST(QuietVoices, AFreedHeldKeyStruckAgainSoundsAsAStrikeFromRest) {
  Synth played = prepared({fastDecaying(29, 29)}, kBlock);
  render(played, {{0.0, on(29, 110)}}, 3.0, kBlock);
  ASSERT_FALSE(played.voice(0, 29)->sounding());
  ASSERT_TRUE(played.voice(0, 29)->down);
  const Take again = render(played, {{0.0, on(29, 70)}}, 0.5, kBlock);
  Synth fresh = prepared({fastDecaying(29, 29)}, kBlock);
  const Take first = render(fresh, {{0.0, on(29, 70)}}, 0.5, kBlock);
  ASSERT_GT(peak(first), 1e-2f);
  EXPECT_LE(largestDifference(again, first), 1e-6f * peak(first));
}

}  // namespace
}  // namespace hamiltone
