// --preset and --set as both players read them: a --set without NAME= is refused saying what is
// valid, every preset gets every --set, and every preset's refusal is gathered into one error.
#include "preset_arguments.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "usage_error.h"

namespace {

using hamiltone::Instrument;
using hamiltone::cli::loadPresets;
using hamiltone::cli::parseSets;
using hamiltone::cli::UsageError;

std::string preset(const char* name) {
  return std::string(HAMILTONE_SOURCE_DIR) + "/presets/" + name + ".toml";
}

// The message of the UsageError loading `files` with `sets` raises ("" if none).
std::string errorOf(const std::vector<std::string>& files, const std::vector<std::string>& sets) {
  try {
    loadPresets(files, sets);
  } catch (const UsageError& e) {
    return e.what();
  }
  return "";
}

TEST(PresetArguments, SetWithoutNameAndEqualsSaysWhatIsValid) {
  for (const char* bad : {"foo", "=3", ""}) {
    const std::string message = errorOf({preset("paper-c3-string")}, {"gain_dB=-3", bad});
    EXPECT_EQ(message.find("--set " + std::string(bad) +
                           ": expected NAME=VALUE, e.g. --set "
                           "scheme.grid_rule=longitudinal"),
              0u)
        << message;
  }
  EXPECT_EQ(errorOf({preset("paper-c3-string")}, {"scheme.oversampling"}),
            "--set scheme.oversampling: expected scheme.oversampling=VALUE (hamiltone-render "
            "--list-params gives its type and range)");
  ASSERT_EQ(parseSets({"a=1", "b = x=y"}).size(), 2u);
  EXPECT_EQ(parseSets({"b = x=y"})[0].value, "x=y");
}

TEST(PresetArguments, EveryPresetGetsEverySet) {
  const std::vector<Instrument> instruments =
      loadPresets({preset("paper-c3-string"), preset("grand-piano")},
                  {"hammer.velocity_max_m_s=4", "gain_dB=-7"});
  ASSERT_EQ(instruments.size(), 2u);
  for (const Instrument& i : instruments) {
    EXPECT_EQ(i.gainDb, -7.0) << i.name;
    for (const auto& key : i.keys) EXPECT_EQ(key.patch.velocityMax, 4.0) << i.name;
  }
}

// A string-only --set refuses the plate preset and only it; the message lists each file's lines.
TEST(PresetArguments, EveryPresetsRefusalIsGathered) {
  const std::string plate = preset("steel-plate");
  EXPECT_EQ(errorOf({preset("paper-c3-string"), plate, plate},
                    {"scheme.grid_rule=longitudinal", "scheme.oversampling=16"}),
            "bad preset:\n" + plate +
                ": --set scheme.grid_rule=longitudinal: string model only; this preset's model "
                "is \"plate\"\n" +
                plate +
                ": --set scheme.grid_rule=longitudinal: string model only; this preset's model "
                "is \"plate\"");
}

// 130 presets were taken without a word, though program change reaches 128 of them.
TEST(PresetArguments, MoreThanProgramChangeReachesIsRefused) {
  const std::vector<std::string> many(129, preset("steel-plate"));
  EXPECT_NE(errorOf(many, {}).find("--preset given 129 times"), std::string::npos);
}

}  // namespace

namespace {

// The notes the players warn are silent: those struck while the preset in force does not play
// them, program changes followed as the synthesizer follows them — C5 after a change to a gong of
// C2 … C4 is silent though the piano loaded first plays it (the warning said nothing: a silent
// file, exit 0); a change to a program beyond those loaded is ignored, and a note-on of velocity 0
// is a note-off.
TEST(PresetArguments, UnplayedNotesFollowTheProgramInForce) {
  using hamiltone::TimedMessage;
  using hamiltone::cli::unplayedNotes;
  std::vector<Instrument> two(2);
  two[0].lowestNote = 21, two[0].highestNote = 108;
  two[1].lowestNote = 36, two[1].highestNote = 60;
  const std::vector<TimedMessage> played = {{0.0, {0x90, 72, 90}},  // the piano: played
                                            {0.1, {0xC0, 1, 0}},
                                            {0.2, {0x90, 48, 90}},   // the gong: played
                                            {0.3, {0x90, 72, 90}},   // the gong: silent
                                            {0.4, {0x90, 100, 0}},   // a note-off
                                            {0.5, {0xC0, 7, 0}},     // no program 7: ignored
                                            {0.6, {0x91, 30, 90}}};  // still the gong: silent
  EXPECT_EQ(unplayedNotes(played, two), " 30 72");
  EXPECT_EQ(unplayedNotes(std::vector<TimedMessage>{{0.0, {0x90, 72, 90}}}, two), "");
}

// Program changes past the presets loaded are ignored: the players name them, each once, and say
// what would play them (they were ignored without a word).
TEST(PresetArguments, ProgramsNotLoadedAreNamedWithWhatWouldLoadThem) {
  using hamiltone::TimedMessage;
  using hamiltone::cli::ignoredProgramText;
  using hamiltone::cli::unloadedPrograms;
  const std::vector<TimedMessage> changes = {
      {0.0, {0xC0, 7, 0}}, {0.1, {0xC1, 1, 0}}, {0.2, {0xC0, 3, 0}}, {0.3, {0xC0, 7, 0}}};
  EXPECT_EQ(unloadedPrograms(changes, 2), " 3 7");
  EXPECT_EQ(unloadedPrograms(changes, 8), "");
  EXPECT_EQ(ignoredProgramText(" 3 7", 2),
            "program changes to 3 7 are ignored: 2 presets are loaded (programs 0 to 1); give "
            "--preset once per program (the first is program 0)");
  EXPECT_EQ(ignoredProgramText(" 5", 1),
            "program change to 5 is ignored: 1 preset is loaded (program 0); give --preset once "
            "per program (the first is program 0)");
}

}  // namespace
