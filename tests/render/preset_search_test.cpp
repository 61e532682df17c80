// Presets by name: found in $XDG_DATA_HOME first, then $XDG_DATA_DIRS in order (relative entries
// ignored), then the program's own share/ — which, for a program in the build tree, is the
// build tree's link to presets/; a path is taken as given; a name found nowhere is refused
// naming every directory searched.
#include "preset_search.h"

#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "support/scoped_environment.h"
#include "support/scratch_dir.h"
#include "usage_error.h"

namespace {

namespace fs = std::filesystem;
using hamiltone::cli::presetDirectories;
using hamiltone::cli::resolvePreset;
using hamiltone::cli::UsageError;
using hamiltone::testing::ScopedEnvironment;

fs::path put(const fs::path& dataDir, const std::string& file) {
  const fs::path dir = dataDir / "hamiltone" / "presets";
  fs::create_directories(dir);
  std::ofstream(dir / file) << "model = \"string\"\n";
  return dir / file;
}

TEST(PresetSearch, UserDataThenSystemDataDirsInOrder) {
  const hamiltone::testing::ScratchDir scratch("hamiltone-presets");
  const fs::path home = scratch.path() / "home", a = scratch.path() / "a", b = scratch.path() / "b";
  const ScopedEnvironment dataHome("XDG_DATA_HOME", home.string());
  const ScopedEnvironment dataDirs("XDG_DATA_DIRS",
                                   "relative/dir:" + a.string() + ":" + b.string());
  const std::vector<fs::path> dirs = presetDirectories();
  ASSERT_GE(dirs.size(), 4u);
  EXPECT_EQ(dirs[0], home / "hamiltone" / "presets");
  EXPECT_EQ(dirs[1], a / "hamiltone" / "presets");  // "relative/dir" is skipped
  EXPECT_EQ(dirs[2], b / "hamiltone" / "presets");

  const fs::path inB = put(b, "bell.toml");
  EXPECT_EQ(resolvePreset("bell"), inB);
  const fs::path inA = put(a, "bell.toml");
  EXPECT_EQ(resolvePreset("bell"), inA);
  const fs::path inHome = put(home, "bell.toml");
  EXPECT_EQ(resolvePreset("bell"), inHome);
  EXPECT_EQ(resolvePreset("bell.toml"), inHome);           // the full file name is found too
  EXPECT_EQ(resolvePreset("./bell"), fs::path("./bell"));  // a path is the user's: as given
}

// This test program sits one directory down in the build tree, as the programs do: its share/
// holds the bundled presets (a link to presets/), found with no XDG directory having any.
TEST(PresetSearch, BuildTreeFindsTheBundledPresets) {
  const ScopedEnvironment dataHome("XDG_DATA_HOME", "/nonexistent");
  const ScopedEnvironment dataDirs("XDG_DATA_DIRS", "/nonexistent");
  const fs::path found = resolvePreset("grand-piano");
  EXPECT_TRUE(fs::equivalent(found, fs::path(HAMILTONE_SOURCE_DIR) / "presets/grand-piano.toml"))
      << found;
}

TEST(PresetSearch, AnUnknownNameIsRefusedNamingTheDirectories) {
  const ScopedEnvironment dataHome("XDG_DATA_HOME", "/nonexistent/home");
  const ScopedEnvironment dataDirs("XDG_DATA_DIRS", "/nonexistent/system");
  try {
    resolvePreset("no-such-preset");
    FAIL() << "no error";
  } catch (const UsageError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.find("--preset no-such-preset: no such file, and no preset "
                           "no-such-preset(.toml) in\n  /nonexistent/home/hamiltone/presets\n  "
                           "/nonexistent/system/hamiltone/presets\n"),
              0u)
        << message;
  }
}

}  // namespace
