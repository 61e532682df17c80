// hamiltone-play's command line where no audio device is needed: presets, every --set and the
// --record target are checked before any device is opened, so a bad one is refused (exit 2, one
// message naming it, files left as they were) and a good one gets as far as the audio API — here
// a JACK server that does not exist.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
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

}  // namespace
