// The XDG data directories, read from the environment at each call, and the program's own
// prefix, found from /proc/self/exe: nothing about the build machine is compiled in but the
// relative way from bin/ to share/.
#include "preset_search.h"

#include <cstdlib>
#include <sstream>
#include <system_error>

#include "usage_error.h"

namespace hamiltone::cli {

namespace fs = std::filesystem;

namespace {

std::string environment(const char* name) {
  const char* value = std::getenv(name);
  return value ? value : "";
}

}  // namespace

std::vector<fs::path> presetDirectories() {
  const fs::path presets = fs::path("hamiltone") / "presets";
  std::vector<fs::path> dirs;
  const fs::path dataHome = environment("XDG_DATA_HOME");
  if (dataHome.is_absolute())
    dirs.push_back(dataHome / presets);
  else if (const fs::path home = environment("HOME"); home.is_absolute())
    dirs.push_back(home / ".local" / "share" / presets);
  std::string dataDirs = environment("XDG_DATA_DIRS");
  if (dataDirs.empty()) dataDirs = "/usr/local/share:/usr/share";
  std::istringstream list(dataDirs);
  for (std::string dir; std::getline(list, dir, ':');)
    if (fs::path(dir).is_absolute()) dirs.push_back(fs::path(dir) / presets);
  std::error_code error;
  const fs::path program = fs::read_symlink("/proc/self/exe", error);
  if (!error)
    dirs.push_back((program.parent_path() / HAMILTONE_DATA_FROM_BIN / presets).lexically_normal());
  return dirs;
}

fs::path resolvePreset(const std::string& argument) {
  std::error_code error;
  // A link here, even one that leads nowhere, is the file meant: the loader says what is wrong.
  if (argument.find('/') != std::string::npos || fs::is_regular_file(argument, error) ||
      fs::is_symlink(argument, error))
    return argument;
  const std::vector<fs::path> dirs = presetDirectories();
  for (const fs::path& dir : dirs)
    for (const std::string& name : {argument + ".toml", argument})
      if (fs::is_regular_file(dir / name, error)) return dir / name;
  std::string searched;
  for (const fs::path& dir : dirs) searched += "\n  " + dir.string();
  throw UsageError("--preset " + argument + ": no such file, and no preset " + argument +
                   "(.toml) in" + searched);
}

}  // namespace hamiltone::cli
