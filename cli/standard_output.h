// Whether what a program printed on standard output reached it: a listing, a summary or --help
// sent to a full disk (or a file past its size limit) was lost with exit code 0.
#pragma once

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace hamiltone::cli {

// Flushes standard output; on an error says so on standard error, naming `program`, and turns an
// exit code of 0 into 1 (an I/O error). Returns the exit code to use.
inline int checkedStandardOutput(const char* program, int code) {
  errno = 0;
  if (std::fflush(stdout) == 0 && !std::ferror(stdout)) return code;
  std::fprintf(stderr, "%s: error: writing to standard output failed: %s\n", program,
               errno != 0 ? std::strerror(errno) : "an earlier write failed");
  return code == 0 ? 1 : code;
}

}  // namespace hamiltone::cli
