// The preset loader and its parameter table: the bundled presets load as their data say, every
// broken fixture gives exactly its error lines, per-key values follow their anchors, and the
// table is consistent with itself and with the voices' defaults.
#include "presets/preset_loader.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numbers>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "instruments/piano_scale.h"
#include "presets/parameters.h"

namespace hamiltone {
namespace {

using ::testing::AllOf;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::Not;

std::string sourcePath(const std::string& relative) {
  return std::string(HAMILTONE_SOURCE_DIR) + "/" + relative;
}

// The lines of the PresetError that loading `file` throws (none if it loads).
std::vector<std::string> errorsOf(const std::string& file, const PresetOptions& options = {}) {
  try {
    loadPreset(file, options);
  } catch (const PresetError& e) {
    return e.lines;
  }
  return {};
}

std::vector<std::string> errorsOfText(const std::string& text, const PresetOptions& options = {}) {
  try {
    parsePreset(text, "test.toml", options);
  } catch (const PresetError& e) {
    return e.lines;
  }
  return {};
}

// Whether `word` is one of the '|'-separated `choices`.
bool listed(std::string_view choices, std::string_view word) {
  size_t start = 0;
  while (true) {
    const size_t bar = choices.find('|', start);
    if (choices.substr(start, bar - start) == word) return true;
    if (bar == std::string_view::npos) return false;
    start = bar + 1;
  }
}

const std::string kStringHead = "model = \"string\"\nlowest_note = \"C2\"\nhighest_note = \"C4\"\n";

TEST(PresetLoader, BundledPresetsLoadAsTheirDataSay) {
  const Instrument piano = loadPreset(sourcePath("presets/grand-piano.toml"));
  EXPECT_EQ(piano.model, InstrumentModel::string);
  EXPECT_EQ(piano.lowestNote, 21);
  EXPECT_EQ(piano.highestNote, 108);
  ASSERT_EQ(piano.keys.size(), 88u);
  // Data §1.4: single strings A0–E1, bichords F1–A1, trichords from A#1.
  for (int note = 21; note <= 108; ++note)
    EXPECT_EQ(piano.keys[note - 21].unisons, note <= 28 ? 1 : note <= 33 ? 2 : 3) << note;
  EXPECT_DOUBLE_EQ(piano.keys[48 - 21].detuneCents, 2.64);  // data §3.2, C3
  EXPECT_DOUBLE_EQ(piano.keys[48 - 21].patch.damperT60, 0.63);

  const Instrument paper = loadPreset(sourcePath("presets/paper-c3-string.toml"));
  EXPECT_EQ(paper.model, InstrumentModel::string);
  EXPECT_EQ(paper.lowestNote, 42);
  EXPECT_EQ(paper.highestNote, 54);
  for (const StringKey& key : paper.keys) EXPECT_EQ(key.unisons, 1);

  struct PlateRange {
    const char* file;
    int lowest, highest;
  };
  for (const PlateRange& p :
       {PlateRange{"presets/steel-plate.toml", 27, 39}, PlateRange{"presets/gong.toml", 36, 48},
        PlateRange{"presets/thunder-sheet.toml", 36, 40},
        PlateRange{"presets/small-cymbal.toml", 60, 72}}) {
    const Instrument plate = loadPreset(sourcePath(p.file));
    EXPECT_EQ(plate.model, InstrumentModel::plate) << p.file;
    EXPECT_EQ(plate.lowestNote, p.lowest) << p.file;
    EXPECT_EQ(plate.highestNote, p.highest) << p.file;
    EXPECT_EQ(plate.plate.lowestNote, p.lowest) << p.file;
    EXPECT_EQ(plate.plate.highestNote, p.highest) << p.file;
    EXPECT_TRUE(plate.keys.empty()) << p.file;
  }
}

// The preset's anchors are piano_scale.cpp's and interpolate the same way: every key's string
// agrees with pianoString() to roundoff.
TEST(PresetLoader, GrandPianoStringsAreThePianoScale) {
  const Instrument piano = loadPreset(sourcePath("presets/grand-piano.toml"));
  for (int note = 21; note <= 108; ++note) {
    const StringPhysics& got = piano.keys[note - 21].patch.string;
    const StringPhysics want = pianoString(note);
    EXPECT_NEAR(got.length, want.length, 1e-12 * want.length) << note;
    EXPECT_NEAR(got.area, want.area, 1e-12 * want.area) << note;
    EXPECT_NEAR(got.density, want.density, 1e-12 * want.density) << note;
    EXPECT_NEAR(got.tension, want.tension, 1e-12 * want.tension) << note;
    EXPECT_NEAR(got.inertia, want.inertia, 1e-12 * want.inertia) << note;
    EXPECT_EQ(got.young, want.young) << note;
  }
}

TEST(PresetLoader, PaperPresetsHoldThePaperParameters) {
  const Instrument string = loadPreset(sourcePath("presets/paper-c3-string.toml"));
  const StringPhysics& s = string.keys[48 - 42].patch.string;  // BDZ §4.2, C3
  EXPECT_NEAR(s.area, 8.87e-7, 1e-6 * 8.87e-7);
  EXPECT_EQ(s.density, 7850.0);
  EXPECT_EQ(s.length, 1.259);
  EXPECT_EQ(s.young, 2.02e11);
  EXPECT_EQ(s.tension, 759.0);
  EXPECT_EQ(s.inertia, 0.0);

  const Instrument plate = loadPreset(sourcePath("presets/steel-plate.toml"));  // BDZ §4.3.3
  EXPECT_EQ(plate.plate.plate.young, 2e11);
  EXPECT_EQ(plate.plate.plate.density, 7850.0);
  EXPECT_EQ(plate.plate.plate.poisson, 0.3);
  EXPECT_EQ(plate.plate.plate.thickness, 2e-3);
  EXPECT_EQ(plate.plate.plate.lx, 0.5);
  EXPECT_EQ(plate.plate.plate.ly, 0.5);
  EXPECT_EQ(plate.plate.referenceNote, 27);
}

struct Fixture {
  const char* file;
  std::vector<std::string> lines;  // after "<path>:"
};

TEST(PresetLoader, BrokenFixturesGiveExactlyTheirErrors) {
  const std::vector<Fixture> fixtures = {
      {"bad-unknown-key.toml",
       {"7:1: string.tension_n = 759: unknown key; did you mean string.tension_N?"}},
      {"bad-type.toml", {"7:1: hammer.exponent = \"hard\": expected a number"}},
      {"bad-range.toml",
       {"7:1: string.unisons = 4: out of range; expected 1 … 3",
        "11:1: loss.t60_high_s = 50: out of range; expected 0.01 … 20 (loss.t60_low_s)"}},
      {"bad-nonfinite.toml",
       {"5:1: gain_dB = nan: not a finite number",
        "11:1: hammer.mass_kg = inf: not a finite number"}},
      {"bad-unstable.toml",
       {"8:1: string.length_m = 0.02 at C3: shorter than two grid spacings h = "
        "0.01009 m at k = 2.083e-05 s (stiff-string bound (44)); use "
        "a smaller time step (a higher sample rate, or scheme.oversampling)"}},
      {"bad-syntax.toml",
       {"2:16: syntax error: Error while parsing string: unescaped control characters other "
        "than TAB (U+0009) are explicitly prohibited"}},
      {"bad-several.toml",
       {"1:1: highest_note: missing; expected a MIDI note 0 … 127 or a name like \"C4\"",
        "6:1: plate.thickness_m = \"thin\": expected a number",
        "8:2: [hammer]: string model only; this preset's model is \"plate\""}},
  };
  for (const Fixture& f : fixtures) {
    const std::string path = sourcePath(std::string("tests/data/presets/") + f.file);
    std::vector<std::string> want;
    for (const std::string& line : f.lines) want.push_back(path + ":" + line);
    EXPECT_EQ(errorsOf(path), want) << f.file;
  }
}

TEST(PresetLoader, ErrorNamesTheAnchorAndTheModel) {
  EXPECT_THAT(errorsOfText(kStringHead + "[[key]]\nnote = \"C3\"\nhammer.width_m = 0.01\n"),
              ElementsAre("test.toml:6:8: key[C3].hammer.width_m = 0.01: not per-key; set it in "
                          "[hammer]"));
  EXPECT_THAT(errorsOfText(kStringHead + "[[key]]\nnote = \"C3\"\n[[key]]\nnote = 48\n"),
              ElementsAre("test.toml:7:1: key[C3].note = 48: duplicate anchor; C3 is already an "
                          "anchor at line 5"));
  EXPECT_THAT(errorsOfText(kStringHead + "[[key]]\nnote = \"C5\"\n"),
              ElementsAre("test.toml:5:1: key[C5].note = \"C5\": outside lowest_note … "
                          "highest_note, C2 … C4"));
  EXPECT_THAT(errorsOfText(kStringHead + "[[key]]\nstring.length_m = 1\n"),
              ElementsAre("test.toml:4:1: key[1]: missing note; each [[key]] table needs note = "
                          "\"C4\" (or a MIDI number)"));
  EXPECT_THAT(errorsOfText("model = \"plate\"\nlowest_note = 40\nhighest_note = 41\n"
                           "[pickups]\nchannels = 1\n[stirke]\nwidth_m = 1\n"),
              ElementsAre("test.toml:5:1: pickups.channels = 1: string model only; this "
                          "preset's model is \"plate\"",
                          "test.toml:6:2: [stirke]: unknown table; did you mean [strike]?"));
  EXPECT_THAT(errorsOfText("lowest_note = 40\nhighest_note = 41\n"),
              ElementsAre("test.toml:1:1: model: missing; expected \"string\" or \"plate\""));
}

// toml++ 3.3 has undefined behaviour on some non-ASCII characters where TOML expects
// whitespace; the loader refuses them first. Comments and strings may hold any text.
TEST(PresetLoader, NonAsciiOnlyInCommentsAndStrings) {
  EXPECT_THAT(errorsOfText("model = \"string\"\nx = 1 \xC3\xA9\n"),
              ElementsAre("test.toml:2:7: syntax error: a non-ASCII character outside a string or "
                          "comment"));
  EXPECT_THAT(errorsOfText("s = \"\"\"\\\n  \xC2\xA7\"\"\"\n"),
              ElementsAre("test.toml:1:8: syntax error: a non-ASCII character first after a "
                          "line-ending backslash"));
  const Instrument i = parsePreset(
      "# Gong — §4\nname = \"Gong — §4\"\nmodel = \"plate\"\nlowest_note = 40\n"
      "highest_note = 41\n",
      "test.toml");
  EXPECT_EQ(i.name, "Gong — §4");
}

// A parameter's own bound is checked key by key where anchors make it vary.
TEST(PresetLoader, CrossFieldBoundsHoldAtEveryKey) {
  EXPECT_THAT(errorsOfText(kStringHead + "[loss]\nt60_low_s = 5\n[[key]]\nnote = \"C4\"\n"
                                         "loss.t60_high_s = 6\n"),
              ElementsAre("test.toml:8:6: key[C4].loss.t60_high_s = 6: out of range; expected "
                          "0.01 … 5 (loss.t60_low_s at C4)"));
  EXPECT_THAT(errorsOfText(kStringHead + "[hammer]\nvelocity_min_m_s = 8\n"),
              ElementsAre("test.toml:5:1: hammer.velocity_min_m_s = 8: out of range; expected "
                          "at most 6 (hammer.velocity_max_m_s)"));
}

// The dynamics calibration (docs/instrument-data.md §5.4) varies the velocity law and the pickups'
// gain per key: anchors set them, linearly between (their bounds reach 0 or below), held beyond;
// and velocity_max must stay at least velocity_min at every key.
TEST(PresetLoader, VelocityLawAndPickupGainVaryPerKey) {
  const Instrument i = parsePreset(kStringHead +
                                       "[hammer]\nvelocity_curve = 2\n[pickups]\ngain = 0.025\n"
                                       "[[key]]\nnote = \"C2\"\npickups.gain = 0.1\n"
                                       "hammer.velocity_min_m_s = 1.0\n"
                                       "[[key]]\nnote = \"C4\"\npickups.gain = 0.02\n",
                                   "test.toml");
  EXPECT_EQ(i.keys[0].patch.gain, 0.1);
  EXPECT_NEAR(i.keys[48 - 36].patch.gain, 0.06, 1e-15);
  EXPECT_EQ(i.keys[60 - 36].patch.gain, 0.02);
  for (const StringKey& key : i.keys) {
    EXPECT_EQ(key.patch.velocityMin, 1.0);
    EXPECT_EQ(key.patch.velocityMax, 6.0);
    EXPECT_EQ(key.patch.velocityCurve, 2.0);
  }
  EXPECT_THAT(errorsOfText(kStringHead + "[[key]]\nnote = \"C3\"\nhammer.velocity_max_m_s = 0.4\n"),
              ElementsAre(HasSubstr("key[C3].hammer.velocity_max_m_s = 0.4: out of range")));
}

TEST(PresetLoader, AnchorsScaleGeometricallyLinearlyOrStepwise) {
  const Instrument i = parsePreset(kStringHead +
                                       "[string]\nlength_m = 1.5\n"
                                       "[[key]]\nnote = \"C2\"\nstring.length_m = 2.0\n"
                                       "string.detune_cents = 0\nstring.unisons = 1\n"
                                       "[[key]]\nnote = \"C3\"\nstring.detune_cents = 10\n"
                                       "[[key]]\nnote = \"C4\"\nstring.length_m = 0.5\n"
                                       "string.unisons = 3\n",
                                   "test.toml");
  auto key = [&](int note) { return i.keys[note - 36]; };
  EXPECT_NEAR(key(36).patch.string.length, 2.0, 1e-15);
  EXPECT_NEAR(key(48).patch.string.length, 1.0, 1e-15);  // geometric mean of 2 and 0.5
  EXPECT_NEAR(key(42).patch.string.length, std::sqrt(2.0), 1e-15);
  EXPECT_NEAR(key(42).detuneCents, 5.0, 1e-15);   // linear: detune may be 0
  EXPECT_NEAR(key(60).detuneCents, 10.0, 1e-15);  // held beyond the last anchor setting it
  EXPECT_EQ(key(59).unisons, 1);                  // an integer holds from its anchor up
  EXPECT_EQ(key(60).unisons, 3);
  // A parameter no anchor sets keeps the section's value everywhere; so does the density.
  EXPECT_EQ(key(50).patch.string.density, 7850.0);
}

TEST(PresetLoader, LinearDensityMakesTheEquivalentPlainString) {
  const Instrument i = parsePreset(kStringHead +
                                       "[string]\ndiameter_m = 1.48e-3\n"
                                       "linear_density_kg_m = 99.413e-3\n",
                                   "test.toml");
  const StringPhysics& s = i.keys[0].patch.string;
  const double area = std::numbers::pi * 1.48e-3 * 1.48e-3 / 4.0;
  EXPECT_NEAR(s.area, area, 1e-15 * area);
  EXPECT_NEAR(s.linearDensity(), 99.413e-3, 1e-15);  // data §1.5: ρA with the winding
  EXPECT_NEAR(s.inertia, std::numbers::pi * std::pow(1.48e-3, 4) / 64.0, 1e-24);
}

// A file that sets only what is required gets the voices' own defaults.
TEST(PresetLoader, DefaultsAreTheVoicesDefaults) {
  const Instrument s =
      parsePreset("model = \"string\"\nlowest_note = 48\nhighest_note = 48\n", "test.toml");
  const StringPatch& got = s.keys[0].patch;
  const StringPatch want;
  EXPECT_NEAR(got.string.area, want.string.area, 1e-6 * want.string.area);
  EXPECT_EQ(got.string.density, want.string.density);
  EXPECT_EQ(got.string.length, want.string.length);
  EXPECT_EQ(got.string.young, want.string.young);
  EXPECT_EQ(got.string.tension, want.string.tension);
  EXPECT_EQ(got.hammer.mass, want.hammer.mass);
  EXPECT_EQ(got.hammer.stiffness, want.hammer.stiffness);
  EXPECT_EQ(got.hammer.exponent, want.hammer.exponent);
  EXPECT_EQ(got.hammer.position, want.hammer.position);
  EXPECT_EQ(got.hammer.width, want.hammer.width);
  EXPECT_EQ(got.tuneBy, want.tuneBy);
  EXPECT_EQ(got.a4Hz, want.a4Hz);
  EXPECT_EQ(got.grid, want.grid);
  EXPECT_EQ(got.gridFactor, want.gridFactor);
  EXPECT_EQ(got.oversampling, want.oversampling);
  EXPECT_EQ(got.epsilon, want.epsilon);
  EXPECT_EQ(got.t60Low, want.t60Low);
  EXPECT_EQ(got.t60High, want.t60High);
  EXPECT_EQ(got.t60HighHz, want.t60HighHz);
  EXPECT_EQ(got.damperT60, want.damperT60);
  EXPECT_EQ(got.pickups[0], want.pickups[0]);
  EXPECT_EQ(got.pickups[1], want.pickups[1]);
  EXPECT_EQ(got.channels, want.channels);
  EXPECT_EQ(got.signal, want.signal);
  EXPECT_EQ(got.gain, want.gain);
  EXPECT_EQ(got.velocityMin, want.velocityMin);
  EXPECT_EQ(got.velocityMax, want.velocityMax);
  EXPECT_EQ(got.velocityCurve, want.velocityCurve);
  EXPECT_EQ(got.guardEnergyMultiple, want.guardEnergyMultiple);
  EXPECT_EQ(got.bendRange, want.bendRange);
  const Instrument defaults;
  EXPECT_EQ(s.polyphony, defaults.polyphony);
  EXPECT_EQ(s.gainDb, defaults.gainDb);
  EXPECT_EQ(s.panSpread, defaults.panSpread);
  EXPECT_EQ(s.bendRange, defaults.bendRange);
  EXPECT_EQ(s.name, "test");

  const Instrument p =
      parsePreset("model = \"plate\"\nlowest_note = 48\nhighest_note = 50\n", "test.toml");
  const PlatePatch& plate = p.plate;
  const PlatePatch wantPlate;
  EXPECT_EQ(plate.plate.young, wantPlate.plate.young);
  EXPECT_EQ(plate.plate.density, wantPlate.plate.density);
  EXPECT_EQ(plate.plate.poisson, wantPlate.plate.poisson);
  EXPECT_EQ(plate.plate.thickness, wantPlate.plate.thickness);
  EXPECT_EQ(plate.plate.lx, wantPlate.plate.lx);
  EXPECT_EQ(plate.plate.ly, wantPlate.plate.ly);
  EXPECT_EQ(plate.referenceNote, 48);  // the lowest note
  EXPECT_EQ(plate.gridFactor, wantPlate.gridFactor);
  EXPECT_EQ(plate.oversampling, wantPlate.oversampling);
  EXPECT_EQ(plate.t60Low, wantPlate.t60Low);
  EXPECT_EQ(plate.t60High, wantPlate.t60High);
  EXPECT_EQ(plate.t60HighHz, wantPlate.t60HighHz);
  EXPECT_EQ(plate.damperT60, wantPlate.damperT60);
  EXPECT_EQ(plate.strike[0], wantPlate.strike[0]);
  EXPECT_EQ(plate.strike[1], wantPlate.strike[1]);
  EXPECT_EQ(plate.strikeWidth, wantPlate.strikeWidth);
  EXPECT_EQ(plate.forceMax, wantPlate.forceMax);
  EXPECT_EQ(plate.durationMin, wantPlate.durationMin);
  EXPECT_EQ(plate.durationMax, wantPlate.durationMax);
  EXPECT_EQ(plate.velocityCurve, wantPlate.velocityCurve);
  EXPECT_EQ(plate.noteMovesStrike, wantPlate.noteMovesStrike);
  EXPECT_EQ(plate.strikeHigh[0], wantPlate.strikeHigh[0]);
  EXPECT_EQ(plate.strikeHigh[1], wantPlate.strikeHigh[1]);
  for (int c = 0; c < 2; ++c)
    for (int d = 0; d < 2; ++d) EXPECT_EQ(plate.pickups[c][d], wantPlate.pickups[c][d]);
  EXPECT_EQ(plate.signal, wantPlate.signal);
  EXPECT_EQ(plate.gain, wantPlate.gain);
  EXPECT_EQ(plate.guardEnergyMultiple, wantPlate.guardEnergyMultiple);
}

// The longitudinal wave's own law: the bundled pianos carry RT-425's (data §3.1), the paper's C3
// shares the transverse law (unset); set alone, one time stands for both; a law that is no decay
// is refused at its line, naming what would be valid.
TEST(PresetLoader, TheLongitudinalLossLawIsReadAndChecked) {
  for (const char* name : {"presets/grand-piano.toml", "presets/grand-piano-strings.toml"}) {
    const Instrument piano = loadPreset(sourcePath(name));
    EXPECT_EQ(piano.keys.front().patch.longitudinalT60Low, 13.8) << name;
    EXPECT_EQ(piano.keys.back().patch.longitudinalT60High, 6.10) << name;
  }
  const Instrument paper = loadPreset(sourcePath("presets/paper-c3-string.toml"));
  EXPECT_FALSE(paper.keys.front().patch.longitudinalT60Low);
  EXPECT_FALSE(paper.keys.front().patch.longitudinalT60High);
  const Instrument alone =
      parsePreset(kStringHead + "[loss]\nlongitudinal_t60_low_s = 9\n", "test.toml");
  EXPECT_EQ(alone.keys.front().patch.longitudinalT60Low, 9.0);
  EXPECT_FALSE(alone.keys.front().patch.longitudinalT60High);
  EXPECT_THAT(
      errorsOfText(kStringHead +
                   "[loss]\nlongitudinal_t60_low_s = 2\nlongitudinal_t60_high_s = 3\n"),
      ElementsAre("test.toml:6:1: loss.longitudinal_t60_high_s = 3: out of range; expected 0.01 "
                  "… 2 (loss.longitudinal_t60_low_s)"));
  // A voice's refusal names the time's line and the shortest stable time (at 8× oversampling v's
  // coarse grid is 8× finer, and its top modes 8× higher).
  EXPECT_THAT(errorsOfText(kStringHead + "[loss]\nlongitudinal_t60_high_s = 0.01\n" +
                           "longitudinal_t60_low_s = inf\n[scheme]\noversampling = 8\n"),
              ElementsAre(HasSubstr("test.toml:5:1: loss.longitudinal_t60_high_s = 0.01 at C2: "
                                    "must be at least ")));
}

TEST(PresetLoader, VoiceCheckCanBeLeftOut) {
  const std::string path = sourcePath("tests/data/presets/bad-unstable.toml");
  EXPECT_FALSE(errorsOf(path).empty());
  std::ifstream in(path);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_TRUE(errorsOfText(text, {.checkVoices = false}).empty());
}

TEST(PresetLoader, RefusesWhatItCannotRead) {
  EXPECT_THAT(errorsOf(sourcePath("tests/data/presets/no-such-file.toml")),
              ElementsAre(HasSubstr("no-such-file.toml: cannot read: no such file")));
  EXPECT_THAT(errorsOf(sourcePath("tests/data/presets")),
              ElementsAre(HasSubstr("presets: cannot read: not a regular file")));
  EXPECT_THAT(errorsOfText(std::string((1 << 20) + 1, '#')),
              ElementsAre("test.toml: 1048577 bytes: larger than the 1 MiB a preset may be"));
}

// A link to nothing and a loop of links are said as such (both read "no such file").
TEST(PresetLoader, SaysWhatIsWrongWithALink) {
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / "preset-links";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  std::filesystem::create_symlink(dir / "gone.toml", dir / "dangling.toml");
  std::filesystem::create_symlink(dir / "b.toml", dir / "a.toml");
  std::filesystem::create_symlink(dir / "a.toml", dir / "b.toml");
  EXPECT_THAT(errorsOf((dir / "dangling.toml").string()),
              ElementsAre(HasSubstr("dangling.toml: cannot read: a symbolic link to " +
                                    (dir / "gone.toml").string() + ", which does not exist")));
  EXPECT_THAT(errorsOf((dir / "a.toml").string()),
              ElementsAre(HasSubstr("a.toml: cannot read: Too many levels of symbolic links")));
  std::filesystem::remove_all(dir);
}

// 300 unknown keys: 99 lines and one that counts the rest.
TEST(PresetLoader, CapsTheErrorLines) {
  std::string text = kStringHead;
  for (int i = 0; i < 300; ++i) text.append("unknown").append(std::to_string(i)).append(" = 1\n");
  const std::vector<std::string> lines = errorsOfText(text);
  ASSERT_EQ(lines.size(), 100u);
  EXPECT_EQ(lines.back(), "test.toml: … and 201 more errors");
}

// --- --set NAME=VALUE over the file (PresetOptions::overrides) ----------------------------------

std::vector<std::string> errorsWith(const std::string& text, std::vector<PresetOverride> set) {
  return errorsOfText(text, {.overrides = std::move(set)});
}

TEST(PresetOverrides, ArgumentSplitsAtTheFirstEquals) {
  auto split = [](std::string_view argument) {
    const auto o = parseOverride(argument);
    return o ? o->name + "|" + o->value : std::string("none");
  };
  EXPECT_EQ(split("scheme.grid_rule=longitudinal"), "scheme.grid_rule|longitudinal");
  EXPECT_EQ(split(" name = \"a=b\" "), "name|\"a=b\"");
  EXPECT_EQ(split("gain_dB="), "gain_dB|");  // the loader says what the value should be
  EXPECT_EQ(split("scheme.oversampling"), "none");
  EXPECT_EQ(split("=16"), "none");
}

// The grand piano as the bundled file has it, and with the scheme and a hammer setting changed on
// the command line: every key is built with the new values and nothing else moves.
TEST(PresetOverrides, ChangeWhatIsBuilt) {
  const std::string piano = sourcePath("presets/grand-piano.toml");
  const Instrument file = loadPreset(piano);
  ASSERT_EQ(file.keys[0].patch.grid, GridRule::twoGrid);  // else the test shows nothing
  ASSERT_EQ(file.keys[0].patch.oversampling, 1);
  ASSERT_NE(file.keys[0].patch.velocityMax, 4.0);
  const Instrument set = loadPreset(piano, {.overrides = {{"scheme.grid_rule", "longitudinal"},
                                                          {"scheme.oversampling", "16"},
                                                          {"hammer.velocity_max_m_s", "4"},
                                                          {"name", "Piano B"}}});
  EXPECT_EQ(set.name, "Piano B");
  ASSERT_EQ(set.keys.size(), file.keys.size());
  for (size_t i = 0; i < set.keys.size(); ++i) {
    const StringPatch& p = set.keys[i].patch;
    EXPECT_EQ(p.grid, GridRule::longitudinal) << i;
    EXPECT_EQ(p.oversampling, 16) << i;
    EXPECT_EQ(p.velocityMax, 4.0) << i;
    EXPECT_EQ(p.string.tension, file.keys[i].patch.string.tension) << i;
    EXPECT_EQ(p.hammer.mass, file.keys[i].patch.hammer.mass) << i;
  }
}

// The voices are checked at the rate they will play at when it is known: C8 on the longitudinal
// grid is shorter than two of its segments at 48 kHz (h >= c_L k = 0.11 m) and fine at 384 kHz,
// where hamiltone-render refused it all the same (hostile test), quoting 48 kHz's step.
TEST(PresetOverrides, VoicesAreCheckedAtTheRateGiven) {
  const std::string strings = sourcePath("presets/grand-piano-strings.toml");
  const std::vector<PresetOverride> c8 = {{"scheme.grid_rule", "longitudinal"},
                                          {"lowest_note", "C8"}};
  try {
    loadPreset(strings, {.overrides = c8});
    ADD_FAILURE() << "C8 on the longitudinal grid accepted at 48 kHz";
  } catch (const PresetError& e) {
    EXPECT_NE(std::string(e.what()).find("k = 2.083e-05 s"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(loadPreset(strings, {.checkRate = 384000.0, .overrides = c8}));
}

// A word may go without quotes where the row wants a word (choice, text) or a note name; a TOML
// value is read as the file would read it, and quotes still work.
TEST(PresetOverrides, ValuesAreWrittenAsInAFileOrAsBareWords) {
  const Instrument i = parsePreset(kStringHead, "test.toml",
                                   {.overrides = {{"scheme.grid_rule", "\"longitudinal\""},
                                                  {"string.tune_by", "length"},
                                                  {"lowest_note", "C#2"},
                                                  {"highest_note", "40"},
                                                  {"name", "2024"},
                                                  {"loss.t60_low_s", "inf"},
                                                  {"string.bending_stiffness", "false"}}});
  EXPECT_EQ(i.keys[0].patch.grid, GridRule::longitudinal);
  EXPECT_EQ(i.keys[0].patch.tuneBy, TuneBy::length);
  EXPECT_EQ(i.lowestNote, 37);
  EXPECT_EQ(i.highestNote, 40);
  EXPECT_EQ(i.name, "2024");  // text: the number is taken as its word
  EXPECT_EQ(i.keys[0].patch.t60Low, INFINITY);
  EXPECT_EQ(i.keys[0].patch.string.inertia, 0.0);
}

// A per-key parameter set on the command line holds at every key: the [[key]] anchors that set it
// give way, those that set other parameters still shape them.
TEST(PresetOverrides, PerKeyOverrideBeatsTheAnchors) {
  const std::string text = kStringHead +
                           "[string]\nlength_m = 1.5\n"
                           "[[key]]\nnote = \"C2\"\nstring.length_m = 2.0\n"
                           "string.detune_cents = 0\nstring.unisons = 1\n"
                           "[[key]]\nnote = \"C3\"\nstring.detune_cents = 10\n"
                           "[[key]]\nnote = \"C4\"\nstring.length_m = 0.5\nstring.unisons = 3\n";
  const Instrument file = parsePreset(text, "test.toml");
  ASSERT_NEAR(file.keys[48 - 36].patch.string.length, 1.0, 1e-15);  // the anchors' own value
  const Instrument i = parsePreset(
      text, "test.toml", {.overrides = {{"string.length_m", "1.2"}, {"string.unisons", "2"}}});
  for (const StringKey& key : i.keys) {
    EXPECT_EQ(key.patch.string.length, 1.2);
    EXPECT_EQ(key.unisons, 2);
  }
  EXPECT_NEAR(i.keys[42 - 36].detuneCents, 5.0, 1e-15);  // still between its anchors
}

// A file's anchors must lie in its own range; a narrower range set on the command line builds
// those keys only, with the values the anchors beyond it give them.
TEST(PresetOverrides, NarrowerRangeKeepsTheAnchorsBeyondIt) {
  const std::string anchors =
      "[[key]]\nnote = \"C2\"\nstring.length_m = 2.0\n"
      "[[key]]\nnote = \"C4\"\nstring.length_m = 0.5\n";
  EXPECT_THAT(
      errorsOfText("model = \"string\"\nlowest_note = \"C3\"\nhighest_note = \"D3\"\n" + anchors),
      ElementsAre(HasSubstr("key[C2].note = \"C2\": outside lowest_note … highest_note"),
                  HasSubstr("key[C4].note = \"C4\": outside lowest_note … highest_note")));
  const Instrument i = parsePreset(kStringHead + anchors, "test.toml",
                                   {.overrides = {{"lowest_note", "C3"}, {"highest_note", "D3"}}});
  ASSERT_EQ(i.keys.size(), 3u);
  EXPECT_NEAR(i.keys[0].patch.string.length, 1.0, 1e-15);  // geometric mean of 2 and 0.5
}

// Each kind of bad value gets the file's message, the --set named in place of LINE:COL.
TEST(PresetOverrides, BadOverridesAreRefusedNamingTheSet) {
  const struct {
    PresetOverride set;
    const char* line;
  } cases[] = {
      {{"scheme.oversampling", "3"},
       "test.toml: --set scheme.oversampling=3: expected one of 1, 2, 4, 8, 16, 32, 64"},
      {{"string.unisons", "4"}, "test.toml: --set string.unisons=4: out of range; expected 1 … 3"},
      {{"hammer.mass_kg", "heavy"}, "test.toml: --set hammer.mass_kg=heavy: expected a number"},
      {{"gain_dB", "nan"}, "test.toml: --set gain_dB=nan: not a finite number"},
      {{"scheme.grid_rule", "diagonal"},
       "test.toml: --set scheme.grid_rule=diagonal: expected one of \"two-grid\", "
       "\"transverse\", \"longitudinal\""},
      {{"string.bending_stiffness", "yes"},
       "test.toml: --set string.bending_stiffness=yes: expected true or false"},
      {{"lowest_note", "H2"},
       "test.toml: --set lowest_note=H2: expected a MIDI note 0 … 127 or a name like \"C4\""},
      {{"scheme.oversampeling", "16"},
       "test.toml: --set scheme.oversampeling=16: unknown key; did you mean scheme.oversampling?"},
      {{"plate.lx_m", "1"},
       "test.toml: --set plate.lx_m=1: plate model only; this preset's model is \"string\""},
      {{"key.note", "C3"}, "test.toml: --set key.note=C3: unknown key"},
      {{"model", "plate"},
       "test.toml: --set model=plate: the model cannot be set; it decides what the file's other "
       "keys mean (load a preset of that model instead)"},
      // One value only: what follows a newline is part of the text, not another key.
      {{"gain_dB", "1\nmodel = \"plate\""},
       "test.toml: --set gain_dB=1?model = \"plate\": expected a number"},
  };
  for (const auto& c : cases)
    EXPECT_THAT(errorsWith(kStringHead, {c.set}), ElementsAre(c.line)) << c.set.name;
}

// The bound one parameter sets another blames the --set that broke it, whichever side it is on.
TEST(PresetOverrides, CrossFieldBoundsBlameTheSet) {
  const std::string text = kStringHead + "[loss]\nt60_low_s = 5\nt60_high_s = 1\n";
  EXPECT_THAT(errorsWith(text, {{"loss.t60_high_s", "50"}}),
              ElementsAre("test.toml: --set loss.t60_high_s=50: out of range; expected 0.01 … 5 "
                          "(loss.t60_low_s)"));
  EXPECT_THAT(errorsWith(text, {{"loss.t60_low_s", "0.5"}}),
              ElementsAre("test.toml: --set loss.t60_low_s=0.5: out of range; expected at least 1 "
                          "(loss.t60_high_s)"));
}

// The file's own errors come first, in file order, then the --set ones in the order given.
TEST(PresetOverrides, ErrorsListTheFileThenEachSetInOrder) {
  EXPECT_THAT(errorsWith(kStringHead + "bogus = 1\n", {{"polyphony", "0"}, {"gain_dB", "x"}}),
              ElementsAre("test.toml:4:1: bogus = 1: unknown key",
                          "test.toml: --set polyphony=0: out of range; expected 1 … 128",
                          "test.toml: --set gain_dB=x: expected a number"));
}

// A felt wider than the string has room for at its strike point (2 min(x0, L − x0)) is refused
// where the string is too short for it: grand-piano's top keys with a 2 cm felt, each line naming
// the --set and the key; 1.1 cm fits them all (C8: 4.98 cm struck at 0.12, room for 1.2 cm).
TEST(PresetOverrides, AFeltWiderThanItsStringIsRefused) {
  const std::string piano = sourcePath("presets/grand-piano.toml");
  const std::vector<std::string> lines =
      errorsOf(piano, {.overrides = {{"hammer.width_m", "0.02"}}});
  ASSERT_FALSE(lines.empty());
  for (const std::string& line : lines)
    EXPECT_THAT(line, AllOf(HasSubstr("--set hammer.width_m=0.02 at "),
                            HasSubstr("so that the felt lies on the")));
  // The first key without room is D#7 (8.06 cm: room for 1.93 cm); the lines go up from there.
  EXPECT_THAT(lines.front(),
              HasSubstr("at D#7: must be under 2 min(x0, L - x0) = 0.01934 m, so "
                        "that the felt lies on the 0.08059 m string struck at 0.12"));
  EXPECT_NO_THROW(loadPreset(piano, {.overrides = {{"hammer.width_m", "0.011"}}}));
}

// A bridge so light that its load pulls the strings out of what the tuning takes out was refused
// as a detune_cents the preset never set (-205 cents on paper-c3-string's F#2 at 10 g): the message
// now names the bridge's fields, the load, and a mass that would do; 5e-324 kg too, whose load
// is no number of cents, and whose search for that mass never ended (5 % of a denormal rounds to
// it).
TEST(PresetOverrides, ABridgeTooLightToTuneIsRefusedNamingTheBridge) {
  const std::string paper = sourcePath("presets/paper-c3-string.toml");
  for (const char* mass : {"0.01", "5e-324"}) {
    const std::vector<std::string> lines =
        errorsOf(paper, {.overrides = {{"bridge.mass_kg", mass}}});
    ASSERT_FALSE(lines.empty()) << mass;
    for (const std::string& line : lines)
      EXPECT_THAT(line, AllOf(HasSubstr("bridge.mass_kg = "), HasSubstr("the bridge's load moves"),
                              HasSubstr("expected a heavier bridge (bridge.mass_kg >= "),
                              Not(HasSubstr("detune_cents"))))
          << mass;
  }
  EXPECT_THAT(errorsOf(paper, {.overrides = {{"bridge.mass_kg", "0.01"}}}).front(),
              HasSubstr("moves the strings' pitch by 205.3 cents"));
  EXPECT_NO_THROW(loadPreset(paper, {.overrides = {{"bridge.mass_kg", "0.05"}}}));
}

// A value out of its own range names the parameter that bounds it too: loss.t60_high_s = −1 read
// "expected 0.01 … inf", though it must be at most loss.t60_low_s as well.
TEST(PresetOverrides, ARangeNamesTheParameterThatBoundsItToo) {
  EXPECT_THAT(errorsOf(sourcePath("presets/paper-c3-string.toml"),
                       {.overrides = {{"loss.t60_high_s", "-1"}}}),
              ElementsAre(HasSubstr("expected 0.01 … inf, and at most loss.t60_low_s")));
}

// A grid the string cannot have (the longitudinal rule at the base rate makes h longer than the
// treble strings) is the voices' refusal: each line names the setting the voice names and every
// --set it was built with.
TEST(PresetOverrides, VoiceCheckNamesTheSets) {
  const std::string piano = sourcePath("presets/grand-piano.toml");
  const std::vector<std::string> lines =
      errorsOf(piano, {.overrides = {{"scheme.grid_rule", "longitudinal"}}});
  ASSERT_FALSE(lines.empty());
  for (const std::string& line : lines) {
    EXPECT_THAT(line, HasSubstr("shorter than two grid spacings"));
    EXPECT_THAT(line, HasSubstr("(with --set scheme.grid_rule=longitudinal)"));
  }
  // The same grid at 16 times the rate is fine.
  EXPECT_NO_THROW(loadPreset(
      piano, {.overrides = {{"scheme.grid_rule", "longitudinal"}, {"scheme.oversampling", "16"}}}));
  // Where the voice names the overridden parameter itself, the line is the --set's, once.
  EXPECT_THAT(errorsWith(kStringHead, {{"string.length_m", "0.02"}}),
              ElementsAre(AllOf(HasSubstr("test.toml: --set string.length_m=0.02 at C2: shorter "
                                          "than two grid spacings"),
                                Not(HasSubstr("(with")), Not(HasSubstr("grid factor")))));
  // A smaller grid factor is advice only where the factor is above 1 (it cannot go below).
  EXPECT_THAT(errorsWith(kStringHead, {{"string.length_m", "0.02"}, {"scheme.grid_factor", "2"}}),
              ElementsAre(HasSubstr("or a smaller grid factor")));
}

TEST(PresetParameters, DefaultsSatisfyTheirOwnRanges) {
  for (const Parameter& p : parameters()) {
    if (p.defaultKind != DefaultKind::value) continue;
    switch (p.type) {
      case ParameterType::real:
      case ParameterType::integer:
      case ParameterType::note: {
        const double v = defaultNumber(p);
        EXPECT_GE(v, p.min) << p.name;
        EXPECT_LE(v, p.max) << p.name;
        if (p.type != ParameterType::real) {
          EXPECT_EQ(v, std::round(v)) << p.name;
        }
        if (!p.choices.empty()) {
          EXPECT_TRUE(listed(p.choices, p.defaultText)) << p.name;
        }
        break;
      }
      case ParameterType::choice:
        EXPECT_TRUE(listed(p.choices, p.defaultText)) << p.name;
        break;
      case ParameterType::boolean:
        EXPECT_TRUE(p.defaultText == "true" || p.defaultText == "false") << p.name;
        break;
      case ParameterType::text:
        ADD_FAILURE() << p.name << ": a text parameter's default is derived";
        break;
    }
    if (!p.minOf.empty()) {
      const Parameter* other = findParameter(p.minOf);
      ASSERT_NE(other, nullptr) << p.name;
      EXPECT_GE(defaultNumber(p), defaultNumber(*other)) << p.name;
    }
    if (!p.maxOf.empty()) {
      for (InstrumentModel m : {InstrumentModel::string, InstrumentModel::plate}) {
        const Parameter* other = findParameter(p.maxOf, m);
        if (appliesTo(p, m) && other) {
          EXPECT_LE(defaultNumber(p), defaultNumber(*other)) << p.name;
        }
      }
    }
  }
}

TEST(PresetParameters, PerKeyParametersAreStringNumbers) {
  for (const Parameter& p : parameters())
    if (p.perKey) {
      EXPECT_EQ(p.model, ParameterModel::string) << p.name;
      EXPECT_TRUE(p.type == ParameterType::real || p.type == ParameterType::integer) << p.name;
    }
}

// The printed table's lines, and where a column starts in one of them (the ranges hold "…": a
// column is a character, not a byte).
std::vector<std::string> tableLines(const std::string& table) {
  std::vector<std::string> lines;
  for (size_t start = 0; start < table.size();) {
    const size_t end = std::min(table.find('\n', start), table.size());
    lines.push_back(table.substr(start, end - start));
    start = end + 1;
  }
  return lines;
}
bool continuationByte(char c) { return (static_cast<unsigned char>(c) & 0xC0) == 0x80; }

TEST(PresetParameters, PrintedTableListsEveryParameterIn100Columns) {
  const std::string table = parameterTable();
  for (const Parameter& p : parameters()) EXPECT_THAT(table, HasSubstr(std::string(p.name)));
  for (const std::string& line : tableLines(table))
    EXPECT_LE(std::count_if(line.begin(), line.end(), [](char c) { return !continuationByte(c); }),
              100)
        << line;
}

// Every row's last cell, the models it applies to, starts under the heading "model", on the row's
// own line or, when a cell before it is wider than its column (a range such as
// "0.01 … longitudinal_t60_low_s"), on the line that continues the row.
TEST(PresetParameters, PrintedTableKeepsEveryCellUnderItsHeading) {
  const std::vector<std::string> lines = tableLines(parameterTable());
  // The text of a line from a column on.
  auto from = [](const std::string& line, size_t column) {
    size_t at = 0, i = 0;
    for (; i < line.size() && at < column; ++i) at += continuationByte(line[i]) ? 0 : 1;
    while (i < line.size() && continuationByte(line[i])) ++i;
    return at == column ? line.substr(i) : std::string();
  };
  const auto header = std::find_if(lines.begin(), lines.end(),
                                   [](const std::string& l) { return l.rfind("  name ", 0) == 0; });
  ASSERT_NE(header, lines.end());
  const size_t model = header->find("model");
  int continued = 0;
  for (const Parameter& p : parameters()) {
    const std::string start = "  " + std::string(p.name) + " ";
    const auto row = std::find_if(lines.begin(), lines.end(), [&](const std::string& l) {
      return l.rfind(start, 0) == 0 && l != *header;  // the parameter "name" is a heading too
    });
    ASSERT_NE(row, lines.end()) << p.name;
    // A row goes on below when the next line starts past the name's column (a parameter's text
    // starts at 6); its models are on its last line.
    auto line = row;
    while (line + 1 != lines.end() && !line[1].empty() &&
           line[1].find_first_not_of(' ') > start.size())
      ++line;
    continued += line != row;
    const std::string last = from(*line, model);
    EXPECT_TRUE(last.rfind("both", 0) == 0 || last.rfind("string", 0) == 0 ||
                last.rfind("plate", 0) == 0)
        << p.name << ": the models start at column " << model << " of \"" << *row << "\", got \""
        << last << "\"";
  }
  EXPECT_GE(continued, 1) << "no row is wider than its columns: the continuation is untested";
}

TEST(PresetNotes, NamesAndNumbers) {
  EXPECT_EQ(parseNoteName("A0"), 21);
  EXPECT_EQ(parseNoteName("C4"), 60);
  EXPECT_EQ(parseNoteName("c4"), 60);
  EXPECT_EQ(parseNoteName("C#4"), 61);
  EXPECT_EQ(parseNoteName("Db4"), 61);
  EXPECT_EQ(parseNoteName("C-1"), 0);
  EXPECT_EQ(parseNoteName("G9"), 127);
  for (const char* bad : {"", "C", "H3", "G#9", "Cb-1", "C10", "C+4", "C#", "4C", "C 4"})
    EXPECT_EQ(parseNoteName(bad), std::nullopt) << bad;
  for (int note = 0; note <= 127; ++note) EXPECT_EQ(parseNoteName(noteName(note)), note);
  EXPECT_EQ(noteName(61), "C#4");
}

}  // namespace
}  // namespace hamiltone
