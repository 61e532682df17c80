// The plugin's audio-thread part without a host: velocity curves, MIDI bytes on their frames (more
// than fit one piece, past the block, sysex skipped), and the swap to a new synthesizer between
// blocks — the old one faded out in 10 ms, nothing lost or doubled.
#include "playing_synth.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <thread>
#include <vector>

namespace hamiltone::plugin {
namespace {

// A MIDI event as DPF hands it over: frame, size, bytes.
struct Midi {
  uint32_t frame, size;
  uint8_t data[4];
};

constexpr double kRate = 48000.0;

struct Block {
  std::vector<float> left, right;
  explicit Block(size_t frames) : left(frames), right(frames) {}
  float peak(size_t from = 0, size_t to = SIZE_MAX) const {
    to = std::min(to, left.size());
    float p = 0.0f;
    for (const std::vector<float>* channel : {&left, &right})
      for (float x : std::span(*channel).subspan(from, to - from)) p = std::max(p, std::abs(x));
    return p;
  }
};

Block play(PlayingSynth& playing, size_t frames, const std::vector<Midi>& midi = {}) {
  Block b(frames);
  playing.process(std::span(b.left), std::span(b.right), std::span<const Midi>(midi));
  return b;
}

TEST(CurvedVelocity, BendsTheVelocityAndNeverMakesANoteOff) {
  EXPECT_EQ(curvedVelocity(64, 1.0), 64);
  EXPECT_EQ(curvedVelocity(127, 2.0), 127);
  EXPECT_EQ(curvedVelocity(64, 2.0), 32);  // 127 (64/127)² = 32.25
  EXPECT_EQ(curvedVelocity(64, 0.5), 90);  // 127 (64/127)^½ = 90.15
  EXPECT_EQ(curvedVelocity(1, 4.0), 1);    // 0 would be a note-off
}

class PlayingSynthTest : public ::testing::Test {
 protected:
  void SetUp() override {
    loader_.start(kRate);
    playing_.prepare(kRate);
  }
  void TearDown() override {
    playing_.release();
    loader_.stop();
  }
  SynthLoader loader_;
  PlayingSynth playing_{loader_};
};

TEST_F(PlayingSynthTest, EveryMessageIsPlayedEvenMoreThanAPieceHolds) {
  // kMaxEvents + 100 volume messages before a note-on at the last frame of the block: the note is
  // heard in the next block. A note-on whose frame is past the block plays at its last frame.
  std::vector<Midi> midi;
  for (int i = 0; i < PlayingSynth::kMaxEvents + 100; ++i)
    midi.push_back({static_cast<uint32_t>(i), 3, {0xB0, 7, 127}});
  midi.push_back({1023, 6, {0xF0, 0x7E, 0x7F, 0x06}});  // sysex: skipped
  midi.push_back({1023, 3, {0x90, 69, 100}});
  midi.push_back({5000, 3, {0x90, 72, 100}});
  play(playing_, 1024, midi);
  const Block next = play(playing_, 4800);
  EXPECT_GT(next.peak(), 0.01f);
  ASSERT_TRUE(playing_.playing());
  EXPECT_EQ(playing_.playing()->bundled, 0);
}

TEST_F(PlayingSynthTest, ASwapFadesTheOldSynthesizerOutAndPlaysTheNew) {
  play(playing_, 256, {{0, 3, {0x90, 69, 110}}});  // A4 on the piano
  const Block sounding = play(playing_, 4800);
  ASSERT_GT(sounding.peak(), 0.05f);
  loader_.setBundled(1);  // the paper's string: no A4
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (loader_.status() == LoadStatus::loading && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ASSERT_EQ(loader_.status(), LoadStatus::ready);
  // The swap at the start of this block: the piano fades (all sound off, 5 ms) and is gone after
  // the 10 ms it is heard; no step bigger than the playing note's own.
  const Block swap = play(playing_, 960);
  EXPECT_EQ(playing_.playing()->bundled, 1);
  EXPECT_GT(swap.peak(0, 48), 0.01f);
  EXPECT_LT(swap.peak(480), 1e-6f);
  float step = 0.0f;
  for (size_t i = 1; i < swap.left.size(); ++i)
    step = std::max(step, std::abs(swap.left[i] - swap.left[i - 1]));
  EXPECT_LT(step, 0.1f);
  // The new one plays its own notes.
  play(playing_, 256, {{0, 3, {0x90, 48, 100}}});
  EXPECT_GT(play(playing_, 4800).peak(), 0.01f);
}

TEST_F(PlayingSynthTest, GainFollowsItsControlSmoothly) {
  playing_.setControls({});  // as the plugin's run() does before every block
  play(playing_, 256, {{0, 3, {0x90, 69, 110}}});
  const float before = play(playing_, 4800).peak();
  playing_.setControls({.gainDb = -60.0});
  const Block fading = play(playing_, 4800);
  // A one-pole of 10 ms: after 5 ms the level is still above half (e^−½ = 0.61, less the note's
  // own decay); after 90 ms it is at the target's −60 dB (e^−9 = 1.2e−4 of the way left).
  EXPECT_GT(fading.peak(0, 240), 0.5f * before);
  EXPECT_LT(fading.peak(4320), 2e-3f * before);
}

// A session's gain is the first control a fresh activation is given (in LV2, with the first
// block): it holds from the first sample, not faded in from 0 dB over 10 ms — a note at the
// session's start peaked as loud at −60 dB as at 0 dB (hostile test).
TEST_F(PlayingSynthTest, TheFirstGainAfterPrepareHoldsFromTheFirstSample) {
  playing_.setControls({.gainDb = -60.0});
  const float quiet = play(playing_, 4800, {{0, 3, {0x90, 69, 110}}}).peak(0, 480);
  playing_.release();
  playing_.prepare(kRate);
  loader_.start(kRate);
  playing_.setControls({});
  const float full = play(playing_, 4800, {{0, 3, {0x90, 69, 110}}}).peak(0, 480);
  ASSERT_GT(full, 0.01f);
  EXPECT_LT(quiet, 2e-3f * full);  // −60 dB is 1e-3
}

// Until the loader is no longer loading, within 30 s.
void awaitLoader(const SynthLoader& loader) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (loader.status() == LoadStatus::loading && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
}

// A swap to another synthesizer (a new preset) keeps the pedal and the volume the player left:
// with the sustain pedal down and CC7 at 30 before the swap, a key struck in the swap's own block
// and released rings on at the volume asked for — not from full volume, as a fresh synthesizer's
// smoothing would start it. (Both were lost: a swap forgot them. Sostenuto, the soft pedal and
// the bend are handed over the same way, PlayingSynth::remember, and not measured here.)
TEST_F(PlayingSynthTest, ASwapKeepsThePedalAndTheVolume) {
  // The reference: the same controllers sent to the new synthesizer itself.
  loader_.setBundled(6);
  awaitLoader(loader_);
  play(playing_, 4800);  // the swap, and its fade
  play(playing_, 256, {{0, 3, {0xB0, 64, 127}}, {1, 3, {0xB0, 7, 30}}});
  play(playing_, 4800);  // the volume's 10 ms smoothing, as after the swap below
  const std::vector<Midi> strike = {{0, 3, {0x90, 60, 100}}, {2400, 3, {0x80, 60, 0}}};
  const Block reference = play(playing_, 9600, strike);
  const float referenceTail = reference.peak(7200);

  // Now the controllers before a swap.
  playing_.release();
  loader_.stop();
  loader_.setBundled(0);
  loader_.start(kRate);
  playing_.prepare(kRate);
  play(playing_, 256, {{0, 3, {0xB0, 64, 127}}, {1, 3, {0xB0, 7, 30}}});
  loader_.setBundled(6);
  awaitLoader(loader_);
  const Block swapped = play(playing_, 9600, strike);  // adopted at this block's start
  ASSERT_GT(referenceTail, 1e-4f);                     // the pedal holds the released key
  // The volume: (30/127)² of the peak at full volume, where the swap once played it.
  EXPECT_NEAR(swapped.peak(), reference.peak(), 0.02f * reference.peak());
  EXPECT_NEAR(swapped.peak(7200), referenceTail, 0.02f * referenceTail);
}

// The Light tails switch reaches the synthesizer playing, and the next one a swap adopts; off
// again, both are off. A host's value is the control's (Synth::setLiveTail).
TEST_F(PlayingSynthTest, LightTailsReachTheSynthesizerAndSurviveASwap) {
  play(playing_, 256);
  ASSERT_NE(playing_.synth(), nullptr);
  EXPECT_FALSE(playing_.synth()->liveTail());
  playing_.setControls({.lightTails = true});
  play(playing_, 256);
  EXPECT_TRUE(playing_.synth()->liveTail());
  EXPECT_TRUE(playing_.synth()->takesLiveTail());  // the grand piano's strings
  loader_.setBundled(6);
  awaitLoader(loader_);
  play(playing_, 4800);  // the swap, and its fade
  EXPECT_EQ(playing_.playing()->bundled, 6);
  EXPECT_TRUE(playing_.synth()->liveTail());
  playing_.setControls({});
  play(playing_, 256);
  EXPECT_FALSE(playing_.synth()->liveTail());
}

// A host's sample rate of NaN or ±inf builds no synthesizer; the output is silence, not NaN (it
// was NaN for good: the gain's smoothing took the rate).
TEST(PlayingSynth, ARateNoSynthesizerBuildsAtGivesSilence) {
  for (const double rate : {std::numeric_limits<double>::quiet_NaN(),
                            std::numeric_limits<double>::infinity(), -48000.0}) {
    SynthLoader loader;
    loader.start(rate);
    EXPECT_EQ(loader.status(), LoadStatus::failed) << rate;
    PlayingSynth playing(loader);
    playing.prepare(rate);
    playing.setControls({});
    const Block b = play(playing, 256, {{0, 3, {0x90, 60, 100}}});
    for (const float x : b.left) ASSERT_EQ(x, 0.0f) << rate;
    loader.stop();
  }
}

// A host may send any float: a gain of +1000 dB made the output infinite and, once the smoothing
// met inf − inf, NaN for good (hostile test in jalv). Every control is held in its declared range
// and NaN is its default: +1000 dB plays as +12 dB, and the gain comes back when set back.
TEST_F(PlayingSynthTest, ControlsOutsideTheirRangesAreHeldInside) {
  play(playing_, 256, {{0, 3, {0x90, 69, 110}}});
  const float before = play(playing_, 4800).peak();
  const double inf = std::numeric_limits<double>::infinity();
  for (const double wild : {1000.0, 1e30, inf, -inf, std::numeric_limits<double>::quiet_NaN()}) {
    playing_.setControls(
        {.gainDb = wild, .velocityCurve = wild, .damperScale = wild, .polyphony = 1 << 30});
    const Block loud = play(playing_, 4800);
    for (const float x : loud.left) ASSERT_TRUE(std::isfinite(x)) << wild;
    // +12 dB at most (4×), and the master's limiter sits before the gain.
    EXPECT_LE(loud.peak(), 4.0f) << wild;
  }
  playing_.setControls({});
  play(playing_, 4800);
  const Block back = play(playing_, 4800);
  for (const float x : back.left) ASSERT_TRUE(std::isfinite(x));
  EXPECT_GT(back.peak(), 0.05f * before);
  EXPECT_LT(back.peak(), 1.0f);
}

}  // namespace
}  // namespace hamiltone::plugin
