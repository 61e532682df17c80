// A command-line program as a user runs it, for the tests of hamiltone-render and hamiltone-play:
// its exit code and what it said on stderr.
#pragma once

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace hamiltone::testing {

struct CommandResult {
  int exitCode;  // -1 if it did not exit (a signal)
  std::string err;
};

// `command` run by /bin/sh with stdin closed and stdout discarded; stderr is kept in `errFile`
// meanwhile, which is removed after.
inline CommandResult runCommand(const std::string& command, const std::filesystem::path& errFile) {
  const int status =
      std::system((command + " >/dev/null 2>" + errFile.string() + " </dev/null").c_str());
  std::ifstream in(errFile);
  std::stringstream s;
  s << in.rdbuf();
  std::filesystem::remove(errFile);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, s.str()};
}

}  // namespace hamiltone::testing
