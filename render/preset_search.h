// Presets named without a path (--preset gong): found in the data directories of the XDG Base
// Directory specification, where `cmake --install` puts the bundled ones, and beside the program.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace hamiltone::cli {

// The directories searched, in order, each ending in hamiltone/presets:
//   $XDG_DATA_HOME (default ~/.local/share), for presets of the user's own;
//   each of $XDG_DATA_DIRS (default /usr/local/share:/usr/share);
//   the program's own prefix: share/ beside its bin/ (HAMILTONE_DATA_FROM_BIN from the
//   executable's directory), so an install anywhere, or the build tree, finds its own.
// Relative paths in the variables are ignored, as the specification asks.
std::vector<std::filesystem::path> presetDirectories();

// The preset file `argument` names: itself when it is a file or has a '/'; otherwise NAME.toml
// or NAME in the first directory of presetDirectories() that has it. UsageError when none has,
// naming the directories searched.
std::filesystem::path resolvePreset(const std::string& argument);

}  // namespace hamiltone::cli
