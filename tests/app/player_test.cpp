// The audio callback's work: clean output over the sample-rate × block-size grid, MIDI placed on
// the sample its arrival time gives, the recording tee (exact, whole blocks or none) and the
// overload protection's voice limit. Allocation is checked in tests/schemes/no_allocation_test.cpp
// and real-time safety under RealtimeSanitizer in tests/rtsan/.
#include "player.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "support/player_performance.h"
#include "support/test_instruments.h"

namespace hamiltone::app {
namespace {

using testing::nanoseconds;
using testing::pianoKeys;

constexpr double kRate = 48000.0;
constexpr std::int64_t kNow = 1'000'000'000;  // the simulated clock's "now", 1 s

Synth prepared(std::vector<Instrument> instruments, double rate = kRate, int threads = 0) {
  Synth synth;
  synth.prepare(std::move(instruments),
                {.sampleRate = rate, .maxBlock = 1024, .notes = {}, .threads = threads});
  return synth;
}

// `samples` sample periods before kNow, rounded to the nanosecond.
std::int64_t before(double samples) { return kNow - nanoseconds(samples / kRate); }

// The left channel of interleaved stereo.
std::vector<float> left(const std::vector<float>& interleaved) {
  std::vector<float> l(interleaved.size() / 2);
  for (size_t i = 0; i < l.size(); ++i) l[i] = interleaved[2 * i];
  return l;
}

long onset(const std::vector<float>& x) {
  const auto it = std::find_if(x.begin(), x.end(), [](float v) { return v != 0.0f; });
  return it == x.end() ? -1 : static_cast<long>(it - x.begin());
}

// --- The grid: 0.3 s of the performance at every rate and block size -----------------------------

class PlayerGrid : public ::testing::TestWithParam<double> {};

TEST_P(PlayerGrid, OutputIsFiniteNormalAndWithinTheUnitRange) {
  const double rate = GetParam();
  Synth synth;
  synth.prepare(testing::performanceInstruments(HAMILTONE_SOURCE_DIR),
                testing::performanceSetup(rate));
  for (int frames : {1, 64, 256, 1024}) {
    SCOPED_TRACE(::testing::Message() << frames << " frames");
    synth.setPolyphony(0);  // undo what an earlier run's overload protection lowered
    SpscQueue<StampedMessage> midi(256);
    Player player(synth, midi, nullptr, rate, frames);
    std::vector<float> interleaved(2 * static_cast<size_t>(frames));
    testing::SampleFaults faults;
    float peak = 0.0f;
    testing::playPerformance(player, midi, rate, frames, interleaved,
                             [&](std::span<const float> block) {
                               faults.check(block);
                               for (float x : block) peak = std::max(peak, std::abs(x));
                             });
    EXPECT_EQ(faults.nonFinite, 0);
    EXPECT_EQ(faults.subnormal, 0);
    EXPECT_EQ(faults.outOfRange, 0);
    EXPECT_EQ(synth.nonFiniteSamples(), 0);  // none replaced by the master either
    EXPECT_GT(peak, 0.01f);                  // and the performance was heard
  }
}

INSTANTIATE_TEST_SUITE_P(Rates, PlayerGrid, ::testing::Values(44100.0, 48000.0, 96000.0),
                         [](const auto& rate) { return std::to_string(int(rate.param)); });

// --- MIDI placement ------------------------------------------------------------------------------

// A message that arrived d before now lands at frames − d·rate, clamped to the block: too old for
// this block → its first sample; stamped after now (a clock step) → its last.
TEST(Player, NoteLandsWhereItsArrivalTimePutsIt) {
  constexpr int kFrames = 256;
  const MidiMessage note{0x90, 60, 100};
  // The voice's own delay from the strike to its first nonzero sample.
  Synth reference = prepared({pianoKeys(60, 60)});
  std::vector<float> l(2 * kFrames), r(2 * kFrames);
  const SynthEvent atZero[] = {{0, note}};
  reference.process(l, r, atZero);
  const long delay = onset(l);
  ASSERT_GE(delay, 0);
  ASSERT_LT(delay, kFrames);

  // Stamped up to a period ahead (age −50 or 0), it lands in the next block in place; further
  // ahead, at the end of this one.
  for (const auto& [age, offset] :
       {std::pair{1.0, kFrames - 1}, std::pair{100.0, kFrames - 100}, std::pair{255.0, 1},
        std::pair{256.0, 0}, std::pair{700.0, 0}, std::pair{-50.0, kFrames + 50},
        std::pair{0.0, kFrames}, std::pair{-300.0, kFrames - 1}}) {
    SCOPED_TRACE(::testing::Message() << "arrived " << age << " samples before now");
    Synth synth = prepared({pianoKeys(60, 60)});
    SpscQueue<StampedMessage> midi(16);
    Player player(synth, midi, nullptr, kRate, kFrames);
    ASSERT_TRUE(midi.push({before(age), note}));
    std::vector<float> first(2 * kFrames), second(2 * kFrames);
    player.render(first.data(), kFrames, kNow);
    player.render(second.data(), kFrames, kNow + nanoseconds(kFrames / kRate));
    first.insert(first.end(), second.begin(), second.end());
    EXPECT_EQ(onset(left(first)), offset + delay);
    EXPECT_EQ(midi.peek(), nullptr);  // drained
  }
}

// Messages in arrival order keep their spacing to the sample: two blocks equal the synth's own
// output with each event at frames − d·rate (non-decreasing, clamped to the first block), those
// stamped ahead of now (the JACK input's, jack_midi_input.h) in the second block.
TEST(Player, MessagesInArrivalOrderKeepTheirSpacing) {
  constexpr int kFrames = 512;
  const std::pair<double, MidiMessage> arrivals[] = {
      {900.0, {0x90, 48, 90}},  {600.0, {0x90, 50, 70}},  {511.0, {0xB0, 64, 127}},
      {300.0, {0x90, 52, 127}}, {299.0, {0x80, 48, 0}},   {120.0, {0xE0, 0, 90}},
      {40.0, {0x90, 49, 100}},  {-10.0, {0x90, 51, 100}}, {-30.0, {0xB0, 7, 80}}};
  Synth reference = prepared({pianoKeys(48, 52)});
  std::vector<SynthEvent> first, second;
  for (const auto& [age, message] : arrivals) {
    if (age > 0.0)
      first.push_back({std::clamp(kFrames - static_cast<int>(age), 0, kFrames - 1), message});
    else
      second.push_back({-static_cast<int>(age), message});
  }
  std::vector<float> l(2 * kFrames), r(2 * kFrames);
  reference.process(std::span(l).first(kFrames), std::span(r).first(kFrames), first);
  reference.process(std::span(l).last(kFrames), std::span(r).last(kFrames), second);

  Synth synth = prepared({pianoKeys(48, 52)});
  SpscQueue<StampedMessage> midi(16);
  Player player(synth, midi, nullptr, kRate, kFrames);
  for (const auto& [age, message] : arrivals) ASSERT_TRUE(midi.push({before(age), message}));
  std::vector<float> interleaved(4 * kFrames);
  player.render(interleaved.data(), kFrames, kNow);
  EXPECT_EQ(player.status().lastMessage, 0x90u << 16 | 49u << 8 | 100u);  // the rest waits
  player.render(interleaved.data() + 2 * kFrames, kFrames, kNow + nanoseconds(kFrames / kRate));
  for (int i = 0; i < 2 * kFrames; ++i) {
    ASSERT_EQ(interleaved[2 * i], l[i]) << "frame " << i;
    ASSERT_EQ(interleaved[2 * i + 1], r[i]) << "frame " << i;
  }
  EXPECT_EQ(player.status().lastMessage, 0xB0u << 16 | 7u << 8 | 80u);
}

// Stamped ahead of now in one period after another (the JACK input's, its client run before the
// player's each cycle): each period's message waits one block and lands in place there — a block
// that took a waiting message still leaves the next period's for the block after.
TEST(Player, MessagesStampedAheadEveryPeriodEachLandInTheNextBlock) {
  constexpr int kFrames = 256, kBlocks = 4, kAhead = 10;
  Synth reference = prepared({pianoKeys(48, 52)});
  std::vector<float> l((kBlocks + 1) * kFrames), r(l.size());
  for (int b = 0; b <= kBlocks; ++b) {
    std::vector<SynthEvent> events;
    if (b > 0) events.push_back({kAhead, {0x90, uint8_t(47 + b), 100}});
    reference.process(std::span(l).subspan(b * kFrames, kFrames),
                      std::span(r).subspan(b * kFrames, kFrames), events);
  }
  Synth synth = prepared({pianoKeys(48, 52)});
  SpscQueue<StampedMessage> midi(16);
  Player player(synth, midi, nullptr, kRate, kFrames);
  std::vector<float> interleaved(2 * (kBlocks + 1) * kFrames);
  for (int b = 0; b <= kBlocks; ++b) {
    const std::int64_t now = kNow + nanoseconds(b * kFrames / kRate);
    if (b < kBlocks) {
      ASSERT_TRUE(midi.push({now + nanoseconds(kAhead / kRate), {0x90, uint8_t(48 + b), 100}}));
    }
    player.render(interleaved.data() + 2 * b * kFrames, kFrames, now);
  }
  for (size_t i = 0; i < l.size(); ++i) {
    ASSERT_EQ(interleaved[2 * i], l[i]) << "frame " << i;
    ASSERT_EQ(interleaved[2 * i + 1], r[i]) << "frame " << i;
  }
}

// --- The recording tee ---------------------------------------------------------------------------

TEST(Player, RecordingReceivesExactlyTheRenderedSamples) {
  constexpr int kFrames = 256;
  Synth synth =
      prepared({pianoKeys(48, 64, testing::kPerformancePolyphony), testing::smallPlate()});
  SpscQueue<StampedMessage> midi(256);
  SpscQueue<float> record(2 * static_cast<size_t>(kRate));  // 1 s: the 0.3 s performance fits
  Player player(synth, midi, &record, kRate, kFrames);
  std::vector<float> interleaved(2 * kFrames), rendered;
  testing::playPerformance(player, midi, kRate, kFrames, interleaved,
                           [&](std::span<const float> block) {
                             rendered.insert(rendered.end(), block.begin(), block.end());
                           });
  std::vector<float> recorded(rendered.size() + 1);
  recorded.resize(record.pop(recorded.data(), recorded.size()));
  EXPECT_EQ(recorded, rendered);
  EXPECT_EQ(player.status().recordDropped, 0);
}

// A block the ring has no room for is dropped whole and counted; the next one that fits is kept.
TEST(Player, FullRecordingDropsWholeBlocksAndCountsThem) {
  constexpr int kFrames = 64, kSamples = 2 * kFrames;
  Synth synth = prepared({pianoKeys(60, 60)});
  SpscQueue<StampedMessage> midi(16);
  SpscQueue<float> record(300);
  const int fit = static_cast<int>(record.capacity() / kSamples);
  ASSERT_GT(record.capacity() % kSamples, 0u);  // a partial block would fit: it must not be written
  Player player(synth, midi, &record, kRate, kFrames);
  ASSERT_TRUE(midi.push({kNow, {0x90, 60, 127}}));
  std::vector<std::vector<float>> blocks;
  auto renderBlock = [&] {
    blocks.emplace_back(kSamples);
    player.render(blocks.back().data(), kFrames,
                  kNow + nanoseconds(static_cast<double>(blocks.size()) * kFrames / kRate));
  };
  for (int n = 0; n <= fit; ++n) renderBlock();
  EXPECT_EQ(player.status().recordDropped, kSamples);  // the last one

  std::vector<float> got(kSamples);
  ASSERT_EQ(record.pop(got.data(), kSamples), size_t{kSamples});  // room for one block again
  EXPECT_EQ(got, blocks[0]);
  renderBlock();
  EXPECT_EQ(player.status().recordDropped, kSamples);
  std::vector<int> kept;  // block `fit` was dropped; the one after it was kept
  for (int n = 1; n < fit; ++n) kept.push_back(n);
  kept.push_back(fit + 1);
  for (int n : kept) {
    ASSERT_EQ(record.pop(got.data(), kSamples), size_t{kSamples});
    EXPECT_EQ(got, blocks[n]) << "block " << n;
  }
  EXPECT_EQ(record.pop(got.data(), kSamples), 0u);
}

// hamiltone-play gives the synthesizer's workers the scheduling of the thread that calls render().
TEST(Player, KnowsTheThreadOfItsCallback) {
  Synth synth = prepared({pianoKeys(48, 48)});
  SpscQueue<StampedMessage> midi(16);
  Player player(synth, midi, nullptr, kRate, 64);
  EXPECT_FALSE(player.callbackThread());
  std::vector<float> interleaved(2 * 64);
  pthread_t callback{};
  std::thread([&] {
    callback = pthread_self();
    player.render(interleaved.data(), 64, kNow);
  }).join();
  ASSERT_TRUE(player.callbackThread());
  EXPECT_TRUE(pthread_equal(*player.callbackThread(), callback));
}

// --- Overload protection -------------------------------------------------------------------------
// The load is measured on the real clock against the period the claimed sample rate gives a
// block: claiming 1 GHz makes every block late (a 64-frame block stands for 64 ns), claiming 1 Hz
// makes every block early (64 s). Recovery needs a second of early blocks after late ones from the
// same player, which no claimed rate gives, so it is not tested here. With workers the load still
// ends with the block's last key, as Synth::process returns only once every key is rendered.

// A budget of a nanosecond's share of the period makes every block overloaded, on the real rate's
// clock, so the hold after each drop passes as it does live.
constexpr double kNoBudget = 1e-9;

// Overloaded block after block with 8 keys sounding: nothing on the first block (a single late
// block, as a busy server gives, is no overload), then the strings' live tail, and kHoldSeconds
// later one key at a time, kHoldSeconds apart (the key fading out is measured gone first), down
// to the floor of kFloorVoices and no further.
TEST(Player, OverloadLowersTheVoiceLimitOneKeyPerHoldDownToTheFloor) {
  constexpr int kFrames = 64, kPolyphony = 8;
  const double hold = Player::kHoldSeconds * kRate / kFrames;  // blocks
  for (int threads : {1, 3}) {  // on the callback's thread alone, and with two workers
    SCOPED_TRACE(std::to_string(threads) + " threads");
    Synth synth = prepared({pianoKeys(48, 55, kPolyphony)}, kRate, threads);
    SpscQueue<StampedMessage> midi(16);
    Player player(synth, midi, nullptr, kRate, kFrames, kNoBudget);
    EXPECT_EQ(player.status().limit, kPolyphony);
    for (int note = 48; note < 48 + kPolyphony; ++note)
      ASSERT_TRUE(midi.push({0, {0x90, uint8_t(note), 100}}));
    std::vector<float> interleaved(2 * kFrames);
    std::vector<int> dropsAt;
    int limit = kPolyphony;
    for (int block = 0; block < std::lround(6 * hold); ++block) {
      player.render(interleaved.data(), kFrames, 0);
      const Player::Status status = player.status();
      EXPECT_GT(status.load, kNoBudget);
      EXPECT_GE(status.peakLoad, status.load);
      EXPECT_EQ(synth.polyphony(), status.limit);
      EXPECT_LE(status.voices, status.limit);
      EXPECT_EQ(status.voices, synth.activeVoices());
      if (status.limit != limit) {
        EXPECT_EQ(status.limit, limit - 1) << "block " << block;
        EXPECT_GT(status.dropLoad, kNoBudget);
        dropsAt.push_back(block);
        limit = status.limit;
      }
      EXPECT_EQ(status.limitDrops, static_cast<long>(dropsAt.size()));
      // The live tail, at kTailShare of the budget, goes on before the first drop, once.
      EXPECT_EQ(status.liveTail, block >= Player::kOverloadedBlocks - 1) << "block " << block;
      EXPECT_EQ(synth.liveTail(), status.liveTail);
      EXPECT_EQ(status.liveTails, status.liveTail ? 1 : 0);
    }
    EXPECT_EQ(limit, Player::kFloorVoices);
    ASSERT_EQ(dropsAt.size(), size_t{kPolyphony - Player::kFloorVoices});
    // The tail first, then a key only once its effect could be measured.
    EXPECT_GE(dropsAt[0], Player::kOverloadedBlocks - 1 + hold);
    EXPECT_LE(dropsAt[0], Player::kOverloadedBlocks + hold);
    for (size_t k = 1; k < dropsAt.size(); ++k) EXPECT_GE(dropsAt[k] - dropsAt[k - 1], hold);
  }
}

// The host's load, not the keys': overloaded blocks with no key sounding, or fewer keys than the
// floor, leave the limit alone (it went to 1 at the first late block).
TEST(Player, OverloadWithoutKeysToTakeLeavesTheLimitAlone) {
  constexpr int kFrames = 64, kPolyphony = 8;
  Synth synth = prepared({pianoKeys(48, 55, kPolyphony)});
  SpscQueue<StampedMessage> midi(16);
  Player player(synth, midi, nullptr, kRate, kFrames, kNoBudget);
  std::vector<float> interleaved(2 * kFrames);
  for (int block = 0; block < 100; ++block) {
    for (int note = 48; block == 50 && note < 48 + Player::kFloorVoices; ++note)
      ASSERT_TRUE(midi.push({0, {0x90, uint8_t(note), 100}}));
    player.render(interleaved.data(), kFrames, 0);
    EXPECT_EQ(player.status().limit, kPolyphony) << "block " << block;
    EXPECT_EQ(player.status().limitDrops, 0);
  }
  EXPECT_EQ(synth.activeVoices(), Player::kFloorVoices);
}

TEST(Player, UnderLightLoadTheLimitStaysAtThePresetsPolyphony) {
  constexpr int kFrames = 64, kPolyphony = 4;
  for (int threads : {1, 3}) {  // on the callback's thread alone, and with two workers
    SCOPED_TRACE(std::to_string(threads) + " threads");
    Synth synth = prepared({pianoKeys(48, 55, kPolyphony)}, kRate, threads);
    SpscQueue<StampedMessage> midi(16);
    Player player(synth, midi, nullptr, 1.0, kFrames);
    for (int note = 48; note < 48 + 6; ++note)
      ASSERT_TRUE(midi.push({0, {0x90, uint8_t(note), 100}}));
    std::vector<float> interleaved(2 * kFrames);
    for (int block = 0; block < 20; ++block) {
      player.render(interleaved.data(), kFrames, 0);
      const Player::Status status = player.status();
      EXPECT_LT(status.load, Player::kRelief);
      EXPECT_EQ(status.limit, kPolyphony);
      EXPECT_FALSE(status.liveTail);
      EXPECT_FALSE(synth.liveTail());
      EXPECT_EQ(synth.polyphony(), kPolyphony);
      EXPECT_EQ(status.voices, synth.activeVoices());
      EXPECT_EQ(status.guardEvents, synth.guardEvents());
      EXPECT_EQ(status.recordDropped, 0);  // no recording ring
    }
    EXPECT_EQ(player.status().lastMessage, 0x90u << 16 | 53u << 8 | 100u);
  }
}

// --- The score (--midi, --notes) -----------------------------------------------------------------

// The score's messages land on the sample their time gives, counted from the first rendered
// sample, merged in order with the queue's: the output equals the synth's own with the same
// events at those offsets, in blocks of any size.
TEST(Player, ScoreMessagesLandOnTheirSamplesMergedWithLiveOnes) {
  const TimedMessage score[] = {{0.0, {0x90, 48, 90}},
                                {100.0 / kRate, {0x90, 50, 70}},
                                {300.0 / kRate, {0xB0, 64, 127}},
                                {300.0 / kRate, {0x90, 52, 127}},
                                {700.0 / kRate, {0x80, 48, 0}},
                                {1000.0 / kRate, {0x90, 51, 100}}};
  constexpr int kFrames = 256, kBlocks = 5;
  // Live: arrived 56 samples before the end of the second block, i.e. at its sample 200.
  const MidiMessage live{0x90, 49, 110};
  const std::pair<long, MidiMessage> all[] = {{0, score[0].message},   {100, score[1].message},
                                              {300, score[2].message}, {300, score[3].message},
                                              {256 + 200, live},       {700, score[4].message},
                                              {1000, score[5].message}};
  Synth reference = prepared({pianoKeys(48, 52)});
  std::vector<float> l(kFrames * kBlocks), r(kFrames * kBlocks);
  for (int b = 0; b < kBlocks; ++b) {
    std::vector<SynthEvent> events;
    for (const auto& [sample, message] : all)
      if (sample / kFrames == b) events.push_back({static_cast<int>(sample % kFrames), message});
    reference.process(std::span(l).subspan(b * kFrames, kFrames),
                      std::span(r).subspan(b * kFrames, kFrames), events);
  }

  Synth synth = prepared({pianoKeys(48, 52)});
  SpscQueue<StampedMessage> midi(16);
  Player player(synth, midi, nullptr, kRate, kFrames);
  player.setScore(score);
  std::vector<float> interleaved(2 * kFrames);
  for (int b = 0; b < kBlocks; ++b) {
    const std::int64_t now = kNow + nanoseconds(b * kFrames / kRate);
    if (b == 1) {
      ASSERT_TRUE(midi.push({now - nanoseconds(56 / kRate), live}));
    }
    player.render(interleaved.data(), kFrames, now);
    for (int i = 0; i < kFrames; ++i) {
      ASSERT_EQ(interleaved[2 * i], l[b * kFrames + i]) << "block " << b << ", frame " << i;
      ASSERT_EQ(interleaved[2 * i + 1], r[b * kFrames + i]) << "block " << b << ", frame " << i;
    }
  }
}

// Finished once the score's last message is played and no key sounds: here all sound off at
// 0.05 s, sample 2400 of block 9, and the keys' 5 ms fade, which ends in block 10.
TEST(Player, FinishedOnceTheScoreIsPlayedAndSilent) {
  constexpr int kFrames = 256;
  const TimedMessage score[] = {
      {0.0, {0x90, 48, 100}}, {0.01, {0x80, 48, 0}}, {0.05, {0xB0, 120, 0}}};
  Synth synth = prepared({pianoKeys(48, 52)});
  SpscQueue<StampedMessage> midi(16);
  Player player(synth, midi, nullptr, kRate, kFrames);
  EXPECT_FALSE(player.status().finished);
  player.setScore(score);
  std::vector<float> interleaved(2 * kFrames);
  const long last = std::lround(0.055 * kRate) / kFrames;  // the block in which the fade ends
  ASSERT_EQ(last, std::lround(0.05 * kRate) / kFrames + 1);
  for (long b = 0; b <= last; ++b) {
    EXPECT_FALSE(player.status().finished) << "block " << b;
    player.render(interleaved.data(), kFrames, kNow);
  }
  EXPECT_TRUE(player.status().finished);

  // Without a score a player never finishes.
  Player live(synth, midi, nullptr, kRate, kFrames);
  live.render(interleaved.data(), kFrames, kNow);
  EXPECT_FALSE(live.status().finished);
}

// A program change past the last preset, live or scored, is ignored by the synthesizer and
// marked in the status, a bit a program, for the main thread to say each once (it was silent).
TEST(Player, ProgramChangesPastTheLastPresetAreCountedInTheStatus) {
  constexpr int kFrames = 256;
  const TimedMessage score[] = {{0.0, {0xC0, 5, 0}}};
  Synth synth = prepared({pianoKeys(48, 52)});
  SpscQueue<StampedMessage> midi(16);
  Player player(synth, midi, nullptr, kRate, kFrames);
  EXPECT_EQ(player.status().ignoredPrograms[0], 0u);
  player.setScore(score);
  std::vector<float> interleaved(2 * kFrames);
  player.render(interleaved.data(), kFrames, kNow);
  EXPECT_EQ(player.status().ignoredPrograms[0], std::uint64_t{1} << 5);
  ASSERT_TRUE(midi.push({before(10), {0xC3, 100, 0}}));  // live, on another channel
  ASSERT_TRUE(midi.push({before(5), {0xC0, 0, 0}}));     // the one preset: taken
  player.render(interleaved.data(), kFrames, kNow);
  EXPECT_EQ(player.status().ignoredPrograms[0], std::uint64_t{1} << 5);
  EXPECT_EQ(player.status().ignoredPrograms[1], std::uint64_t{1} << (100 - 64));
}

// With endRecording (hamiltone-play --midi/--notes, which then exits), the recording ends with the
// block in which the score finished — its last key faded out — whatever comes after it: the same
// file in every run at the same block size. It went on until the main thread noticed the end (a
// 250 ms poll), so that two runs of one score differed in their length of silence.
TEST(Player, TheRecordingEndsWithTheScore) {
  constexpr int kFrames = 256;
  const TimedMessage score[] = {
      {0.0, {0x90, 48, 100}}, {0.01, {0x80, 48, 0}}, {0.05, {0xB0, 120, 0}}};
  Synth synth = prepared({pianoKeys(48, 52)});
  SpscQueue<StampedMessage> midi(16);
  SpscQueue<float> record(1 << 16);
  Player player(synth, midi, &record, kRate, kFrames);
  player.setScore(score, true);
  std::vector<float> interleaved(2 * kFrames), rendered;
  long blocks = 0;
  for (; blocks < 100 && !player.status().finished; ++blocks) {
    player.render(interleaved.data(), kFrames, kNow);
    rendered.insert(rendered.end(), interleaved.begin(), interleaved.end());
  }
  ASSERT_TRUE(player.status().finished);
  // All sound off at 0.05 s and its 5 ms fade are in the recording, the fade's end in its last
  // block.
  EXPECT_EQ(blocks, std::lround(0.055 * kRate) / kFrames + 1);
  for (int b = 0; b < 10; ++b) player.render(interleaved.data(), kFrames, kNow);
  std::vector<float> recorded(rendered.size() + 1);
  recorded.resize(record.pop(recorded.data(), recorded.size()));
  EXPECT_EQ(recorded, rendered);
}

// A score with nothing in it — a valid MIDI file with no channel message, only meta events — is
// played to its end at once. It was taken for no score at all: hamiltone-play --midi on such a
// file played silence forever, listening to no MIDI input and saying nothing.
TEST(Player, AnEmptyScoreIsFinishedOnceTheKeysAreSilent) {
  constexpr int kFrames = 256;
  Synth synth = prepared({pianoKeys(48, 52)});
  SpscQueue<StampedMessage> midi(16);
  Player player(synth, midi, nullptr, kRate, kFrames);
  player.setScore({});
  std::vector<float> interleaved(2 * kFrames);
  // A key played live keeps it from finishing while it sounds.
  ASSERT_TRUE(midi.push({before(100), {0x90, 48, 100}}));
  player.render(interleaved.data(), kFrames, kNow);
  EXPECT_FALSE(player.status().finished);
  ASSERT_TRUE(midi.push({before(100), {0xB0, 120, 0}}));  // all sound off
  for (int b = 0; b < 4; ++b) player.render(interleaved.data(), kFrames, kNow);
  EXPECT_TRUE(player.status().finished);
}

}  // namespace
}  // namespace hamiltone::app
