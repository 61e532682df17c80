// An output file that appears whole or not at all: a temporary beside it, renamed on commit.
#pragma once

#include <sys/stat.h>

#include <cstdio>
#include <initializer_list>
#include <string>
#include <vector>

namespace hamiltone::cli {

// Whether two paths name one file: the same device and inode when both exist (hard links,
// symlinks, "./a" and "a" alike), else the same path once '.', '..' and the symlinks of its
// existing part are resolved (what AtomicFile would rename onto).
bool sameFile(const std::string& a, const std::string& b);

// A file the program reads, by the flag that named it.
struct InputFile {
  std::string flag, path;
};

// Throws UsageError when the output `path` (given by `flag`) is one of the inputs, which writing
// it would destroy; the message names both flags and paths.
void refuseInputAsOutput(const std::string& flag, const std::string& path,
                         const std::vector<InputFile>& inputs);

class AtomicFile {
 public:
  // Creates the temporary now, so an unwritable path fails before any work is done. Throws
  // UsageError naming `flag` and the path (also for a symlink to nothing: neither followed, as
  // it would create a file elsewhere, nor replaced, as the link may be meant).
  //
  // Every signal sent to end the program (endingSignals()) removes every live temporary (up to
  // kMaxLive at once; one more is a std::runtime_error) and exits 128 + N — except a signal the
  // program inherited as ignored (nohup's SIGHUP), which stays ignored. One that comes while
  // commit() or commitTogether() puts the files in place waits for them; once they all are, it
  // came too late to stop the run, and the run ends as it would have.
  // The temporary is named PATH.tmp-PID-XXXXXX: one left by a run that could not clean up
  // (SIGKILL, a crash) is removed when a later run writes PATH and that PID is gone.
  //
  // `keepOthers` (a recording, which cannot be made again): a file another program writes at the
  // path while this one runs is kept, and this one is published beside it as NAME-2.EXT (or the
  // next free number), which path() then names. Otherwise the last to publish replaces it.
  AtomicFile(std::string path, const std::string& flag, bool keepOthers = false);
  ~AtomicFile();  // removes the temporary unless published
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  static constexpr int kMaxLive = 16;
  // Those whose default is to terminate or to quit, the real-time ones included, less the faults
  // (SIGILL, SIGBUS, SIGFPE, SIGSEGV, SIGABRT, SIGTRAP, SIGSYS) that a crash raises in the thread
  // that made it, where no cleanup is safe. A real-time signal is left out when the process already
  // handles it (a library's own).
  static const std::vector<int>& endingSignals();

  std::FILE* stream() { return file_; }
  // Flushes the temporary to the disk (fsync) and closes it, keeping it; throws
  // std::runtime_error on an I/O error (a full disk), after which the destructor removes it. The
  // stream is gone afterwards.
  void finish();
  // Renames the finished temporary onto the final path (or beside it: keepOthers); throws
  // std::runtime_error on failure.
  void publish();
  // finish(), then publish().
  void commit();
  // Closes and removes the temporary now, as the destructor would: for a program about to end by
  // _exit, which runs no destructor. Nothing is published after it.
  void discard();

  const std::string& path() const { return path_; }
  // After publish(): whether the file went beside another program's (keepOthers).
  bool movedAside() const { return movedAside_; }

 private:
  // Whether the file at path_ is not the one there at construction (keepOthers).
  bool writtenByAnother() const;
  void publishBeside();

  std::string path_, temporary_;
  std::FILE* file_ = nullptr;
  int slot_ = -1;  // in the signal handler's table
  bool finished_ = false;
  bool keepOthers_ = false, movedAside_ = false;
  bool existed_ = false;  // a file at the path at construction, and its stat:
  struct stat before_ {};
};

// Commits the files (null entries skipped) all or none: each is finished first, and only when
// every one finished cleanly are they renamed, with the handled signals held back meanwhile so a
// signal cannot publish some and remove the rest. A failure leaves no new file: on an I/O error
// none was renamed; should a rename fail after others succeeded (not seen in practice: the
// temporaries lie beside their targets), the files it had already created are removed again.
void commitTogether(std::initializer_list<AtomicFile*> files);

}  // namespace hamiltone::cli
