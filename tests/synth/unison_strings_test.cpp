// A key's unison strings on the bridge of the grand piano: the fundamental decays in two stages
// (Weinreich), una corda's missed string rings through the bridge, a tilted bridge is pushed
// towards the board by the strike's tension pulse, and a bridge too light for the explicit
// coupling is refused naming its field.
#include "synth/unison_strings.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <span>
#include <vector>

#include "instruments/piano_scale.h"
#include "presets/preset_loader.h"
#include "support/spectrum.h"
#include "support/test_instruments.h"

namespace hamiltone {
namespace {

constexpr double kRate = 48000.0;
constexpr int kBlock = 256;

Instrument grandPiano() {
  return loadPreset(HAMILTONE_SOURCE_DIR "/presets/grand-piano.toml", {.checkVoices = false});
}

// The key's left channel for `seconds`.
std::vector<float> play(UnisonStrings& key, double seconds) {
  std::vector<float> left, l(kBlock), r(kBlock);
  while (left.size() < seconds * kRate) {
    key.process(l, r);
    left.insert(left.end(), l.begin(), l.end());
  }
  return left;
}

// The level (dB) of the partial at `hz` in 100 ms windows (Goertzel's single-bin DFT).
std::vector<double> partialLevel(const std::vector<float>& x, double hz) {
  const size_t window = kRate / 10;
  std::vector<double> db;
  for (size_t start = 0; start + window <= x.size(); start += window) {
    double re = 0.0, im = 0.0;
    for (size_t i = 0; i < window; ++i) {
      const double phase = 2.0 * std::numbers::pi * hz * static_cast<double>(i) / kRate;
      re += x[start + i] * std::cos(phase);
      im += x[start + i] * std::sin(phase);
    }
    db.push_back(10.0 * std::log10(re * re + im * im + 1e-300));
  }
  return db;
}

// dB/s from t0 to t1: the least-squares slope of the level in 100 ms windows, each window's
// power first averaged with its neighbours over `smooth` seconds (the unisons beat, a few seconds
// a period in the aftersound: the mean over the beats is what decays).
double decay(const std::vector<double>& db, double t0, double t1, double smooth) {
  const int half = static_cast<int>(std::lround(smooth * 5.0));
  double st = 0.0, sy = 0.0, stt = 0.0, sty = 0.0;
  int n = 0;
  for (int i = static_cast<int>(std::lround(t0 * 10.0)); i <= std::lround(t1 * 10.0); ++i) {
    double power = 0.0;
    int count = 0;
    for (int j = std::max(0, i - half); j <= std::min<int>(db.size() - 1, i + half); ++j, ++count)
      power += std::pow(10.0, db[j] / 10.0);
    const double t = i / 10.0, y = 10.0 * std::log10(power / count);
    st += t, sy += y, stt += t * t, sty += t * y, ++n;
  }
  return -(n * sty - st * sy) / (n * stt - st * st);
}

// C4's three strings struck together: the fundamental first drains faster than a single string on
// the same bridge does (about three times: the in-phase prompt sound), then, once the part of the
// motion that the detune and the hammer's unequal shares put out of phase is all that is left,
// slower than the single string (the aftersound, which hardly moves the bridge).
TEST(UnisonStrings, OnTheBridgeTheFundamentalDecaysInTwoStages) {
  Instrument piano = grandPiano();
  UnisonStrings key;
  key.prepare(piano, 60, kRate, kBlock);
  ASSERT_TRUE(key.bridged());
  ASSERT_EQ(key.size(), 3u);
  key.noteOn(0.7);
  const std::vector<double> db = partialLevel(play(key, 8.0), key.fundamentalHz());
  const double prompt = decay(db, 0.1, 0.9, 0.0), after = decay(db, 2.5, 7.5, 1.0);
  piano.keys[60 - piano.lowestNote].unisons = 1;
  UnisonStrings one;
  one.prepare(piano, 60, kRate, kBlock);
  one.noteOn(0.7);
  const double single = decay(partialLevel(play(one, 4.0), one.fundamentalHz()), 0.5, 3.5, 0.0);
  std::printf(
      "C4 fundamental: prompt %.1f dB/s, aftersound %.1f dB/s; one string alone %.1f dB/s\n",
      prompt, after, single);
  EXPECT_GT(prompt, 2.0 * single);
  EXPECT_LT(after, 0.5 * single);
  EXPECT_EQ(key.guardEvents(), 0);
}

// The bridge pulls a key's strings flat where it is stiff against their wave impedance — a bass
// key with two or three strings by 2 to 3 cents (F1, C2) — and the tuning raises each string by
// bridgeLoadCents, the first-order shift of the in-phase mode (tan ε = i Z0 n/Z_b at the bridge
// end). With the detune at 0, so that only that mode sounds, the struck fundamental over 0.2–1.7 s
// must sit where the same strings on rigid ends put it (the string's own tuning and soft glide,
// +0.3 cents at A0, are not the bridge's) within a third of the shift corrected — the neglected
// terms, second order in Z0 n/|Z_b| and the grid's, are much less.
TEST(UnisonStrings, OnTheBridgeTheKeysStillPlayTheirNotes) {
  Instrument piano = grandPiano();
  for (const int note : {21, 29, 36}) {
    StringKey& spec = piano.keys[note - piano.lowestNote];
    spec.detuneCents = 0.0;
    const double hz = equalTemperament(note, spec.patch.a4Hz);
    const double corrected = -bridgeLoadCents(spec, hz);
    auto centsOff = [&] {
      UnisonStrings key;
      key.prepare(piano, note, kRate, kBlock);
      key.noteOn(0.3);
      const std::vector<float> take = play(key, 1.7);
      const std::vector<double> steady(take.begin() + static_cast<long>(0.2 * kRate), take.end());
      return 1200.0 * std::log2(testing::peakFrequency(steady, hz, kRate) / hz);
    };
    const double bridged = centsOff();
    spec.bridge.mass = 0.0;  // rigid ends
    const double rigid = centsOff();
    std::printf(
        "note %d: the bridge's pull %+.2f cents corrected; %+.2f on it, %+.2f on rigid ends\n",
        note, -corrected, bridged, rigid);
    EXPECT_LT(std::abs(bridged - rigid), corrected / 3.0) << note;
  }
}

// With una corda the hammer misses the first string; on the bridge that string still rings,
// driven by its neighbours' pull — on rigid ends it stays at rest.
TEST(UnisonStrings, UnaCordaMissedStringRingsThroughTheBridge) {
  for (const bool bridged : {true, false}) {
    Instrument piano = grandPiano();
    if (!bridged) piano.keys[60 - piano.lowestNote].bridge = {};
    UnisonStrings key;
    key.prepare(piano, 60, kRate, kBlock);
    key.noteOn(0.7, /*unaCorda=*/true);
    play(key, 0.5);
    const double missed = key.strings()[0].energy();
    const double struck = key.strings()[1].energy() + key.strings()[2].energy();
    if (bridged) {
      EXPECT_GT(missed, 1e-6 * struck);
    } else {
      EXPECT_EQ(missed, 0.0);
    }
  }
}

// Struck again with una corda while still ringing from a released strike: the key lifts every
// damper of its strings, the missed one's too, so that string rings on at its own decay instead
// of dying under the damper it had (it did: −72 dB against −58 for its neighbours, hostile test).
// Rigid ends, so only its own damper acts on it. Measured: its energy −0.9 dB over the 0.5 s
// after the restrike with the damper lifted, −13.7 dB when it stayed down.
TEST(UnisonStrings, UnaCordaLiftsTheMissedStringsDamperToo) {
  Instrument piano = grandPiano();
  piano.keys[60 - piano.lowestNote].bridge = {};
  UnisonStrings key;
  key.prepare(piano, 60, kRate, kBlock);
  key.noteOn(1.0);
  play(key, 0.2);
  key.release(1.0, 1.0);
  play(key, 0.05);
  key.noteOn(1.0, /*unaCorda=*/true);
  play(key, 0.05);
  const double before = key.strings()[0].energy();
  play(key, 0.5);
  const double after = key.strings()[0].energy();
  const double db = 10.0 * std::log10(after / before);
  std::printf("the missed string over 0.5 s after the restrike: %.1f dB\n", db);
  EXPECT_GT(db, -5.0);
}

// The grand piano's strings meet the bridge at 1° (bridge.angle_deg), so a strike's tension pulse
// reaches the board ahead of the transverse wave and pushes it down, towards the board: the force
// the key passes to the board is negative (w positive away from it) well before the transverse
// wave could arrive. On a level bridge it is exactly zero then. C2's strings: L/c_L 0.3 ms, L/c_T
// some 5 ms; the first 2 ms are looked at, and the first sample above 1e-6 of their largest.
TEST(UnisonStrings, TheTiltedBridgeIsPushedTowardsTheBoardFirst) {
  Instrument piano = grandPiano();
  const int c2 = 36;
  std::vector<double> firstSigns;
  for (double angle : {1.0, 0.0}) {
    for (StringKey& key : piano.keys) key.bridge.angle = angle * std::numbers::pi / 180.0;
    UnisonStrings key;
    key.prepare(piano, c2, kRate, 32);
    key.noteOn(1.0);
    std::vector<float> l(32), r(32);
    std::vector<double> force;
    while (force.size() < 0.002 * kRate) {
      key.process(l, r);
      const auto f = key.boardForce();
      force.insert(force.end(), f.begin(), f.end());
    }
    double largest = 0.0;
    for (double f : force) largest = std::max(largest, std::abs(f));
    double first = 0.0;
    for (double f : force)
      if (std::abs(f) > 1e-6 * largest) {
        first = f;
        break;
      }
    firstSigns.push_back(largest > 0.0 ? first : 0.0);
  }
  EXPECT_LT(firstSigns[0], 0.0);  // 1°: down, towards the board
  EXPECT_EQ(firstSigns[1], 0.0);  // level: nothing yet
}

TEST(UnisonStrings, ABridgeTooLightIsRefusedNamingItsField) {
  try {
    loadPreset(HAMILTONE_SOURCE_DIR "/presets/grand-piano.toml",
               {.overrides = {{"bridge.mass_kg", "1e-6"}}});
    FAIL() << "a 1 mg bridge was accepted";
  } catch (const PresetError& e) {
    EXPECT_NE(std::string(e.what()).find("bridge.mass_kg"), std::string::npos) << e.what();
  }
}

// The bridged key's guard looks at its samples as they leave, in float, and silences the key from
// the first one that is not finite, at the same sample whatever the blocks. A gain (beyond the
// presets' range, which a StringPatch alone still takes) that puts the strike's loudest samples,
// finite in double, beyond float's range: before, they left the key as infinities with no guard
// event. Rendered whole in blocks of 256, and after a first block of 10 in blocks of 100, so that
// the guard's sample falls inside a block at a different place in each.
TEST(UnisonStrings, TheGuardSilencesASampleBeyondFloatFromThatSampleWhateverTheBlocks) {
  constexpr double kSeconds = 0.1;
  constexpr size_t kFirst = 10;  // the second rendering's first block
  Instrument piano = grandPiano();
  UnisonStrings measured;
  measured.prepare(piano, 60, kRate, kBlock);
  measured.noteOn(1.0);
  float peak = 0.0f;
  for (float x : play(measured, kSeconds)) peak = std::max(peak, std::abs(x));
  ASSERT_GT(peak, 0.0f);
  // Twice float's largest at the peak: the samples above half of it overflow.
  piano.keys[60 - piano.lowestNote].patch.gain *= 2.0 * std::numeric_limits<float>::max() / peak;
  std::vector<float> out[2];
  for (int b = 0; b < 2; ++b) {
    UnisonStrings key;
    key.prepare(piano, 60, kRate, kBlock);
    key.noteOn(1.0);
    std::vector<float> l(kBlock), r(kBlock);
    while (out[b].size() < kSeconds * kRate) {
      const size_t block = b == 0 ? kBlock : out[b].empty() ? kFirst : 100;
      key.process(std::span(l).first(block), std::span(r).first(block));
      for (size_t i = 0; i < block; ++i) {
        ASSERT_TRUE(std::isfinite(l[i]) && std::isfinite(r[i]));
        out[b].push_back(l[i]);
      }
      for (float f : key.boardForce()) ASSERT_TRUE(std::isfinite(f));
    }
    EXPECT_EQ(key.guardEvents(), 1);
    EXPECT_FALSE(key.active());
  }
  out[1].resize(out[0].size());
  EXPECT_EQ(out[0], out[1]);
  // The guard's sample: sound before it, none from it on; past the second rendering's first block.
  const auto last = std::find_if(out[0].rbegin(), out[0].rend(), [](float x) { return x != 0.0f; });
  ASSERT_NE(last, out[0].rend());
  const long silencedFrom = out[0].rend() - last;
  EXPECT_GT(silencedFrom, static_cast<long>(kFirst));
  EXPECT_LT(silencedFrom, static_cast<long>(kBlock));
}

}  // namespace
}  // namespace hamiltone
