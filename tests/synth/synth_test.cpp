// The synthesizer: MIDI semantics (sustain, re-strike, all notes off, bend, program, volume),
// voice allocation under the polyphony limit and its stealing order, a click-free steal, the
// master section's bounds, determinism, and independence of the block size and the thread count.
#include "synth/synth.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

#include "support/modal.h"
#include "support/synth_takes.h"
#include "support/test_instruments.h"
#include "synth/denormals.h"

namespace hamiltone {
namespace {

using testing::cc;
using testing::off;
using testing::on;
using testing::peak;
using testing::pianoKeys;
using testing::prepared;
using testing::render;
using testing::smallPlate;
using testing::Take;

constexpr double kRate = testing::kTakeRate;

// The live tail moves something only where strings take the linear tail: the piano keys
// (linear_below 5e-5 by default), and keys already at its bound of 1e-3, whose modes it drops
// under −80 dB rather than −100; not a plate, nor keys whose preset says 0 (never linear). It
// follows the instrument a program change chooses.
TEST(Synth, TakesTheLiveTailOnlyWhereAStringsTailWouldMove) {
  Instrument never = pianoKeys(60, 61), atBound = pianoKeys(60, 61);
  for (StringKey& key : never.keys) key.patch.linearBelow = 0.0;
  for (StringKey& key : atBound.keys) key.patch.linearBelow = kMaxLinearBelow;
  Synth synth = prepared({pianoKeys(60, 61), smallPlate(), never, atBound});
  EXPECT_TRUE(synth.takesLiveTail());
  for (int program : {1, 2}) {
    synth.handle({0xC0, static_cast<uint8_t>(program), 0});
    EXPECT_FALSE(synth.takesLiveTail()) << "program " << program;
  }
  synth.handle({0xC0, 3, 0});
  EXPECT_TRUE(synth.takesLiveTail());
  synth.handle({0xC0, 0, 0});
  EXPECT_TRUE(synth.takesLiveTail());
}

TEST(Synth, SustainHoldsReleasedNotesUntilThePedalLifts) {
  Synth synth = prepared({pianoKeys(48, 50)});
  render(synth, {{0.0, cc(64, 127)}, {0.0, on(48)}, {0.1, off(48)}}, 0.5, 256);
  EXPECT_TRUE(synth.voice(0, 48)->sounding());  // the pedal holds it
  EXPECT_TRUE(synth.voice(0, 48)->sustained);
  // A value under 64 is the pedal up: the damper falls and the voice frees itself.
  render(synth, {{0.0, cc(64, 63)}}, 1.5, 256);
  EXPECT_FALSE(synth.voice(0, 48)->sounding());
  // Without the pedal a note-off releases at once (the damper, T60 0.25 s: gone within 1 s).
  render(synth, {{0.0, on(49)}, {0.1, {0x90, 49, 0}}}, 1.2, 256);  // velocity 0 is a note-off
  EXPECT_FALSE(synth.voice(0, 49)->sounding());
}

// The damper scale reaches the keys released after it is set, through the pedal too: the test
// keys' damper (T60 0.25 s) frees a key within 1 s; four times as long, it still sounds then.
TEST(Synth, DamperScaleLengthensTheDecayOfReleasedKeys) {
  Synth synth = prepared({pianoKeys(48, 50)});
  synth.setDamperScale(4.0);
  render(synth, {{0.0, on(48)}, {0.1, off(48)}}, 1.1, 256);
  EXPECT_TRUE(synth.voice(0, 48)->sounding());
  render(synth, {{0.0, cc(64, 127)}, {0.0, on(49)}, {0.1, off(49)}, {0.2, cc(64, 0)}}, 1.2, 256);
  EXPECT_TRUE(synth.voice(0, 49)->sounding());
  synth.setDamperScale(1.0);
  render(synth, {{0.0, on(50)}, {0.1, off(50)}}, 1.1, 256);
  EXPECT_FALSE(synth.voice(0, 50)->sounding());
}

// The decay rate of a key, dB/s, from the RMS of two 50 ms windows of the take (seconds).
double decayDbPerS(const Take& take, double from, double to) {
  auto rms = [&](double t) {
    const size_t a = std::lround(t * kRate), b = std::lround((t + 0.05) * kRate);
    double sum = 0.0;
    for (size_t i = a; i < b; ++i) sum += double(take.left[i]) * take.left[i];
    return std::sqrt(sum / double(b - a));
  };
  return 20.0 * std::log10(rms(from) / rms(to)) / (to - from);
}

// A key released at 0.2 s under the pedal at `value` (none: no CC64 at all); `held`: never
// released. The damper T60 is 1 s (60 dB/s) so that even fully damped the key stays well above
// roundoff over the measurement; the voices never free themselves, as references. Struck softly
// (40): at 100 the string's tension modulation moves energy between its partials enough to bend
// the held key's measured decay (1.2 dB/s instead of its partials' 7 or so).
Take releasedUnderPedal(int value, bool held = false) {
  Instrument piano = pianoKeys(48, 48);
  piano.keys[0].patch.damperT60 = 1.0;
  Synth synth = prepared({piano}, 256, false);
  std::vector<TimedMessage> score;
  if (value >= 0) score.push_back({0.0, cc(64, value)});
  score.push_back({0.0, on(48, 40)});
  if (!held) score.push_back({0.2, off(48)});
  return render(synth, score, 1.0, 256);
}

// The release velocity: a key let go fast (127) damps at twice the rate of one let go at 64, a
// slow one (1) at half of it (Synth::releaseScale: T60 × 2^((64 − v)/63)); 64 and 0 (no velocity
// given) are the preset's damper to the bit. The damper's 60 dB/s dominates the key's own decay, so
// the measured rates stand within 15 % of 120, 60 and 30 dB/s plus the held key's.
TEST(Synth, ReleaseVelocitySetsHowFastTheDamperActs) {
  auto released = [](int velocity) {
    Instrument piano = pianoKeys(48, 48);
    piano.keys[0].patch.damperT60 = 1.0;
    Synth synth = prepared({piano}, 256, false);
    return render(synth, {{0.0, on(48, 40)}, {0.2, {0x80, 48, uint8_t(velocity)}}}, 1.0, 256);
  };
  const Take fast = released(127), neutral = released(64), none = released(0), slow = released(1);
  EXPECT_EQ(neutral.left, none.left);
  const double own = decayDbPerS(releasedUnderPedal(-1, true), 0.3, 0.8);
  const double rates[] = {decayDbPerS(fast, 0.3, 0.8), decayDbPerS(neutral, 0.3, 0.8),
                          decayDbPerS(slow, 0.3, 0.8)};
  const double damper[] = {60.0 * std::exp2(63.0 / 63.0), 60.0, 60.0 * std::exp2(-63.0 / 63.0)};
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(rates[i] - own, damper[i], 0.15 * damper[i]) << i;
}

// Half-pedalling: the decay rate of a released key falls monotonically with CC64 from the damped
// one (0, and the pedal's free play up to 20: bit for bit a key released without any pedal) to
// the undamped one (127, and from 100: bit for bit a key still held). In between the damper adds
// damperContact() of its 60 dB/s; the key's own decay is the same throughout, so the measured
// rate is the held key's plus that share, within 1.5 dB/s (the 50 ms windows over a 130 Hz
// string's partials, decaying at several rates, are not a pure exponential).
TEST(Synth, HalfPedalSetsTheDecayBetweenDampedAndUndamped) {
  const Take released = releasedUnderPedal(-1), held = releasedUnderPedal(-1, true);
  EXPECT_EQ(releasedUnderPedal(0).left, released.left);
  EXPECT_EQ(releasedUnderPedal(20).left, released.left);
  EXPECT_EQ(releasedUnderPedal(127).left, held.left);
  EXPECT_EQ(releasedUnderPedal(100).left, held.left);
  const double damped = decayDbPerS(released, 0.5, 0.8), free = decayDbPerS(held, 0.5, 0.8);
  EXPECT_NEAR(damped - free, 60.0, 3.0);
  double previous = INFINITY;
  for (int value : {0, 32, 64, 96, 127}) {
    const double rate = decayDbPerS(releasedUnderPedal(value), 0.5, 0.8);
    std::printf("CC64 %3d: contact %.3f, decay %.1f dB/s\n", value, Synth::damperContact(value),
                rate);
    EXPECT_LT(rate, previous) << "CC64 " << value;
    EXPECT_NEAR(rate, free + Synth::damperContact(value) * (damped - free), 1.5) << value;
    previous = rate;
  }
  const double half = decayDbPerS(releasedUnderPedal(64), 0.5, 0.8);
  EXPECT_GT(half, free + 10.0);
  EXPECT_LT(half, damped - 10.0);
}

// The pedal moved while a released key rings changes its decay from that moment: lifted fully
// (127) it holds, half down (64) it decays at the half pedal's rate, down (0) at the damper's. The
// loss changes between two steps, so the signal has no step: no sample-to-sample jump after the
// changes larger than the key's own largest before them.
TEST(Synth, MovingThePedalWhileAKeyRingsChangesItsDecayWithoutAClick) {
  Instrument piano = pianoKeys(48, 48);
  piano.keys[0].patch.damperT60 = 1.0;
  Synth synth = prepared({piano}, 256, false);
  const Take take = render(
      synth,
      {{0.0, cc(64, 127)}, {0.0, on(48)}, {0.1, off(48)}, {0.6, cc(64, 64)}, {1.0, cc(64, 0)}}, 1.4,
      256);
  const double sustained = decayDbPerS(take, 0.3, 0.5), half = decayDbPerS(take, 0.7, 0.9),
               damped = decayDbPerS(take, 1.1, 1.3);
  EXPECT_LT(sustained, half - 10.0);
  EXPECT_LT(half, damped - 10.0);
  float before = 0.0f, after = 0.0f;
  for (size_t i = 12000; i < take.left.size(); ++i) {  // from 0.25 s; the change at 0.6 s
    float& largest = i < 28800 ? before : after;
    largest = std::max(largest, std::abs(take.left[i] - take.left[i - 1]));
  }
  EXPECT_LE(after, before);
}

// Sostenuto (CC66): 48, held as the pedal goes down, rings on after its release (its own T60 of
// 8 s: after 0.5 s within a few dB of its peak); 52, struck after, is damped at its release (T60
// 0.25 s: 120 dB down in 0.5 s). Lifting the pedal damps 48 too. Levels from the keys' rendered
// output (KeyVoice::level).
TEST(Synth, SostenutoHoldsOnlyTheKeysHeldAsItGoesDown) {
  Synth synth = prepared({pianoKeys(48, 52)}, 256, false);
  render(synth, {{0.0, on(48)}, {0.1, cc(66, 127)}, {0.2, on(52)}, {0.3, off(48)}, {0.3, off(52)}},
         0.8, 256);
  EXPECT_GT(synth.voice(0, 48)->level(), 0.3);
  EXPECT_LT(synth.voice(0, 52)->level(), 1e-3);
  EXPECT_TRUE(synth.voice(0, 48)->caught);
  // A key struck and released under the sustain pedal meanwhile is the sustain pedal's alone.
  render(synth, {{0.0, cc(64, 127)}, {0.0, on(50)}, {0.1, off(50)}, {0.2, cc(64, 0)}}, 0.8, 256);
  EXPECT_GT(synth.voice(0, 48)->level(), 0.2);
  EXPECT_LT(synth.voice(0, 50)->level(), 1e-3);
  render(synth, {{0.0, cc(66, 0)}}, 0.5, 256);
  EXPECT_FALSE(synth.voice(0, 48)->caught);
  EXPECT_LT(synth.voice(0, 48)->level(), 1e-3);
  // Reset controllers lifts it too.
  render(synth, {{0.0, on(49)}, {0.05, cc(66, 127)}, {0.1, cc(121, 0)}, {0.15, off(49)}}, 0.7, 256);
  EXPECT_LT(synth.voice(0, 49)->level(), 1e-3);
}

// Una corda (CC67): a three-string key struck with the soft pedal down strikes two of its strings
// — the energy of two hammers' shares of three, so its level is about 20·log10(2/3) = −3.5 dB
// (its amplitude, two strings of the same amplitude instead of three), within 1 dB (the strings'
// cent of detuning beat differently); it stays on pitch. A key of one string is struck as ever, bit
// for bit; the pedal up, three strings again.
TEST(Synth, UnaCordaStrikesTwoStringsOfThree) {
  Instrument piano = pianoKeys(57, 57);
  piano.keys[0].unisons = 3;
  piano.keys[0].detuneCents = 2.0;  // the strings at −1, 0 and +1 cent
  piano.gainDb = -20.0;             // well under the master's limiter (0.98)
  auto take = [&](bool soft) {
    Synth synth = prepared({piano}, 256, false);
    std::vector<TimedMessage> score;
    if (soft) score.push_back({0.0, cc(67, 127)});
    score.push_back({0.0, on(57, 40)});
    return render(synth, score, 1.0, 256);
  };
  const Take full = take(false), soft = take(true);
  auto rms = [](const Take& t) {
    double sum = 0.0;
    for (size_t i = 2400; i < 12000; ++i) sum += double(t.left[i]) * t.left[i];
    return std::sqrt(sum / 9600.0);
  };
  const double db = 20.0 * std::log10(rms(soft) / rms(full));
  std::printf("una corda: %.2f dB\n", db);
  EXPECT_NEAR(db, 20.0 * std::log10(2.0 / 3.0), 1.0);
  // On pitch: the three strings' mean is the note (the test string itself sounds about half a
  // cent sharp of 220 Hz: its stiffness); the two struck are its middle and highest, 0 and +1
  // cent, so the soft note is sharp of the full one by their mean, 0.5 cent (± 0.2: the
  // zero-crossing count over 0.5 s).
  auto cents = [](const Take& t) {
    std::vector<double> x(t.left.begin() + 24000, t.left.end());
    return testing::cents(testing::zeroCrossingFrequency(x, 1.0 / kRate), 220.0);
  };
  std::printf("three strings %+.2f cents, una corda %+.2f cents\n", cents(full), cents(soft));
  EXPECT_NEAR(cents(full), 0.0, 1.0);
  EXPECT_NEAR(cents(soft) - cents(full), 0.5, 0.2);
  // One string: the pedal changes nothing.
  Instrument one = pianoKeys(57, 57);
  Synth a = prepared({one}, 256, false), b = prepared({one}, 256, false);
  EXPECT_EQ(render(a, {{0.0, on(57)}}, 0.2, 256).left,
            render(b, {{0.0, cc(67, 127)}, {0.0, on(57)}}, 0.2, 256).left);
}

TEST(Synth, RestrikingASoundingKeyReexcitesTheSameVoice) {
  Synth synth = prepared({pianoKeys(48, 48)});
  render(synth, {{0.0, on(48, 60)}}, 0.2, 64);
  const long first = synth.voice(0, 48)->order();
  const Take take = render(synth, {{0.0, on(48, 120)}}, 0.2, 64);
  EXPECT_EQ(synth.activeVoices(), 1);
  EXPECT_GT(synth.voice(0, 48)->order(), first);
  EXPECT_GT(peak(take.left), 0.0f);
}

TEST(Synth, AllNotesOffReleasesHeldKeysAndAllSoundOffSilences) {
  Synth synth = prepared({pianoKeys(48, 52)});
  render(synth, {{0.0, on(48)}, {0.0, on(50)}, {0.0, on(52)}}, 0.2, 256);
  EXPECT_EQ(synth.activeVoices(), 3);
  render(synth, {{0.0, cc(123, 0)}}, 1.2, 256);
  EXPECT_EQ(synth.activeVoices(), 0);

  const Take before = render(synth, {{0.0, on(48)}, {0.0, on(50)}}, 0.2, 256);
  const Take take = render(synth, {{0.0, cc(120, 0)}}, 0.3, 256);
  EXPECT_EQ(synth.activeVoices(), 0);
  // After the 5 ms fade only the master's 5 Hz DC blocker still rings, decaying with its 32 ms
  // time constant: 1e-3 of the level before, a quarter second on.
  EXPECT_LT(peak(take.left, 12000), 1e-3f * peak(before.left));
}

// At the limit the key furthest below its own peak goes, held or not: 48, held, decays fast
// (T60 1 s) and after a second is further below its peak (about −60 dB) than 50, released 0.15 s
// ago (damper 0.25 s: about −26 dB); then 50 goes before 52, held and struck 0.1 s ago. Each
// steal is counted with the stolen key's level.
TEST(Synth, PolyphonyLimitStealsTheKeyFurthestBelowItsPeak) {
  Instrument piano = pianoKeys(48, 60, 3);
  piano.keys[0].patch.t60Low = piano.keys[0].patch.t60High = 1.0;
  Synth synth = prepared({piano});
  render(synth, {{0.0, on(48, 127)}, {0.8, on(50, 127)}, {0.85, off(50)}, {0.9, on(52, 127)}}, 1.0,
         64);
  ASSERT_EQ(synth.activeVoices(), 3);
  const double held = synth.voice(0, 48)->level(), released = synth.voice(0, 50)->level();
  ASSERT_LT(held, released);
  ASSERT_LT(released, synth.voice(0, 52)->level());
  render(synth, {{0.0, on(55)}}, 0.02, 64);
  EXPECT_FALSE(synth.voice(0, 48)->sounding());
  EXPECT_TRUE(synth.voice(0, 50)->sounding());
  EXPECT_EQ(synth.activeVoices(), 3);
  render(synth, {{0.0, on(57)}}, 0.02, 64);
  EXPECT_FALSE(synth.voice(0, 50)->sounding());
  EXPECT_TRUE(synth.voice(0, 52)->sounding());
  EXPECT_EQ(synth.steals(), 2);
  // The louder of the two: 50, 20 ms further into its damping than when measured.
  EXPECT_LT(synth.loudestSteal(), released);
  EXPECT_GT(synth.loudestSteal(), held);
  // The CLI's --voices overrides the preset's polyphony.
  synth.setPolyphony(1);
  render(synth, {{0.0, on(59)}}, 0.02, 64);
  EXPECT_EQ(synth.activeVoices(), 1);
}

// The stolen voice fades linearly over 5 ms: no sample-to-sample step larger than the note's own
// largest step plus its peak / 240 (the fade's slope per sample at 48 kHz).
TEST(Synth, StealingDoesNotClick) {
  Synth synth = prepared({pianoKeys(48, 60, 1)});
  Take take = render(synth, {{0.0, on(60, 127)}, {0.3, on(48, 1)}}, 0.35, 64);
  const size_t steal = std::lround(0.3 * kRate);
  float before = 0.0f, during = 0.0f;
  for (size_t i = steal - 4800; i < steal; ++i)
    before = std::max(before, std::abs(take.left[i] - take.left[i - 1]));
  for (size_t i = steal; i < steal + 480; ++i)
    during = std::max(during, std::abs(take.left[i] - take.left[i - 1]));
  const float level = peak(take.left, steal - 4800, steal);
  ASSERT_GT(level, 1e-3f);
  EXPECT_LE(during, before + level / 240.0f + 1e-6f);
  EXPECT_EQ(synth.activeVoices(), 1);
}

TEST(Synth, OutputIsBitIdenticalForTheSameInput) {
  const std::vector<TimedMessage> score = {
      {0.0, on(48)}, {0.05, on(52, 30)}, {0.1, cc(64, 127)}, {0.15, off(48)}, {0.2, {0xE0, 0, 80}}};
  Synth a = prepared({pianoKeys(48, 55)}), b = prepared({pianoKeys(48, 55)});
  const Take x = render(a, score, 0.4, 64), y = render(b, score, 0.4, 64);
  EXPECT_EQ(x.left, y.left);
  EXPECT_EQ(x.right, y.right);
}

bool sameBits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

// Each key renders into its own buffer and the buffers are summed in (instrument, note) order,
// so which thread rendered which key cannot show in the output: 2, 3 and 4 threads (more than
// this machine's cores) give the bits of 1. The score has everything that changes a key's state
// between two blocks or inside one: a chord, restrikes, the pedal, steals (polyphony 4 of 7
// keys), a bend, a program change to a plate and back, all sound off and a strike in its fade.
TEST(Synth, OutputIsBitIdenticalWhateverTheThreadCount) {
  const std::vector<TimedMessage> score = {
      {0.0, on(48)},       {0.0, on(52, 60)},     {0.0, on(55, 90)},    {0.01, cc(64, 127)},
      {0.02, on(58, 110)}, {0.03, off(48)},       {0.04, on(60, 40)},   {0.05, on(48, 127)},
      {0.06, on(53, 70)},  {0.07, {0xE0, 0, 90}}, {0.08, {0xC0, 1, 0}}, {0.08, on(60, 127)},
      {0.09, on(61, 100)}, {0.1, {0xC0, 0, 0}},   {0.1, on(52, 100)},   {0.11, cc(64, 0)},
      {0.12, cc(120, 0)},  {0.122, on(55, 80)},   {0.13, off(55)},      {0.14, on(57, 127)}};
  std::vector<Take> takes;
  for (int threads : {1, 2, 3, 4}) {
    Synth synth = prepared({pianoKeys(48, 60, 4), smallPlate()}, 100, true, threads);
    EXPECT_EQ(synth.threads(), threads);
    takes.push_back(render(synth, score, 0.3, 100));
  }
  ASSERT_GT(peak(takes[0].left), 1e-3f);
  for (size_t t = 1; t < takes.size(); ++t) {
    EXPECT_TRUE(sameBits(takes[t].left, takes[0].left)) << t + 1 << " threads";
    EXPECT_TRUE(sameBits(takes[t].right, takes[0].right)) << t + 1 << " threads";
  }
}

// Blocks of 1, 64 and 1000 frames: events land on the same samples, every voice runs sample by
// sample, stealing follows a per-sample loudness and voices free themselves sample by sample, so
// the takes agree to float roundoff. The score steals (polyphony 2), releases, re-strikes a
// fading key and lets released keys fall silent and free themselves.
TEST(Synth, OutputDoesNotDependOnTheBlockSize) {
  const std::vector<TimedMessage> score = {
      {0.0, on(48)},  {0.0123, on(52, 30)}, {0.05, off(48)}, {0.07, {0xE0, 0, 90}},
      {0.09, on(55)}, {0.0905, on(48, 70)}, {0.12, off(52)}, {0.15, off(55)},
      {0.2, off(48)}, {0.25, on(50, 127)},  {0.26, off(50)}};
  std::vector<Take> takes;
  for (int block : {1, 64, 1000}) {
    Instrument piano = pianoKeys(48, 55, 2);
    for (StringKey& key : piano.keys) key.patch.damperT60 = 0.05;  // they free within the take
    Synth synth = prepared({piano}, 1000);
    takes.push_back(render(synth, score, 1.2, block));
    EXPECT_EQ(synth.activeVoices(), 0) << "block " << block;
  }
  const float level = peak(takes[0].left);
  ASSERT_GT(level, 1e-3f);
  for (size_t t = 1; t < takes.size(); ++t)
    for (size_t i = 0; i < takes[0].left.size(); ++i) {
      ASSERT_NEAR(takes[t].left[i], takes[0].left[i], 1e-6f * level)
          << "block take " << t << " at " << i;
      ASSERT_NEAR(takes[t].right[i], takes[0].right[i], 1e-6f * level);
    }
}

// The edge cases of a key's state: a note-on and note-off inside a steal's fade, a key stolen in
// the last milliseconds of its own release, CC120 then the same key again, a program change
// between a note-on and its note-off, and the sustain pedal over a re-strike.
TEST(Synth, KeysNeverGetStuckOrDead) {
  Instrument piano = pianoKeys(48, 52, 1);
  Synth synth = prepared({piano, pianoKeys(48, 52, 4)});
  // Polyphony 1: 50 steals 48; 48 again within the 5 ms fade, released within it too.
  render(synth, {{0.0, on(48)}, {0.1, on(50)}, {0.101, on(48)}, {0.102, off(48)}}, 0.15, 64);
  render(synth, {}, 1.0, 64);
  EXPECT_FALSE(synth.voice(0, 48)->down);
  EXPECT_LE(synth.activeVoices(), 1);
  // CC120 with a voice about to free itself, then the key again: it sounds.
  render(synth, {{0.0, cc(120, 0)}}, 0.05, 64);
  Take take = render(synth, {{0.0, on(48, 127)}}, 0.2, 64);
  EXPECT_TRUE(synth.voice(0, 48)->sounding());
  EXPECT_GT(peak(take.left), 1e-2f);
  // Program change between note-on and note-off: the note-off reaches the key that was struck;
  // the same key struck in the new program lets the old one go.
  render(synth, {{0.0, {0xC0, 1, 0}}, {0.0, on(50)}, {0.01, {0xC0, 0, 0}}, {0.02, off(50)}}, 0.05,
         64);
  EXPECT_FALSE(synth.voice(1, 50)->down);
  render(synth, {{0.0, on(52)}, {0.01, {0xC0, 1, 0}}, {0.02, on(52)}}, 0.05, 64);
  EXPECT_FALSE(synth.voice(0, 52)->down);
  EXPECT_TRUE(synth.voice(1, 52)->down);
  // Sustain over a re-strike: the key is held again, then sustained, then released by the pedal.
  render(synth, {{0.0, cc(64, 127)}, {0.0, on(51)}, {0.01, off(51)}, {0.02, on(51)}}, 0.05, 64);
  EXPECT_TRUE(synth.voice(1, 51)->down);
  EXPECT_FALSE(synth.voice(1, 51)->sustained);
  render(synth, {{0.0, off(51)}}, 0.01, 64);
  EXPECT_TRUE(synth.voice(1, 51)->sustained);
  render(synth, {{0.0, cc(64, 0)}}, 1.0, 64);
  EXPECT_FALSE(synth.voice(1, 51)->sounding());
}

// A chord struck at once never steals its own notes: a key just struck counts as loud.
TEST(Synth, AChordDoesNotStealItself) {
  Synth synth = prepared({pianoKeys(48, 60, 2)});
  render(synth, {{0.0, on(48, 127)}}, 0.5, 64);
  render(synth, {{0.0, on(52, 40)}, {0.0, on(55, 40)}}, 0.05, 64);
  EXPECT_TRUE(synth.voice(0, 52)->sounding());
  EXPECT_TRUE(synth.voice(0, 55)->sounding());
  EXPECT_FALSE(synth.voice(0, 48)->sounding() && !synth.voice(0, 48)->fading());
}

// A note-on at offset 37 of a block starts exactly there: the output before it is silent.
TEST(Synth, EventsApplyAtTheirSampleOffset) {
  Synth synth = prepared({pianoKeys(60, 60)});
  std::vector<float> l(256), r(256);
  const SynthEvent events[] = {{37, on(60, 127)}};
  synth.process(l, r, events);
  EXPECT_EQ(peak(l, 0, 37), 0.0f);
  EXPECT_GT(peak(l, 37, 256), 0.0f);
}

// The wheel retunes the string: at full bend up the fundamental is the range higher, within a
// cent (measured from the output's zero crossings) — the largest range, 12 semitones, too: a stiff
// string needs a little over 4× its tension for the octave up (4 + 3B), which the range allows.
// Struck softly: an octave down the string is at a quarter of its tension, so the same strike
// stretches it 16 times as much relative to it: its tension modulation held it sharp over
// 0.5–1 s by 12.7 cents at velocity 40 and 1.5 at velocity 5 (physics, not the wheel); two
// semitones down (0.79 of its tension) velocity 40 held it 1.03 cents sharp once the felt's
// contact was spread over the grid as the felt presses (HammeredString), velocity 20 held it
// 0.35 cent (the glide goes about as the strike's energy).
TEST(Synth, PitchBendMovesTheFundamentalByTheRange) {
  for (double range : {2.0, 12.0}) {
    for (int wheel : {16383, 0}) {
      Instrument a3 = pianoKeys(57, 57);
      a3.bendRange = range;
      Synth synth = prepared({a3});
      const double expected = 220.0 * std::pow(2.0, (wheel ? range : -range) / 12.0);
      MidiMessage bend{0xE0, uint8_t(wheel & 0x7F), uint8_t(wheel >> 7)};
      const Take take = render(synth, {{0.0, bend}, {0.0, on(57, range > 2.0 ? 1 : 20)}}, 1.0, 256);
      std::vector<double> x(take.left.begin() + 24000, take.left.end());
      const double measured = testing::zeroCrossingFrequency(x, 1.0 / kRate);
      EXPECT_NEAR(testing::cents(measured, expected), 0.0, 1.0)
          << "range " << range << ", wheel " << wheel;
    }
  }
}

TEST(Synth, ProgramChangeSelectsAnInstrumentAndIgnoresOthers) {
  Synth synth = prepared({pianoKeys(48, 50), pianoKeys(60, 62)});
  render(synth, {{0.0, {0xC0, 1, 0}}, {0.0, on(60)}, {0.01, {0xC0, 9, 0}}}, 0.05, 64);
  EXPECT_EQ(synth.program(), 1);
  EXPECT_TRUE(synth.voice(1, 60)->sounding());
  EXPECT_EQ(synth.voice(0, 60), nullptr);
  EXPECT_EQ(synth.ignoredPrograms(0), std::uint64_t{1} << 9);  // for the player to say so
  EXPECT_EQ(synth.ignoredPrograms(1), 0u);
}

// The limiter: four loud keys with +24 dB of gain stay inside the ceiling; CC7 = 0 silences.
TEST(Synth, MasterNeverLeavesTheUnitRange) {
  Instrument loud = pianoKeys(48, 60);
  loud.gainDb = 24.0;
  Synth synth = prepared({loud});
  const Take take = render(
      synth, {{0.0, on(48, 127)}, {0.0, on(52, 127)}, {0.0, on(55, 127)}, {0.0, on(60, 127)}}, 0.3,
      256);
  EXPECT_GT(peak(take.left), 0.9f);
  EXPECT_LE(peak(take.left), MasterBus::kCeiling + 1e-6);
  EXPECT_LE(peak(take.right), MasterBus::kCeiling + 1e-6);
  const Take muted = render(synth, {{0.0, cc(7, 0)}}, 0.3, 256);
  EXPECT_LT(peak(muted.left, 9600), 1e-3f);  // 10 ms smoothing: −87 dB after 0.2 s
}

TEST(Synth, FlushToZeroIsOnWhileProcessingAndRestoredAfter) {
  const bool outside = ScopedFlushToZero::active();
  {
    const ScopedFlushToZero ftz;
    EXPECT_TRUE(ScopedFlushToZero::active());
    volatile double tiny = 1e-310;  // subnormal
    EXPECT_EQ(tiny * 0.5, 0.0);
  }
  EXPECT_EQ(ScopedFlushToZero::active(), outside);
}

TEST(Synth, RejectsBadSetups) {
  Synth synth;
  Instrument silent = pianoKeys(60, 60, 0);
  EXPECT_THROW(synth.prepare({silent}, {.sampleRate = kRate, .maxBlock = 64, .notes = {}}),
               std::invalid_argument);
  EXPECT_THROW(synth.prepare({}, {}), std::invalid_argument);
  EXPECT_THROW(
      synth.prepare({pianoKeys(60, 60)}, {.sampleRate = kRate, .maxBlock = 0, .notes = {}}),
      std::invalid_argument);
  for (int threads : {-1, Synth::kMaxThreads + 1})
    EXPECT_THROW(
        synth.prepare({pianoKeys(60, 60)},
                      {.sampleRate = kRate, .maxBlock = 64, .notes = {}, .threads = threads}),
        std::invalid_argument);
  Instrument broken = pianoKeys(60, 60);
  broken.keys[0].patch.oversampling = 3;
  try {
    synth.prepare({broken}, {});
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(),
                 "pianoKeys(60, 60): note 60: oversampling = 3: must be 1, 2, 4, 8, 16, 32 or 64");
  }
}

}  // namespace
}  // namespace hamiltone
