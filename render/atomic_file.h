// An output file that appears whole or not at all: a temporary beside it, renamed on commit.
#pragma once

#include <cstdio>
#include <initializer_list>
#include <string>

namespace hamiltone::cli {

class AtomicFile {
 public:
  // Creates the temporary now, so an unwritable path fails before any work is done. Throws
  // UsageError naming `flag` and the path. SIGINT, SIGTERM, SIGHUP and SIGXFSZ remove every live
  // temporary (up to kMaxLive at once; one more is a std::runtime_error) and exit 128 + N.
  AtomicFile(std::string path, const std::string& flag);
  ~AtomicFile();  // removes the temporary unless published
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  static constexpr int kMaxLive = 16;

  std::FILE* stream() { return file_; }
  // Flushes and closes the temporary, keeping it; throws std::runtime_error on an I/O error (a
  // full disk), after which the destructor removes it. The stream is gone afterwards.
  void finish();
  // Renames the finished temporary onto the final path; throws std::runtime_error on failure.
  void publish();
  // finish(), then publish().
  void commit();

  const std::string& path() const { return path_; }

 private:
  std::string path_, temporary_;
  std::FILE* file_ = nullptr;
  int slot_ = -1;  // in the signal handler's table
  bool finished_ = false;
};

// Commits the files (null entries skipped) all or none: each is finished first, and only when
// every one finished cleanly are they renamed, with the handled signals held back meanwhile so a
// signal cannot publish some and remove the rest. A failure leaves no new file: on an I/O error
// none was renamed; should a rename fail after others succeeded (not seen in practice: the
// temporaries lie beside their targets), the files it had already created are removed again.
void commitTogether(std::initializer_list<AtomicFile*> files);

}  // namespace hamiltone::cli
