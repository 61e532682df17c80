// The plate voice: strikes at every velocity and common rate give finite sound and an energy that
// is exactly the strike's work (lossless), harder strikes are louder, and the note sets the size.
#include "voices/plate_voice.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "support/modal.h"

namespace hamiltone {
namespace {

PlatePatch lossless() {
  PlatePatch p;
  p.t60Low = p.t60High = INFINITY;
  return p;
}

// Plays `seconds`; returns the peak |sample| and whether every sample was finite.
std::pair<double, bool> play(PlateVoice& voice, double seconds, double rate, auto each) {
  std::vector<float> l(64), r(64);
  double peak = 0.0;
  bool finite = true;
  for (long n = 0; n < std::lround(seconds * rate / 64); ++n) {
    voice.process(l, r);
    for (size_t i = 0; i < l.size(); ++i) {
      finite = finite && std::isfinite(l[i]) && std::isfinite(r[i]);
      peak = std::max({peak, std::abs(double(l[i])), std::abs(double(r[i]))});
    }
    each();
  }
  return {peak, finite};
}

// Lossless, from rest: H^{n+½} equals the work the force pulse has done, step by step, to
// roundoff over ~1e4 steps of ~900 unknowns.
TEST(PlateVoice, StrikesConserveEnergyWithTheInputAccounted) {
  for (double rate : {44100.0, 48000.0, 96000.0}) {
    for (int velocity : {1, 64, 127}) {
      PlateVoice voice;
      voice.prepare(lossless(), 48, rate);
      voice.noteOn(velocity / 127.0);
      double worst = 0.0;
      const auto [peak, finite] = play(voice, 0.1, rate, [&] {
        worst = std::max(
            worst, std::abs(voice.energy() - voice.suppliedEnergy()) / voice.suppliedEnergy());
      });
      EXPECT_TRUE(finite) << velocity << " at " << rate;
      EXPECT_GT(peak, 0.0);
      EXPECT_LE(worst, 1e-10) << velocity << " at " << rate;
      EXPECT_EQ(voice.guardEvents(), 0);
    }
  }
}

// A strike is a force pulse of impulse J = F0 T / 2. One shorter than the scheme's step (20.8 µs
// at 48 kHz) still sounds, and is heard through J alone: a 10 µs and a 5 µs pulse of equal J give
// the same sound to roundoff, and a 40 µs one (two steps) of equal J — whose spectrum is within
// 3 dB of theirs below 10 kHz (a raised cosine of length T falls 3 dB near f = 0.48/T) — a peak
// within a factor 2. Sampled at the steps, the short pulses were F(0) = 0: silence.
TEST(PlateVoice, AStrikeShorterThanAStepDeliversItsImpulse) {
  const double rate = 48000.0;
  auto sound = [&](double duration, double impulse) {
    PlatePatch patch = lossless();
    patch.durationMin = patch.durationMax = duration;
    patch.forceMax = 2.0 * impulse / duration;
    PlateVoice voice;
    voice.prepare(patch, 48, rate);
    voice.noteOn(1.0);
    std::vector<float> l(2400), r(2400);
    voice.process(l, r);
    return std::pair{l, voice.suppliedEnergy()};
  };
  const double impulse = 300.0 * 0.5e-3 / 2.0;  // the default patch's at velocity 127
  const auto [tenMicro, suppliedTen] = sound(1e-5, impulse);
  const auto [fiveMicro, suppliedFive] = sound(0.5e-5, impulse);
  const auto [twoSteps, suppliedTwo] = sound(4e-5, impulse);
  EXPECT_GT(suppliedTen, 0.0);
  double peakTen = 0.0, peakTwo = 0.0, difference = 0.0;
  for (size_t i = 0; i < tenMicro.size(); ++i) {
    peakTen = std::max(peakTen, std::abs(double(tenMicro[i])));
    peakTwo = std::max(peakTwo, std::abs(double(twoSteps[i])));
    difference = std::max(difference, std::abs(double(tenMicro[i]) - double(fiveMicro[i])));
  }
  EXPECT_GT(peakTen, 0.0);
  EXPECT_LE(difference, 1e-6 * peakTen);
  EXPECT_NEAR(suppliedTen, suppliedFive, 1e-9 * suppliedTen);
  EXPECT_GT(peakTen, 0.5 * peakTwo);
  EXPECT_LT(peakTen, 2.0 * peakTwo);
}

TEST(PlateVoice, HarderIsLouder) {
  auto peak = [](double velocity) {
    PlateVoice voice;
    voice.prepare(PlatePatch{}, 48, 48000.0);
    voice.noteOn(velocity);
    return play(voice, 0.05, 48000.0, [] {}).first;
  };
  const double soft = peak(0.2), loud = peak(1.0);
  EXPECT_GT(loud, 4.0 * soft);  // force ∝ v^1.5: 11× the force, and a shorter, brighter pulse
}

// Frequencies go as 1/L²: an octave up halves L² and doubles the lowest mode (to the grid's
// dispersion, which changes with the grid).
TEST(PlateVoice, NoteSetsTheSize) {
  PlateVoice low, high;
  low.prepare(PlatePatch{}, 48, 48000.0);
  high.prepare(PlatePatch{}, 60, 48000.0);
  EXPECT_NEAR(high.lowestModeHz() / low.lowestModeHz(), 2.0, 0.05);
  PlateVoice outside;
  EXPECT_THROW(outside.prepare(PlatePatch{}, 100, 48000.0), std::invalid_argument);
}

// Per patch, the note moves the strike point instead: same plate, same modes, another sound.
TEST(PlateVoice, NoteCanMoveTheStrikeInstead) {
  PlatePatch patch;
  patch.noteMovesStrike = true;
  PlateVoice low, high;
  low.prepare(patch, patch.lowestNote, 48000.0);
  high.prepare(patch, patch.highestNote, 48000.0);
  EXPECT_EQ(low.lowestModeHz(), high.lowestModeHz());
  std::vector<float> l1(256), r1(256), l2(256), r2(256);
  low.noteOn(0.8);
  high.noteOn(0.8);
  low.process(l1, r1);
  high.process(l2, r2);
  EXPECT_NE(l1, l2);
}

// The displacement pickup's DC blocker: a step decays away (to 1 % within 0.15 s at 5 Hz:
// e^{−2π·5·0.15} ≈ 0.009) while a 100 Hz tone passes within 0.2 dB.
TEST(DcBlocker, RemovesAStepAndPassesTheAudioBand) {
  DcBlocker b;
  b.prepare(5.0, 48000.0);
  double y = 0.0;
  for (int n = 0; n < 7200; ++n) y = b.process(1.0);
  EXPECT_LT(std::abs(y), 0.01);
  b.reset();
  double peak = 0.0;
  for (int n = 0; n < 48000; ++n) {
    y = b.process(std::sin(2.0 * std::numbers::pi * 100.0 * n / 48000.0));
    if (n > 24000) peak = std::max(peak, std::abs(y));
  }
  EXPECT_NEAR(20.0 * std::log10(peak), 0.0, 0.2);
}

// With a strong high-frequency loss the grid is coarser (the σ1 term of the bound): every note
// of the patch's range prepares at the usual rates, where the lossless grid would break (44).
TEST(PlateVoice, EveryNotePreparesWithAStrongHighFrequencyLoss) {
  PlatePatch patch;
  patch.t60High = 0.05;
  for (double rate : {44100.0, 48000.0})
    for (int note = patch.lowestNote + 12; note <= patch.highestNote; note += 3) {
      PlateVoice voice;
      EXPECT_NO_THROW(voice.prepare(patch, note, rate)) << note << " at " << rate;
    }
}

TEST(PlateVoice, ReleaseDampsAndFreesTheVoice) {
  PlatePatch patch;
  patch.damperT60 = 0.2;
  PlateVoice voice;
  voice.prepare(patch, 60, 48000.0);
  voice.noteOn(0.8);
  play(voice, 0.05, 48000.0, [] {});
  voice.release();
  play(voice, 2.0, 48000.0, [] {});
  EXPECT_FALSE(voice.active());
}

// Never released, a plate whose sound has died away frees itself too: T60 0.3 s takes a strike
// under −80 dB of its peak within 0.5 s, so after 2 s only a voice kept for nothing would be left.
TEST(PlateVoice, AHeldPlateFreesItselfOnceSilent) {
  PlatePatch patch;
  patch.t60Low = 0.3;
  patch.t60High = 0.2;
  PlateVoice voice;
  voice.prepare(patch, 60, 48000.0);
  voice.noteOn(0.8);
  play(voice, 2.0, 48000.0, [] {});
  EXPECT_FALSE(voice.active());
}

// A strike of 1e200 N overflows the state: the guard silences the block, resets and counts it.
TEST(PlateVoice, GuardSilencesANonFiniteState) {
  PlatePatch patch;
  patch.forceMax = 1e200;
  PlateVoice voice;
  voice.prepare(patch, 48, 48000.0);
  voice.noteOn(1.0);
  std::vector<float> l(64, 1.0f), r(64, 1.0f);
  for (int block = 0; block < 20 && voice.guardEvents() == 0; ++block) voice.process(l, r);
  EXPECT_EQ(voice.guardEvents(), 1);
  for (float x : l) EXPECT_EQ(x, 0.0f);
  EXPECT_FALSE(voice.active());
}

TEST(PlateVoice, RefusesAnInvalidPatch) {
  PlateVoice voice;
  auto with = [](auto change) {
    PlatePatch p;
    change(p);
    return p;
  };
  EXPECT_THROW(voice.prepare(with([](auto& p) { p.oversampling = 3; }), 48, 48000),
               std::invalid_argument);
  EXPECT_THROW(voice.prepare(with([](auto& p) { p.strike[0] = 1.2; }), 48, 48000),
               std::invalid_argument);
  EXPECT_THROW(voice.prepare(with([](auto& p) { p.durationMin = 0.0; }), 48, 48000),
               std::invalid_argument);
  EXPECT_THROW(voice.prepare(with([](auto& p) { p.t60High = 20.0; }), 48, 48000),
               std::invalid_argument);
  EXPECT_THROW(voice.prepare(with([](auto& p) { p.damperT60 = 1e-5; }), 48, 48000),
               std::invalid_argument);
  EXPECT_THROW(voice.prepare(with([](auto& p) { p.oversampling = 16; }), 24, 48000),
               std::invalid_argument);  // 1 m plate, 16x: far more than 120 points a side
}

}  // namespace
}  // namespace hamiltone
