// The linear tail in the string's modes (voices/modal_tail.h): the same linear string as the
// scheme's nodes — its output, its probes and its energy to roundoff with no mode dropped — that
// drops only what lies under its floor and hands the string back to its nodes where they are
// needed: a strike, a felt damper, the modal tail turned off.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <vector>

#include "instruments/piano_scale.h"
#include "instruments/string_tuning.h"
#include "presets/preset_loader.h"
#include "support/energy_checks.h"
#include "support/modal.h"
#include "synth/unison_strings.h"
#include "voices/string_voice.h"

namespace hamiltone {
namespace {

constexpr double kRate = 48000.0;
constexpr size_t kBlock = 64;

// A grand-piano string with the live tail's threshold, so that it goes linear within a second or
// two; stereo velocity pickups, as the grand piano has them.
StringPatch piano(int note) {
  StringPatch p;
  p.string = pianoString(note);
  p.linearBelow = kMaxLinearBelow;
  p.bendRange = 0.0;
  return p;
}

// One block of both channels, appended.
void block(StringVoice& voice, std::vector<double>& out) {
  std::vector<float> l(kBlock), r(kBlock);
  voice.process(l, r);
  for (size_t i = 0; i < kBlock; ++i) {
    out.push_back(l[i]);
    out.push_back(r[i]);
  }
}

double peak(const std::vector<double>& x, size_t from = 0) {
  double p = 0.0;
  for (size_t i = from; i < x.size(); ++i) p = std::max(p, std::abs(x[i]));
  return p;
}

double largestDifference(const std::vector<double>& a, const std::vector<double>& b,
                         size_t from = 0) {
  double d = 0.0;
  for (size_t i = from; i < a.size(); ++i) d = std::max(d, std::abs(a[i] - b[i]));
  return d;
}

// Plays `modal` and `nodal` (the same patch and strike) block by block until `modal` steps its
// modes; returns false if it never does within 10 s.
bool untilModal(StringVoice& modal, StringVoice& nodal, std::vector<double>& a,
                std::vector<double>& b) {
  for (int i = 0; i < 10 * 750 && !modal.inModes(); ++i) {
    block(modal, a);
    block(nodal, b);
  }
  return modal.inModes();
}

// untilModal, then `seconds` more of both; returns where in a and b `modal` went into its modes,
// or 0 if it never did.
size_t modalFor(StringVoice& modal, StringVoice& nodal, std::vector<double>& a,
                std::vector<double>& b, int seconds) {
  if (!untilModal(modal, nodal, a, b)) return 0;
  const size_t switched = a.size();
  for (int i = 0; i < seconds * 750; ++i) {
    block(modal, a);
    block(nodal, b);
  }
  return switched;
}

// `voice` prepared with `patch` for `note`, struck at `velocity` and played until it steps its
// modes; false if it never does within 10 s.
bool struckIntoModes(StringVoice& voice, const StringPatch& patch, int note, double velocity) {
  voice.prepare(patch, note, kRate);
  voice.noteOn(velocity);
  std::vector<double> out;
  for (int i = 0; i < 10 * 750 && !voice.inModes(); ++i) block(voice, out);
  return voice.inModes();
}

// With no mode dropped, the modes are the scheme's linear string in another basis: the two voices
// agree to the bit until the switch (the check comes after a step's pickups), then to roundoff —
// the transform's, and each step's sums taken in another order, which two stable recursions carry
// on at most linearly: over 48000 steps of M ≤ 224 modes, about 48000 × 224 × 1e-16 ≈ 1e-9 of
// the output at the most, and much less as the loss damps it — under the output's own rounding to
// float, 2^-24 of a sample on each side. C2 (v on coarse cells), C4 and C6 (one coarse cell: no
// v), a second after the switch.
TEST(ModalTail, IsTheSchemesLinearStringToRoundoff) {
  for (int note : {36, 60, 84}) {
    StringVoice modal, nodal;
    modal.prepare(piano(note), note, kRate);
    nodal.prepare(piano(note), note, kRate);
    modal.setModalTail(true, 0.0);
    nodal.setModalTail(false);
    modal.noteOn(0.5);
    nodal.noteOn(0.5);
    std::vector<double> a, b;
    ASSERT_TRUE(untilModal(modal, nodal, a, b)) << "note " << note << " never went modal";
    EXPECT_EQ(a, b) << "note " << note << " differs before its modes";
    ASSERT_TRUE(nodal.linear());
    const size_t switched = a.size();
    for (int i = 0; i < 750; ++i) {
      block(modal, a);
      block(nodal, b);
    }
    ASSERT_TRUE(modal.inModes());
    EXPECT_EQ(modal.modalTail().keptTransverse(), modal.segments() - 1);  // floor 0: all kept
    const double scale = peak(b, switched);
    const double difference = largestDifference(a, b, switched);
    const double energy = nodal.energy();
    std::printf("note %d: modes from %.2f s; a second on, output %.2e, energy %.2e of the nodes'\n",
                note, static_cast<double>(switched) / (2 * kRate), difference / scale,
                std::abs(modal.energy() - energy) / energy);
    EXPECT_LE(difference, (1e-9 + 0x1p-23) * scale) << "note " << note;
    EXPECT_NEAR(modal.energy(), energy, 1e-9 * energy) << "note " << note;
  }
}

// What the string's step reads of itself through the modes — the hammer's contact, the bridge's
// pull, v's end tension — is what it would read off its nodes: the modes written back (levels()).
TEST(ModalTail, ItsProbesReadWhatTheNodesWould) {
  for (int note : {36, 84}) {
    StringVoice voice;
    ASSERT_TRUE(struckIntoModes(voice, piano(note), note, 0.5));
    std::vector<double> a;
    for (int i = 0; i < 100; ++i) block(voice, a);
    ASSERT_TRUE(voice.inModes());
    const auto [q, qNext] = voice.levels();
    const HammeredString& system = voice.scheme().system();
    const double u = q.head(system.string().transverseSize()).cwiseAbs().maxCoeff();
    const double w = 1e-6;  // m: the bridge somewhere near the string's end
    EXPECT_NEAR(voice.modalTail().at(ModalTail::kContact), system.contactDisplacement(q),
                1e-12 * u);
    const BridgeCoupling& c = voice.coupling();
    // With the dropped modes' static give (residual()), which the nodes written back lack.
    EXPECT_NEAR(voice.pullOnBridge(w), c.forceOnBridge(q, w) + voice.modalTail().residual() * w,
                1e-12 * (std::abs(c.lastWeight()) + std::abs(c.secondWeight())) * u);
    const double end = system.string().linearEndTension(q);
    EXPECT_NEAR(voice.endTension(), end, 1e-9 * std::abs(end) + 1e-15) << "note " << note;
  }
}

// A non-finite force on the modes (a runaway bridge, which the guard then resets) leaves nothing
// for the next time the string takes its modes: entering sets the padding past the last mode to
// zero again, where the step had left 0 · NaN (C4: 58 modes, 6 of padding to a register).
TEST(ModalTail, ANonFiniteStepLeavesNothingForTheNextEntry) {
  StringVoice voice;
  ASSERT_TRUE(struckIntoModes(voice, piano(60), 60, 0.5));
  ModalTail tail = voice.modalTail();
  const auto [q, qNext] = voice.levels();
  tail.step(std::numeric_limits<double>::quiet_NaN());
  tail.enter(q, qNext);
  tail.step(0.0);
  for (int p = 0; p < ModalTail::kProbes; ++p)
    EXPECT_TRUE(std::isfinite(tail.atNext(static_cast<ModalTail::Probe>(p)))) << "probe " << p;
}

// The floor drops the highest modes as they fall under 1e-10 of the string's energy, counted as
// removed energy: C3 a few seconds into its tail keeps under half its modes, and its output is
// that of all its modes within 1e-4 of the tail's peak — what the dropped modes held is under
// −100 dB of the energy, a part in 1e5 of the amplitude, here summed over the drops and both
// pickups.
TEST(ModalTail, DropsOnlyWhatLiesUnderItsFloor) {
  StringVoice floored, every;
  floored.prepare(piano(48), 48, kRate);
  every.prepare(piano(48), 48, kRate);
  every.setModalTail(true, 0.0);
  floored.noteOn(0.5);
  every.noteOn(0.5);
  std::vector<double> a, b;
  const size_t switched = modalFor(floored, every, a, b, 3);
  ASSERT_GT(switched, 0u);
  ASSERT_TRUE(floored.inModes());
  const int kept = floored.modalTail().keptTransverse(), modes = floored.segments() - 1;
  const double difference = largestDifference(a, b, switched) / peak(b, switched);
  std::printf("C3 3 s into its modes: %d of %d modes kept; output within %.2e of all modes'\n",
              kept, modes, difference);
  EXPECT_LT(kept, modes / 2);
  EXPECT_LE(difference, 1e-4);
  EXPECT_GT(floored.removedEnergy(), every.removedEnergy());
}

// Under the live tail (the player under load) the floor is −80 dB: C2 with the live tail, against
// the same with every mode kept, 1 s into its modes. It keeps fewer modes than the −100 dB floor
// would keep of the same string now (40 and 48 of 224), and its output is that of all its modes
// within 1e-3 of the tail's peak (1.1e-4): a part in 1e4 of the amplitude per drop, summed over
// the drops and both pickups, as the −100 dB floor's is within 2e-5 above. Every mode kept (a
// floor of 0) stays so under the live tail.
TEST(ModalTail, UnderLoadItsFloorIsMinus80dB) {
  StringVoice live, every;
  for (StringVoice* v : {&live, &every}) {
    v->prepare(piano(36), 36, kRate);
    v->setLiveTail(true);
    v->noteOn(0.5);
  }
  every.setModalTail(true, 0.0);
  std::vector<double> a, b;
  const size_t switched = modalFor(live, every, a, b, 1);
  ASSERT_GT(switched, 0u);
  ASSERT_TRUE(live.inModes());
  const int modes = live.segments() - 1;
  EXPECT_EQ(every.modalTail().keptTransverse(), modes);
  ModalTail quieter = every.modalTail();
  quieter.truncate(kModalFloor);
  const int kept = live.modalTail().keptTransverse();
  const double difference = largestDifference(a, b, switched) / peak(b, switched);
  std::printf(
      "C2 live, 1 s into its modes: %d of %d modes kept (%d at -100 dB); output within "
      "%.2e of all modes'\n",
      kept, modes, quieter.keptTransverse(), difference);
  EXPECT_LT(kept, quieter.keptTransverse());
  EXPECT_LE(difference, 1e-3);
}

// On a key's bridge the floor drops modes that the bridge's force holds statically: C2's three
// strings with the live tail (its threshold and its −80 dB floor), the floor on against every mode
// kept, 1 to 5 s into their tails. Without their static give (ModalTail::residual()) the dropped
// modes stiffen each string's end (by up to 4e4 N/m against the bridge's 1.1e5 at the −100 dB
// floor), and the key's output moved by 1.2e-1 of its peak here (2.5e-2 at −100 dB); with it, by
// 3.7e-4 (2.7e-5): what is left is the dropped modes' dynamics, which lie octaves above where the
// bridge moves. The bound, 1e-3, is over a hundred times under the error without it.
TEST(ModalTail, OnTheBridgeTheDroppedModesKeepTheirStaticGive) {
  const Instrument piano = loadPreset(HAMILTONE_SOURCE_DIR "/presets/grand-piano.toml");
  UnisonStrings floored, every;
  for (UnisonStrings* key : {&floored, &every}) {
    key->prepare(piano, 36, kRate, 256);
    key->setLiveTail(true);
  }
  for (StringVoice& s : every.strings()) s.setModalTail(true, 0.0);
  floored.noteOn(0.3, false);
  every.noteOn(0.3, false);
  std::vector<float> l(256), r(256), l2(256), r2(256);
  double worst = 0.0, peakAfter = 0.0;
  int kept = 0, modes = 0;
  for (int n = 0; n < 5 * 188; ++n) {
    floored.process(l, r);
    every.process(l2, r2);
    if (n < 188) continue;  // the first second: the strings go linear and into their modes
    for (size_t i = 0; i < l.size(); ++i) {
      worst = std::max(worst, std::abs(double{l[i]} - l2[i]));
      peakAfter = std::max(peakAfter, std::abs(double{l2[i]}));
    }
  }
  for (const StringVoice& s : floored.strings()) {
    ASSERT_TRUE(s.inModes());
    kept += s.modalTail().keptTransverse();
    modes += s.segments() - 1;
  }
  std::printf("C2 on its bridge, 1-5 s: %d of %d modes kept; output within %.2e of all modes'\n",
              kept, modes, worst / peakAfter);
  EXPECT_LT(kept, 2 * modes / 3);
  EXPECT_LE(worst, 1e-3 * peakAfter);
}

// The pickups' gain is an output scale alone: a key whose strings have twice the gain gives twice
// the samples, exactly (a product by 2 is exact), on both channels, on its nodes and in its modes —
// the step of a string in its modes reads its pickups apart from the scheme's (stepOnBridge).
TEST(ModalTail, ThePickupsGainScalesBothChannelsInTheModes) {
  const Instrument piano = loadPreset(HAMILTONE_SOURCE_DIR "/presets/grand-piano.toml");
  Instrument louder = piano;
  for (StringKey& key : louder.keys) key.patch.gain *= 2.0;
  UnisonStrings once, twice;
  once.prepare(piano, 60, kRate, 256);
  twice.prepare(louder, 60, kRate, 256);
  ASSERT_EQ(once.channels(), 2);
  once.noteOn(0.5, false);
  twice.noteOn(0.5, false);
  std::vector<float> l(256), r(256), l2(256), r2(256);
  int mismatched = 0, blocksInModes = 0;
  float peakInModes[2] = {0.0f, 0.0f};  // both channels sound there: 0 = 2·0 would prove nothing
  for (int n = 0; n < 3 * 188; ++n) {
    once.process(l, r);
    twice.process(l2, r2);
    const bool inModes = once.stringsInModes() == 3;
    for (size_t i = 0; i < l.size(); ++i) {
      mismatched += (l2[i] != 2.0f * l[i]) + (r2[i] != 2.0f * r[i]);
      if (inModes) {
        peakInModes[0] = std::max(peakInModes[0], std::abs(l[i]));
        peakInModes[1] = std::max(peakInModes[1], std::abs(r[i]));
      }
    }
    blocksInModes += inModes;
  }
  EXPECT_EQ(mismatched, 0);
  EXPECT_GT(blocksInModes, 188);  // a second of it with every string in its modes
  EXPECT_GT(peakInModes[0], 1e-4f);
  EXPECT_GT(peakInModes[1], 1e-4f);
}

// A lossless C3 on a lossless, upright bridge (every loss and the bridge's angle set off over the
// grand piano): what it holds — strings, couplings, bridge — plus what its strings' back-checks and
// dropped modes removed, less what strikes and switches injected, stays constant to roundoff
// through the strike, the linear switch, the modes, their drops (at a floor of 1e-4, so that a
// lossless string drops some) and their change of the coupling's self-stiffness, and the
// restoring of every mode when the key is struck again.
TEST(ModalTail, TheBridgedKeysEnergyAccountStaysExact) {
  PresetOptions options{.checkVoices = false};
  for (const char* name : {"loss.t60_low_s", "loss.t60_high_s", "loss.longitudinal_t60_low_s",
                           "loss.longitudinal_t60_high_s"})
    options.overrides.push_back({name, "inf"});
  options.overrides.push_back({"bridge.resistance_kg_s", "0"});
  options.overrides.push_back({"bridge.angle_deg", "0"});
  const Instrument piano = loadPreset(HAMILTONE_SOURCE_DIR "/presets/grand-piano.toml", options);
  UnisonStrings key;
  key.prepare(piano, 48, kRate, 256);
  key.setLiveTail(true);
  for (StringVoice& s : key.strings()) s.setModalTail(true, 1e-4);
  auto account = [&] {
    double removed = 0.0;
    for (const StringVoice& s : key.strings()) removed += s.removedEnergy();
    return key.energy() + removed - key.injectedEnergy();
  };
  key.noteOn(0.1, false);
  std::vector<float> l(256), r(256);
  double worst = 0.0, scale = 0.0;
  bool dropped = false;
  for (int n = 0; n < 3 * 188; ++n) {
    if (n == 2 * 188) {
      for (const StringVoice& s : key.strings()) ASSERT_TRUE(s.inModes());
      key.noteOn(0.1, true);  // una corda: the missed string keeps its modes, every one of them
    }
    key.process(l, r);
    scale = std::max(scale, key.injectedEnergy());
    worst = std::max(worst, std::abs(account()));
    for (const StringVoice& s : key.strings())
      dropped = dropped || (s.inModes() && s.modalTail().keptTransverse() < s.segments() - 1);
  }
  EXPECT_TRUE(dropped);
  EXPECT_LE(worst, 1e-10 * scale);
}

// A bend retunes the modes and the bridge's pull at once: after it, what the string pulls the
// bridge with is what its nodes would pull with (the pull's weights change with the tension).
TEST(ModalTail, ABendReachesThePullAtOnce) {
  StringPatch patch = piano(48);
  patch.bendRange = 2.0;
  StringVoice voice;
  ASSERT_TRUE(struckIntoModes(voice, patch, 48, 0.5));
  voice.setBend(1.0);
  ASSERT_TRUE(voice.inModes());
  const auto [q, qNext] = voice.levels();
  const double u = q.head(voice.segments() - 1).cwiseAbs().maxCoeff();
  const BridgeCoupling& c = voice.coupling();
  const double w = 1e-6;
  const double residual = voice.modalTail().residual();
  EXPECT_NEAR(voice.pullOnBridge(w), c.forceOnBridge(q, w) + residual * w,
              1e-12 * (std::abs(c.lastWeight()) + std::abs(c.secondWeight())) * u);
  EXPECT_NEAR(voice.couplingEnergy(w, 2.0 * w),
              c.energy(q, qNext, w, 2.0 * w) - 0.5 * residual * 2.0 * w * w,
              1e-12 * (std::abs(c.lastWeight()) + std::abs(c.secondWeight())) * u * w);
}

// The fundamental's T60 of a lossless C3 with a 0.3 s uniform damper released while it steps its
// modes: the damper's σ0 reaches the modes' recursions (within 5 %, as on the nodes:
// StringVoice.DamperShortensTheDecayToItsT60), and the string stays in them.
TEST(ModalTail, AUniformDamperDampsTheModes) {
  StringPatch patch = piano(48);
  patch.t60Low = patch.t60High = INFINITY;
  patch.damperT60 = 0.3;
  StringVoice voice;  // pianissimo: lossless, only a soft strike falls under the threshold
  ASSERT_TRUE(struckIntoModes(voice, patch, 48, 0.05));
  voice.release();
  ASSERT_TRUE(voice.inModes());
  const double k = 1.0 / kRate;
  const double omega =
      2.0 * std::numbers::pi * schemePartial(voice.scheme().system().string(), k, 1);
  std::vector<double> a, t, logE;
  for (int i = 0; i < 0.12 * 750; ++i) {  // 0.12 s: 40 % of the T60, as the nodes' test
    block(voice, a);
    const auto [q, qNext] = voice.levels();
    const double amplitude = testing::modalAmplitude(q, voice.segments(), 1);
    const double rate = (testing::modalAmplitude(qNext, voice.segments(), 1) - amplitude) / k;
    t.push_back(i * kBlock / kRate);
    logE.push_back(std::log(rate * rate + omega * omega * amplitude * amplitude));
  }
  EXPECT_TRUE(voice.inModes());
  const double t60 = 2.0 * 6.907755278982137 / -testing::leastSquaresSlope(t, logE);
  EXPECT_NEAR(t60, 0.3, 0.05 * 0.3);
}

// The modes give the string back to its nodes where the scheme has what they lack: a strike (the
// hammer's and V''s gradients), a felt damper's dashpots on the nodes under it, or the modal tail
// turned off; each time with the energy account kept (the switch counted as injected, as the
// linear tail's own switches are).
TEST(ModalTail, LeavesItsModesWhereTheNodesAreNeeded) {
  StringPatch patch = piano(48);
  patch.feltDamper = true;
  for (int how = 0; how < 3; ++how) {
    StringVoice voice;
    ASSERT_TRUE(struckIntoModes(voice, patch, 48, 0.5));
    const double before = voice.energy();
    if (how == 0) voice.noteOn(0.5);
    if (how == 1) voice.release();
    if (how == 2) voice.setModalTail(false);
    EXPECT_FALSE(voice.inModes()) << "case " << how;
    if (how != 0) {
      // Leaving changes H only by the roundoff of the transform back, and it is counted.
      EXPECT_NEAR(voice.energy(), before, 1e-9 * before) << "case " << how;
      std::vector<double> a;
      for (int i = 0; i < 8; ++i) block(voice, a);  // past a check: stays on the nodes
      EXPECT_FALSE(voice.inModes()) << "case " << how;
    } else {
      EXPECT_FALSE(voice.linear());
    }
  }
  // Without the felt, a release is a σ0 and the modes keep the string (above).
  patch.feltDamper = false;
  StringVoice voice;
  ASSERT_TRUE(struckIntoModes(voice, patch, 48, 0.5));
  voice.release();
  EXPECT_TRUE(voice.inModes());
}

}  // namespace
}  // namespace hamiltone
