// No scheme allocates while stepping or reporting energy: Eigen's EIGEN_RUNTIME_NO_MALLOC guard,
// armed in this binary (see tests/CMakeLists.txt), aborts on any heap allocation through Eigen,
// and this binary's operator new counts every other allocation made while it is forbidden. The
// audio path built on them is held to the same: voices, the synthesizer and the live player.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>
#include <numbers>
#include <tuple>
#include <vector>

#include "instruments/hammer.h"
#include "instruments/piano_body.h"
#include "instruments/piano_scale.h"
#include "instruments/plate.h"
#include "schemes/variable_step_sav.h"
#include "support/fpu_runs.h"
#include "support/player_performance.h"
#include "support/test_instruments.h"
#include "synth/synth.h"
#include "voices/plate_voice.h"
#include "voices/string_voice.h"

namespace {
std::atomic<bool> forbidden{false};
std::atomic<long> forbiddenNews{0};
}  // namespace

void* operator new(std::size_t size) {
  if (forbidden) ++forbiddenNews;
  if (void* p = std::malloc(size ? size : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace hamiltone {
namespace {

// Both guards on: Eigen's (aborts) and operator new's (counted).
void forbidAllocation(bool forbid) {
  Eigen::internal::set_is_malloc_allowed(!forbid);
  forbidden = forbid;
}

template <class Scheme>
void stepWithoutAllocating(Scheme& scheme, int steps = 1000) {
  double sink = 0.0;
  const long before = forbiddenNews;
  forbidAllocation(true);
  for (int n = 0; n < steps; ++n) {
    scheme.step();
    sink += scheme.energy().total() + scheme.dissipated();
  }
  forbidAllocation(false);
  EXPECT_EQ(forbiddenNews - before, 0);
  EXPECT_TRUE(std::isfinite(sink));
}

FermiPastaUlam chain() { return FermiPastaUlam(50, 50.0); }
InitialState start() { return fpuInitialState(chain(), 10.0); }

TEST(NoAllocation, OperatorNewGuardCounts) {
  const long before = forbiddenNews;
  forbidAllocation(true);
  auto* p = new std::vector<int>(10);
  forbidAllocation(false);
  delete p;
  EXPECT_EQ(forbiddenNews - before, 2);  // the vector and its buffer
}

TEST(NoAllocation, GuardIsArmed) {
  EXPECT_DEATH(
      {
        Eigen::internal::set_is_malloc_allowed(false);
        Vector v(100);
        v.setOnes();
      },
      "heap allocation is forbidden");
}

// Lossless and lossy: the schemes branch on the loss once per step.
TEST(NoAllocation, StormerVerlet) {
  for (double sigma0 : {0.0, 1.0}) {
    StormerVerlet<FermiPastaUlam> s(chain(), {.k = 1e-3, .sigma0 = sigma0}, start());
    stepWithoutAllocating(s);
  }
}

TEST(NoAllocation, NonSplitSav) {
  for (double sigma0 : {0.0, 1.0}) {
    NonSplitSav<FermiPastaUlam> s(chain(), {.k = 1e-3, .sigma0 = sigma0, .epsilon = 1.0}, start());
    stepWithoutAllocating(s);
  }
}

TEST(NoAllocation, SplitSav) {
  for (double sigma0 : {0.0, 1.0}) {
    SplitSav<FermiPastaUlam> s(chain(), {.k = 1e-3, .sigma0 = sigma0, .epsilon = 1.0}, start());
    stepWithoutAllocating(s);
  }
}

// The struck string with both losses: the stencils, the hammer contact and the σ1 operator.
// Störmer–Verlet must resolve the longitudinal wave, so it runs on the longitudinal grid.
void strikeWithoutAllocating(GridRule rule, auto makeScheme) {
  StringPhysics physics;
  physics.inertia = std::numbers::pi * std::pow(1.063e-3, 4) / 64.0;
  const double k = 1.0 / 48000.0;
  const HammeredString system(NonlinearString(physics, gridSegments(physics, rule, k, 1e-3, 1.0)),
                              HammerFelt{});
  InitialState start{Vector::Zero(system.size()), Vector::Zero(system.size())};
  start.q[system.hammerIndex()] = -1e-4;
  start.p[system.hammerIndex()] = 0.03;
  auto scheme = makeScheme(system, StepParameters{.k = k, .sigma0 = 1.0, .sigma1 = 1e-3}, start);
  stepWithoutAllocating(scheme);
}

TEST(NoAllocation, VariableStepSav) {
  VariableStepSav<FermiPastaUlam> s(chain(), start(), 1.0);
  s.step(1e-3);  // the start (21)
  double sink = 0.0;
  const long before = forbiddenNews;
  forbidAllocation(true);
  for (int n = 0; n < 1000; ++n) {
    s.step(n % 2 ? 0.5e-3 : 1.5e-3);
    sink += s.energy().total();
  }
  forbidAllocation(false);
  EXPECT_EQ(forbiddenNews - before, 0);
  EXPECT_TRUE(std::isfinite(sink));
}

TEST(NoAllocation, SchemesOnTheStruckString) {
  strikeWithoutAllocating(GridRule::transverse,
                          [](auto&&... a) { return SplitSav<HammeredString>(a...); });
  strikeWithoutAllocating(GridRule::longitudinal,
                          [](auto&&... a) { return StormerVerlet<HammeredString>(a...); });
}

// The voice's audio path: strike, steps, hammer catch, pickups, decimation, guard, damper.
TEST(NoAllocation, StringVoiceProcess) {
  for (int oversampling : {1, 4}) {
    StringPatch patch;
    patch.string = pianoString(60);
    patch.oversampling = oversampling;
    StringVoice voice;
    voice.prepare(patch, 60, 48000.0);
    std::vector<float> left(256), right(256);
    const long before = forbiddenNews;
    forbidAllocation(true);
    voice.noteOn(0.8);
    for (int block = 0; block < 100; ++block) {
      if (block == 50) voice.release();
      voice.process(left, right);
    }
    voice.reset();
    forbidAllocation(false);
    EXPECT_EQ(forbiddenNews - before, 0);
    EXPECT_EQ(voice.guardEvents(), 0);
  }
}

// The linear tail: the switch to the linear string and back at a strike, the linear steps with
// the damper down and up (a threshold of 1e-3 takes C4 at velocity 0.1 linear within 20 ms).
TEST(NoAllocation, StringVoiceLinearTail) {
  StringPatch patch;
  patch.string = pianoString(60);
  patch.linearBelow = 1e-3;
  StringVoice voice;
  voice.prepare(patch, 60, 48000.0);
  std::vector<float> left(256), right(256);
  const long before = forbiddenNews;
  forbidAllocation(true);
  voice.noteOn(0.1);
  bool linear = false;
  for (int block = 0; block < 100; ++block) {
    if (block == 50) voice.release();
    voice.process(left, right);
    linear = linear || voice.linear();
  }
  voice.noteOn(0.1);
  voice.process(left, right);
  forbidAllocation(false);
  EXPECT_EQ(forbiddenNews - before, 0);
  EXPECT_TRUE(linear);
  EXPECT_FALSE(voice.linear());
}

// The plate: stencils, the bracket ℓ and the DST Airy solve (Eigen's blocked products), with
// both losses, from a small grid to the largest the plate voice accepts.
TEST(NoAllocation, SplitSavOnThePlate) {
  PlatePhysics large;
  large.lx = 1.0;
  large.ly = 0.8;
  large.thickness = 1e-3;
  // 121 segments: the 120 interior points a side the plate voice allows at most.
  for (const auto& [physics, mx, my] :
       {std::tuple{PlatePhysics{}, 16, 12}, std::tuple{PlatePhysics{}, 31, 31},
        std::tuple{large, 88, 70}, std::tuple{large, 121, 121}}) {
    const VonKarmanPlate plate(physics, mx, my);
    SplitSav<VonKarmanPlate> scheme(plate, {.k = 1e-6, .sigma0 = 1.0, .sigma1 = 1e-4},
                                    {plateFirstMode(plate, 0.1), Vector::Zero(plate.size())});
    stepWithoutAllocating(scheme, 20);
  }
}

// The plate voice's audio path: the force pulse, steps, pickups, decimation, guard, damper.
TEST(NoAllocation, PlateVoiceProcess) {
  PlateVoice voice;
  voice.prepare(PlatePatch{}, 60, 48000.0);
  std::vector<float> left(128), right(128);
  const long before = forbiddenNews;
  forbidAllocation(true);
  voice.noteOn(0.8);
  for (int block = 0; block < 40; ++block) {
    if (block == 30) voice.release();
    voice.process(left, right);
  }
  voice.reset();
  forbidAllocation(false);
  EXPECT_EQ(forbiddenNews - before, 0);
  EXPECT_EQ(voice.guardEvents(), 0);
}

// The master bus with its limiter acting — attack, hold, release, the meters, non-finite input —
// allocates nothing (it runs in every render path, the live player's callback among them).
TEST(NoAllocation, MasterBusLimiting) {
  MasterBus bus;
  bus.prepare(48000.0);
  std::vector<float> left(4800), right(4800);
  for (size_t n = 0; n < left.size(); ++n) {
    left[n] = n < 2400 ? 4.0f * std::sin(0.05f * static_cast<float>(n)) : 0.1f;
    right[n] = n == 100 ? NAN : -left[n];
  }
  const long before = forbiddenNews;
  forbidAllocation(true);
  for (int block = 0; block < 10; ++block) bus.process(left, right);
  const double db = bus.limiter().deepestReductionDb();
  forbidAllocation(false);
  EXPECT_EQ(forbiddenNews - before, 0);
  EXPECT_GT(bus.limiter().limitedFrames(), 0);
  EXPECT_GT(db, 0.0);
}

// The synthesizer (prepared with blocks of 256) plays the events, then blocks of several sizes (1
// to the prepared maximum, and beyond it), allocating nothing.
void expectSynthProcessDoesNotAllocate(std::vector<Instrument> instruments,
                                       std::span<const SynthEvent> events) {
  Synth synth;
  synth.prepare(std::move(instruments), {.sampleRate = 48000.0, .maxBlock = 256, .notes = {}});
  std::vector<float> left(600), right(600);
  const long before = forbiddenNews;
  forbidAllocation(true);
  synth.process(left, right, events);
  for (int frames : {1, 64, 256, 600})
    for (int block = 0; block < 4; ++block)
      synth.process(std::span(left).first(frames), std::span(right).first(frames), {});
  forbidAllocation(false);
  EXPECT_EQ(forbiddenNews - before, 0);
  EXPECT_EQ(synth.guardEvents(), 0);
}

// The synthesizer's process(): every kind of event, a steal and its pending re-strike, the plate,
// a program change, blocks of several sizes (1 to the prepared maximum, and beyond it).
TEST(NoAllocation, SynthProcess) {
  const SynthEvent events[] = {
      {0, {0x90, 48, 100}}, {3, {0x90, 50, 60}},  {5, {0xB0, 64, 127}},  {9, {0x90, 52, 127}},
      {11, {0x80, 48, 0}},  {20, {0xE0, 0, 100}}, {30, {0x90, 48, 90}},  {40, {0xB0, 7, 90}},
      {41, {0xB0, 64, 0}},  {50, {0xC0, 1, 0}},   {51, {0x90, 60, 127}}, {60, {0xB0, 123, 0}},
      {70, {0xB0, 120, 0}}, {71, {0x90, 61, 80}}, {80, {0xF0, 0, 0}},    {90, {0xB0, 121, 0}}};
  expectSynthProcessDoesNotAllocate({testing::pianoKeys(48, 52, 2), testing::smallPlate()}, events);
}

// The pedals: half-pedalling (CC64 between 20 and 100, moved while keys ring), sostenuto (CC66)
// catching and letting go, una corda (CC67) on three-string keys (one on a bridge), and reset
// controllers.
TEST(NoAllocation, SynthPedals) {
  Instrument piano = testing::pianoKeys(48, 52, 4);
  for (StringKey& key : piano.keys) key.unisons = 3;
  piano.keys[0].bridge = {.mass = 0.05, .stiffness = 1e5, .resistance = 900.0};  // C3 on a bridge
  const SynthEvent events[] = {
      {0, {0xB0, 67, 127}}, {1, {0x90, 48, 100}},  {3, {0x90, 50, 60}},  {5, {0xB0, 66, 127}},
      {9, {0xB0, 64, 90}},  {11, {0x80, 48, 0}},   {20, {0x80, 50, 0}},  {30, {0xB0, 64, 64}},
      {40, {0x90, 52, 90}}, {41, {0xB0, 67, 0}},   {50, {0x80, 52, 0}},  {60, {0xB0, 64, 30}},
      {70, {0xB0, 66, 0}},  {71, {0xB0, 64, 127}}, {80, {0x90, 49, 80}}, {90, {0xB0, 121, 0}}};
  expectSynthProcessDoesNotAllocate({piano}, events);
}

// The audio callback's work (app/player.cpp): the MIDI queue drained onto sample offsets and
// merged with a score's (the same performance, as --midi or --notes would give it), the
// synthesizer, the recording tee and the load measurement, over the rate × block-size grid.
TEST(NoAllocation, PlayerRender) {
  for (double rate : {44100.0, 48000.0, 96000.0}) {
    Synth synth;
    synth.prepare(testing::performanceInstruments(HAMILTONE_SOURCE_DIR),
                  testing::performanceSetup(rate));
    for (int frames : {1, 64, 256, 1024}) {
      SCOPED_TRACE(::testing::Message() << rate << " Hz, " << frames << " frames");
      synth.setPolyphony(0);
      synth.setLiveTail(false);
      SpscQueue<app::StampedMessage> midi(256);
      SpscQueue<float> record(2 * static_cast<size_t>(rate));
      app::Player player(synth, midi, &record, rate, frames);
      player.setScore(testing::kPerformance);
      std::vector<float> interleaved(2 * static_cast<size_t>(frames)), drained(2 * 1024);
      const long before = forbiddenNews;
      forbidAllocation(true);
      testing::playPerformance(
          player, midi, rate, frames, interleaved,
          [&](std::span<const float>) { record.pop(drained.data(), drained.size()); });
      forbidAllocation(false);
      EXPECT_EQ(forbiddenNews - before, 0);
      EXPECT_EQ(player.status().recordDropped, 0);
    }
  }
}

TEST(NoAllocation, MarazzatoWithEveryQuadrature) {
  for (QuadratureRule rule :
       {QuadratureRule::midpoint, QuadratureRule::gaussLegendre2, QuadratureRule::gaussLegendre3,
        QuadratureRule::gaussLegendre5, QuadratureRule::lobatto3, QuadratureRule::lobatto5}) {
    Marazzato<FermiPastaUlam> s(chain(), {.k = 1e-3}, start(), rule);
    stepWithoutAllocating(s);
    forbidAllocation(true);
    const double d = s.discreteEnergy();
    forbidAllocation(false);
    EXPECT_GT(d, 0.0);
  }
}

// The piano's body: the board and the 88 keys' sympathetic strings stepped, read, damped and
// excluded on the audio thread.
TEST(NoAllocation, PianoBodyStep) {
  const PianoBodySpec spec;
  PianoBody body;
  body.prepare(spec, bridgeLine(21, 108, spec.board), grandSympatheticKeys());
  std::vector<double> forces(body.keys(), 0.0);
  double sink = 0.0;
  const long before = forbiddenNews;
  forbidAllocation(true);
  for (int n = 0; n < 2000; ++n) {
    forces[39] = std::sin(0.05 * n);
    if (n == 100) body.setDamper(51, 0.0);
    if (n == 200) body.setExcluded(39, true);
    body.step(forces);
    double l = 0.0, r = 0.0;
    body.output(l, r);
    sink += l + r + body.energy() + body.dissipated() + body.supplied();
  }
  body.reset();
  forbidAllocation(false);
  EXPECT_EQ(forbiddenNews - before, 0);
  EXPECT_TRUE(std::isfinite(sink));
}

}  // namespace
}  // namespace hamiltone
