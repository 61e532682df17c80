// hamiltone-play as a user meets it without an audio server: what it refuses before opening any
// device, with exit code 2 and a message naming the flag, and files left as they were.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "support/riff_chunks.h"
#include "support/sim_cli.h"

namespace {

namespace fs = std::filesystem;

class PlayCli : public hamiltone::test::SimCliTest {
 protected:
  // `hamiltone-play ARGS` on a JACK server name no server has, so no device is ever opened.
  hamiltone::test::CliResult play(const std::string& args) {
    const std::string cmd = "JACK_DEFAULT_SERVER=hamiltone-no-server-" +
                            std::to_string(::getpid()) + " " HAMILTONE_PLAY " " + args + " >" +
                            path("stdout") + " 2>" + path("stderr") + " </dev/null";
    const int status = std::system(cmd.c_str());
    hamiltone::test::CliResult r{WIFEXITED(status) ? WEXITSTATUS(status) : -1,
                                 slurp(path("stdout")), slurp(path("stderr"))};
    fs::remove(path("stdout"));
    fs::remove(path("stderr"));
    return r;
  }
};

// --record naming a preset (directly or through a link) would overwrite it with audio.
TEST_F(PlayCli, RefusesToRecordOntoAPreset) {
  const fs::path toml = dir_ / "in.toml", link = dir_ / "take.wav";
  fs::copy_file(HAMILTONE_SOURCE_DIR "/presets/paper-c3-string.toml", toml);
  const std::string before = hamiltone::testing::fileBytes(toml);
  fs::create_symlink(toml, link);
  for (const fs::path& out : {toml, link}) {
    const hamiltone::test::CliResult r =
        play("--quiet --preset " + toml.string() + " --record " + out.string());
    EXPECT_EQ(r.exitCode, 2) << r.err;
    EXPECT_NE(r.err.find("--record = " + out.string()), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("--preset = " + toml.string()), std::string::npos) << r.err;
    EXPECT_EQ(hamiltone::testing::fileBytes(toml), before);
  }
}

}  // namespace
