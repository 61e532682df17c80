// An output file that appears whole or not at all: a temporary beside it, renamed on commit.
#pragma once

#include <cstdio>
#include <string>

namespace hamiltone::cli {

class AtomicFile {
 public:
  // Creates the temporary now, so an unwritable path fails before any work is done. Throws
  // UsageError naming `flag` and the path. SIGINT, SIGTERM and SIGHUP remove the temporary.
  AtomicFile(std::string path, const std::string& flag);
  ~AtomicFile();  // removes the temporary unless committed
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  std::FILE* stream() { return file_; }
  // Flushes, closes and renames onto the final path; throws std::runtime_error on an I/O error.
  void commit();

 private:
  std::string path_, temporary_;
  std::FILE* file_ = nullptr;
};

}  // namespace hamiltone::cli
