// hamiltone-play's command line where no audio device is needed: presets, every --set, the
// --record target, --midi's file and --notes' list are checked before any device is opened, so a
// bad one is refused (exit 2, one message naming it, files left as they were) and a good one gets
// as far as the audio API — here a JACK server that does not exist.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>

#include "support/riff_chunks.h"
#include "support/run_command.h"
#include "support/scratch_dir.h"

namespace {

namespace fs = std::filesystem;
using hamiltone::testing::CommandResult;

std::string preset(const char* name) {
  return std::string(HAMILTONE_SOURCE_DIR) + "/presets/" + name + ".toml";
}

class PlayCli : public ::testing::Test {
 protected:
  // hamiltone-play --api jack ARGS with a JACK server name of its own that no server has, so a
  // developer's JACK server is never met and none is started.
  CommandResult play(const std::string& args) const {
    const std::string pid = std::to_string(::getpid());
    return hamiltone::testing::runCommand("JACK_DEFAULT_SERVER=hamiltone-none-" + pid +
                                              " JACK_NO_START_SERVER=1 timeout 60 " +
                                              HAMILTONE_PLAY + " --api jack " + args,
                                          dir_ / "stderr");
  }

  hamiltone::testing::ScratchDir scratch_{"hamiltone-play-cli"};
  const fs::path dir_ = scratch_.path();
};

TEST_F(PlayCli, RefusesABadSetBeforeOpeningAnyDevice) {
  const std::string c3 = "--preset " + preset("paper-c3-string");
  for (const auto& [args, mention] :
       {std::pair<std::string, std::string>{c3 + " --set scheme.oversampling=3",
                                            "paper-c3-string.toml: --set scheme.oversampling=3: "
                                            "expected one of 1, 2, 4, 8, 16, 32, 64"},
        {c3 + " --set scheme.oversampeling=16", "did you mean scheme.oversampling?"},
        {c3 + " --set foo", "--set foo: expected NAME=VALUE"}}) {
    const CommandResult r = play(args);
    EXPECT_EQ(r.exitCode, 2) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(mention), std::string::npos) << args << "\n" << r.err;
    EXPECT_EQ(r.err.find("audio"), std::string::npos) << args << "\n" << r.err;
  }
}

TEST_F(PlayCli, RefusesABadThreadCountBeforeOpeningAnyDevice) {
  for (const char* threads : {"0", "257", "all"}) {
    const CommandResult r = play("--quiet --threads " + std::string(threads));
    EXPECT_EQ(r.exitCode, 2) << threads << "\n" << r.err;
    EXPECT_NE(r.err.find("--threads = "), std::string::npos) << threads << "\n" << r.err;
    EXPECT_NE(r.err.find("from 1 to 256"), std::string::npos) << threads << "\n" << r.err;
  }
}

// Past the presets: the refusal is the audio API's, not a preset's.
TEST_F(PlayCli, AcceptsAGoodSetAndGoesOnToTheAudioDevice) {
  const CommandResult r = play("--preset " + preset("paper-c3-string") +
                               " --set scheme.grid_rule=longitudinal --set scheme.oversampling=16");
  EXPECT_EQ(r.exitCode, 2) << r.err;
  EXPECT_NE(r.err.find("no audio output device for API jack"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("--set"), std::string::npos) << r.err;
}

// --record naming a preset (directly or through a link) would overwrite it with audio.
TEST_F(PlayCli, RefusesToRecordOntoAPreset) {
  const fs::path toml = dir_ / "in.toml", link = dir_ / "take.wav";
  fs::copy_file(preset("paper-c3-string"), toml);
  const std::string before = hamiltone::testing::fileBytes(toml);
  fs::create_symlink(toml, link);
  for (const fs::path& out : {toml, link}) {
    const CommandResult r = play("--quiet --preset " + toml.string() + " --record " + out.string());
    EXPECT_EQ(r.exitCode, 2) << r.err;
    EXPECT_NE(r.err.find("--record = " + out.string()), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("--preset = " + toml.string()), std::string::npos) << r.err;
    EXPECT_EQ(hamiltone::testing::fileBytes(toml), before);
  }
}

// --help (or --list-devices) to a full disk: exit 1, saying so, where it was lost with exit 0.
TEST_F(PlayCli, AStandardOutputThatCannotBeWrittenIsAnIoError) {
  const CommandResult r = hamiltone::testing::runCommand(
      std::string("{ ") + HAMILTONE_PLAY + " --help >/dev/full; }", dir_ / "stderr");
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_NE(r.err.find("hamiltone-play: error: writing to standard output failed"),
            std::string::npos)
      << r.err;
}

// An empty --record or --virtual-midi was taken as no recording or no port, saying nothing; a
// --record of another type than its extension names (a WAV written as take.flac) or of no type
// the recorder writes is refused before any device, naming the extensions it takes.
TEST_F(PlayCli, RefusesAnEmptyRecordOrPortAndARecordingOfNoKnownType) {
  for (const std::string& args : {std::string("--record ''"), std::string("--virtual-midi ''")}) {
    const CommandResult r = play("--quiet " + args);
    EXPECT_EQ(r.exitCode, 2) << args << "\n" << r.err;
    EXPECT_NE(r.err.find("is empty"), std::string::npos) << args << "\n" << r.err;
  }
  const fs::path mp3 = dir_ / "take.mp3";
  const CommandResult r = play("--quiet --record " + mp3.string());
  EXPECT_EQ(r.exitCode, 2) << r.err;
  EXPECT_NE(r.err.find("--record"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(".flac"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(mp3));
  EXPECT_TRUE(fs::is_empty(dir_)) << "a temporary was left";
}

// --midi FILE: a file that is missing or is not a Standard MIDI File is refused before any device,
// naming the file and what is wrong, as hamiltone-render says it.
TEST_F(PlayCli, RefusesAMissingOrCorruptMidiFile) {
  const fs::path corrupt = dir_ / "corrupt.mid", missing = dir_ / "missing.mid";
  std::ofstream(corrupt) << "MThd this is not MIDI";
  for (const auto& [file, mention] :
       {std::pair<fs::path, std::string>{missing, "--midi: " + missing.string() + ": "},
        {corrupt, "--midi: " + corrupt.string() + ": byte "}}) {
    const CommandResult r = play("--quiet --midi " + file.string());
    EXPECT_EQ(r.exitCode, 2) << file << "\n" << r.err;
    EXPECT_NE(r.err.find(mention), std::string::npos) << file << "\n" << r.err;
    EXPECT_EQ(r.err.find("audio"), std::string::npos) << file << "\n" << r.err;
  }
}

// --notes takes hamiltone-render's list, and refuses a bad one with the renderer's message.
TEST_F(PlayCli, RefusesABadNoteListAsTheRendererDoes) {
  for (const auto& [notes, mention] :
       {std::pair<std::string, std::string>{"H4", "--notes: item 1 \"H4\": unknown note name"},
        {"C4,,E4", "--notes: item 2 \"\": empty"},
        {"C4:200", "--notes: item 1 \"C4:200\": velocity"},
        {"C4@-1", "--notes: item 1 \"C4@-1\": start"}}) {
    const CommandResult r = play("--quiet --notes '" + notes + "'");
    EXPECT_EQ(r.exitCode, 2) << notes << "\n" << r.err;
    EXPECT_NE(r.err.find(mention), std::string::npos) << notes << "\n" << r.err;
  }
}

// An empty --notes or --midi (a shell variable that was not set) is refused as the list or the
// file it is not; both were taken for no score at all, and the player listened for MIDI instead.
TEST_F(PlayCli, RefusesAnEmptyNoteListOrMidiFileName) {
  for (const auto& [args, mention] :
       {std::pair<std::string, std::string>{"--notes ''", "--notes: item 1 \"\": empty"},
        {"--midi ''", "--midi: the file name is empty"},
        {"--notes '' --midi x.mid", "at most one of --midi FILE and --notes LIST"}}) {
    const CommandResult r = play("--quiet " + args);
    EXPECT_EQ(r.exitCode, 2) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(mention), std::string::npos) << args << "\n" << r.err;
    EXPECT_EQ(r.err.find("audio"), std::string::npos) << args << "\n" << r.err;
  }
}

TEST_F(PlayCli, RefusesConflictingOrOutOfRangeOptions) {
  for (const auto& [args, mention] :
       {std::pair<std::string, std::string>{"--notes C4 --midi x.mid",
                                            "at most one of --midi FILE and --notes LIST"},
        {"--keep-listening", "--keep-listening goes with --midi FILE or --notes LIST"},
        {"--cpu-limit 0", "--cpu-limit = 0"},
        {"--cpu-limit 101", "--cpu-limit = 101: at most 100"}}) {
    const CommandResult r = play("--quiet " + args);
    EXPECT_EQ(r.exitCode, 2) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(mention), std::string::npos) << args << "\n" << r.err;
  }
}

// A good --notes list or MIDI file gets as far as the audio API.
TEST_F(PlayCli, AcceptsNotesAndAMidiFileAndGoesOnToTheAudioDevice) {
  const std::string demo = std::string(HAMILTONE_SOURCE_DIR) + "/presets/demo.mid";
  for (const std::string& args :
       {std::string("--notes 'C4, E4@0.5:80, G4@1:100:2.5' --cpu-limit 95"),
        "--midi " + demo + " --keep-listening"}) {
    const CommandResult r = play("--quiet " + args);
    EXPECT_EQ(r.exitCode, 2) << args << "\n" << r.err;
    EXPECT_NE(r.err.find("no audio output device for API jack"), std::string::npos) << r.err;
  }
}

}  // namespace
