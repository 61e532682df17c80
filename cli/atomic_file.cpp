// mkstemp beside the target, so the final rename(2) is atomic on the same file system; a symlink
// is followed (its target is replaced, the link kept); a device or other special file is refused.
#include "atomic_file.h"

#include <fcntl.h>
#include <pthread.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <climits>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <system_error>
#include <vector>

#include "usage_error.h"

namespace hamiltone::cli {

const std::vector<int>& AtomicFile::endingSignals() {
  // SIGXFSZ: past the file-size limit (ulimit -f). SIGQUIT (Ctrl-\) too: its core dump is not
  // worth a lost recording; gcore, or SIGABRT, still takes one.
  static const std::vector<int> signals = [] {
    std::vector<int> s = {SIGHUP,    SIGINT,  SIGQUIT, SIGTERM, SIGUSR1, SIGUSR2, SIGPIPE,  SIGALRM,
                          SIGVTALRM, SIGPROF, SIGXCPU, SIGXFSZ, SIGPOLL, SIGPWR,  SIGSTKFLT};
    for (int r = SIGRTMIN; r <= SIGRTMAX; ++r) {
      struct sigaction current {};
      if (::sigaction(r, nullptr, &current) == 0 && current.sa_handler == SIG_DFL) s.push_back(r);
    }
    return s;
  }();
  return signals;
}

namespace {

// The temporaries being written, for the signal handler: fixed buffers, as only
// async-signal-safe calls (unlink, _exit) and lock-free atomics may be used there. A slot is
// claimed (free → filling) by compare-exchange, so two threads never share one; the handler
// removes only slots marked live, whose name is complete.
enum SlotState : int { kFree = 0, kFilling = 1, kLive = 2 };
struct Slot {
  std::atomic<int> state{kFree};
  char path[PATH_MAX + 32] = {};
};
static_assert(std::atomic<int>::is_always_lock_free);
Slot liveTemporaries[AtomicFile::kMaxLive];

// Whether files are being put in place (commit, commitTogether), for a signal that comes then.
enum Publishing : int { kWriting = 0, kPublishing = 1, kFailed = 2 };
std::atomic<int> publishing{kWriting};
static_assert(std::atomic<int>::is_always_lock_free);

extern "C" void removeTemporariesAndExit(int signal) {
  // Taken by another thread while the files are being renamed into place (the renaming thread
  // holds the signals back): wait for it. Once all of them are in place, the signal came too
  // late to stop the run; if one failed, it ends the run as any other.
  if (publishing.load() == kPublishing) {
    int state;
    while ((state = publishing.load()) == kPublishing) {
    }
    if (state != kFailed) return;
  }
  bool removed = false;
  for (Slot& slot : liveTemporaries)
    if (slot.state.load() == kLive) removed = ::unlink(slot.path) == 0 || removed;
  // "PROGRAM: stopped by SIGINT; its unfinished output removed", with async-signal-safe calls only.
  char line[160];
  std::size_t n = 0;
  auto add = [&](const char* text) {
    while (*text && n < sizeof line - 1) line[n++] = *text++;
  };
  add(program_invocation_short_name);
  add(": stopped by ");
  if (const char* name = ::sigabbrev_np(signal)) {
    add("SIG");
    add(name);
  } else {
    char digits[12];
    int d = 0;
    for (int v = signal; v > 0 && d < 11; v /= 10) digits[d++] = static_cast<char>('0' + v % 10);
    add("signal ");
    while (d > 0 && n < sizeof line - 1) line[n++] = digits[--d];
  }
  add(removed ? "; its unfinished output removed\n" : "\n");
  [[maybe_unused]] const ssize_t written = ::write(STDERR_FILENO, line, n);
  ::_exit(128 + signal);
}

// Each signal's handler, unless it is ignored: an ignore set by whoever started the program
// (nohup, a shell's trap '') is a request to keep running.
void installHandler() {
  static std::once_flag once;
  std::call_once(once, [] {
    const std::vector<int>& handled = AtomicFile::endingSignals();
    struct sigaction action {};
    action.sa_handler = removeTemporariesAndExit;
    sigemptyset(&action.sa_mask);
    for (const int s : handled) sigaddset(&action.sa_mask, s);  // one handler at a time
    for (const int s : handled) {
      struct sigaction current {};
      if (::sigaction(s, nullptr, &current) == 0 && current.sa_handler == SIG_IGN) continue;
      ::sigaction(s, &action, nullptr);
    }
  });
}

// The PID in a temporary's name "NAME.tmp-PID-XXXXXX" after `prefix` ("NAME.tmp-"), or 0.
pid_t temporaryOwner(const std::string& name, const std::string& prefix) {
  if (name.size() <= prefix.size() + 7 || name.compare(0, prefix.size(), prefix) != 0) return 0;
  const std::string rest = name.substr(prefix.size());
  const std::size_t dash = rest.find('-');
  if (dash == 0 || dash == std::string::npos || rest.size() != dash + 7) return 0;
  pid_t pid = 0;
  for (std::size_t i = 0; i < dash; ++i) {
    if (rest[i] < '0' || rest[i] > '9' || pid > 1'000'000'000) return 0;
    pid = pid * 10 + (rest[i] - '0');
  }
  return pid;
}

// Removes the temporaries of `path` whose process is gone: left by a run killed by SIGKILL, or
// one that crashed. A process in another PID namespace or on another host that shares the
// directory is not seen; its temporary would be taken for stale — not a case this tool meets.
void removeStaleTemporaries(const std::string& path) {
  const std::filesystem::path target(path);
  const std::string prefix = target.filename().string() + ".tmp-";
  std::error_code error;
  const std::filesystem::path dir =
      target.has_parent_path() ? target.parent_path() : std::filesystem::path(".");
  for (std::filesystem::directory_iterator it(dir, error), end; !error && it != end;
       it.increment(error)) {
    const pid_t owner = temporaryOwner(it->path().filename().string(), prefix);
    if (owner > 0 && owner != ::getpid() && ::kill(owner, 0) != 0 && errno == ESRCH)
      ::unlink(it->path().c_str());
  }
}

// The slot now holding `path`, or -1 when it cannot be held (then the caller gives up).
int addLive(const std::string& path) {
  if (path.size() + 1 > sizeof Slot::path) return -1;
  for (int i = 0; i < AtomicFile::kMaxLive; ++i) {
    int expected = kFree;
    if (!liveTemporaries[i].state.compare_exchange_strong(expected, kFilling)) continue;
    std::memcpy(liveTemporaries[i].path, path.c_str(), path.size() + 1);
    liveTemporaries[i].state.store(kLive);
    int failed = kFailed;  // after a failed publish a signal ends the run again; a publish that
    publishing.compare_exchange_strong(failed, kWriting);  // another thread runs stays one
    installHandler();
    return i;
  }
  return -1;
}

void removeLive(int& slot) {
  if (slot >= 0) liveTemporaries[slot].state.store(kFree);
  slot = -1;
}

// Holds the handled signals back on this thread while alive; a held signal is delivered (and
// ends the program) when it ends, unless absorbed.
class SignalsHeld {
 public:
  SignalsHeld() {
    sigemptyset(&held_);
    for (const int s : AtomicFile::endingSignals()) sigaddset(&held_, s);
    ::pthread_sigmask(SIG_BLOCK, &held_, &previous_);
  }
  ~SignalsHeld() { ::pthread_sigmask(SIG_SETMASK, &previous_, nullptr); }
  SignalsHeld(const SignalsHeld&) = delete;
  SignalsHeld& operator=(const SignalsHeld&) = delete;

  // Takes the held signals that came meanwhile, so that they are not delivered at the end.
  void absorb() {
    const timespec now{0, 0};
    while (::sigtimedwait(&held_, nullptr, &now) > 0) {
    }
  }

 private:
  sigset_t held_, previous_;
};

// Renames the files into place with the signals held back on this thread and, for a signal
// another thread takes, `publishing` set (removeTemporariesAndExit). A signal that came meanwhile
// is then too late to stop the run: absorbed once every file is in place.
template <class Publish>
void publishHeld(Publish publishAll) {
  SignalsHeld held;
  publishing.store(kPublishing);
  try {
    publishAll();
  } catch (...) {
    publishing.store(kFailed);
    throw;
  }
  held.absorb();
  publishing.store(kWriting);
}

}  // namespace

bool sameFile(const std::string& a, const std::string& b) {
  struct stat sa {
  }, sb{};
  if (::stat(a.c_str(), &sa) == 0 && ::stat(b.c_str(), &sb) == 0)
    return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
  const auto resolved = [](const std::string& path) {
    // Absolute first: weakly_canonical leaves a relative path with no existing part relative.
    std::error_code error;
    const std::filesystem::path absolute = std::filesystem::absolute(path, error);
    std::filesystem::path p = std::filesystem::weakly_canonical(absolute, error);
    return error ? absolute.lexically_normal() : p.lexically_normal();
  };
  return resolved(a) == resolved(b);
}

void refuseInputAsOutput(const std::string& flag, const std::string& path,
                         const std::vector<InputFile>& inputs) {
  for (const InputFile& input : inputs)
    if (!path.empty() && !input.path.empty() && sameFile(path, input.path))
      throw UsageError(flag + " = " + path + ": the same file as " + input.flag + " = " +
                       input.path + ", which writing would destroy; expected another path");
}

AtomicFile::AtomicFile(std::string path, const std::string& flag, bool keepOthers)
    : path_(std::move(path)), keepOthers_(keepOthers) {
  if (path_.empty()) throw UsageError(flag + " is empty: expected a file path");
  mode_t mode = 0;
  struct stat existing {};
  if (::stat(path_.c_str(), &existing) == 0) {
    existed_ = true;
    before_ = existing;
    if (S_ISDIR(existing.st_mode))
      throw UsageError(flag + " = " + path_ + ": is a directory; expected a file path");
    if (!S_ISREG(existing.st_mode))
      throw UsageError(flag + " = " + path_ +
                       ": is not a regular file (a device or a pipe); expected a file path");
    // Replace what a symlink points to, not the link; keep the file's permissions.
    if (char* resolved = ::realpath(path_.c_str(), nullptr)) {
      path_ = resolved;
      std::free(resolved);
    }
    mode = existing.st_mode & 07777;
  } else {
    struct stat link {};
    if (::lstat(path_.c_str(), &link) == 0 && S_ISLNK(link.st_mode)) {
      std::error_code error;
      const std::string target = std::filesystem::read_symlink(path_, error).string();
      throw UsageError(flag + " = " + path_ + ": a symbolic link to " +
                       (error ? "an unreadable target" : target) +
                       ", which does not exist; expected a new path, an existing file or a link "
                       "to one");
    }
    // mkstemp makes the file 0600; a new output gets the usual 0666 less the umask.
    const mode_t mask = ::umask(0);
    ::umask(mask);
    mode = 0666 & ~mask;
  }
  removeStaleTemporaries(path_);
  std::string pattern = path_ + ".tmp-" + std::to_string(::getpid()) + "-XXXXXX";
  std::vector<char> name(pattern.begin(), pattern.end());
  name.push_back('\0');
  // The signal handler must know the temporary from the moment it exists: hold the signals
  // until it is in the table.
  int fd = -1;
  {
    SignalsHeld held;
    fd = mkstemp(name.data());
    if (fd >= 0) {
      slot_ = addLive(name.data());
      if (slot_ < 0) {
        ::close(fd);
        ::unlink(name.data());
        throw std::runtime_error(flag + " = " + path_ +
                                 ": too many output files open at once (at most " +
                                 std::to_string(kMaxLive) + ")");
      }
    }
  }
  if (fd < 0)
    throw UsageError(flag + " = " + path_ + ": cannot write there (" + std::strerror(errno) +
                     "); expected a path in an existing, writable directory");
  temporary_ = name.data();
  ::fchmod(fd, mode);
  file_ = fdopen(fd, "w");
  if (!file_) {
    const int err = errno;
    ::close(fd);
    std::remove(temporary_.c_str());
    removeLive(slot_);
    throw UsageError(flag + " = " + path_ + ": cannot write there (" + std::strerror(err) + ")");
  }
}

AtomicFile::~AtomicFile() { discard(); }

void AtomicFile::discard() {
  if (file_) std::fclose(file_);
  file_ = nullptr;
  if (!temporary_.empty()) std::remove(temporary_.c_str());
  temporary_.clear();
  removeLive(slot_);
}

void AtomicFile::finish() {
  if (finished_) return;
  if (!file_) throw std::logic_error("AtomicFile::finish after a failed finish");
  errno = 0;
  // On the disk before the rename makes it the file (fsync): otherwise a power cut soon after
  // could leave the new name on an empty or partial file, where the old one was whole.
  const bool written =
      std::fflush(file_) == 0 && !std::ferror(file_) && ::fsync(::fileno(file_)) == 0;
  const int writeError = errno;
  const bool closed = std::fclose(file_) == 0;
  const int closeError = errno;
  file_ = nullptr;
  if (!written || !closed)
    throw std::runtime_error(
        "writing " + path_ + " failed: " +
        (!written ? (writeError != 0 ? std::strerror(writeError) : "an earlier write failed")
                  : std::strerror(closeError)));
  finished_ = true;
}

bool AtomicFile::writtenByAnother() const {
  struct stat now {};
  if (::stat(path_.c_str(), &now) != 0) return false;  // none there (or removed): nothing to keep
  return !existed_ || now.st_dev != before_.st_dev || now.st_ino != before_.st_ino ||
         now.st_size != before_.st_size || now.st_mtim.tv_sec != before_.st_mtim.tv_sec ||
         now.st_mtim.tv_nsec != before_.st_mtim.tv_nsec;
}

namespace {

// rename(2) that never replaces: 0, or the errno (EEXIST: a file is there). Where the file system
// takes no rename flags (NFS, 9p, FUSE without rename2: EINVAL; an old kernel: ENOSYS), a hard
// link does the same (link(2) never replaces either); where it has no hard links (vfat), a check
// and a plain rename, which a file appearing between the two would lose.
int renameNoReplace(const char* from, const char* to) {
  if (::renameat2(AT_FDCWD, from, AT_FDCWD, to, RENAME_NOREPLACE) == 0) return 0;
  if (errno != EINVAL && errno != ENOSYS && errno != EOPNOTSUPP) return errno;
  if (::link(from, to) == 0) {
    ::unlink(from);
    return 0;
  }
  if (errno == EEXIST) return EEXIST;
  struct stat there {};
  if (::lstat(to, &there) == 0) return EEXIST;
  return std::rename(from, to) == 0 ? 0 : errno;
}

}  // namespace

// NAME-2.EXT, NAME-3.EXT, …: the first free one, taken without replacing, so that a file
// appearing meanwhile is not lost either.
void AtomicFile::publishBeside() {
  const std::filesystem::path target(path_);
  const std::string stem = (target.parent_path() / target.stem()).string();
  for (int n = 2; n < 1000; ++n) {
    const std::string beside = stem + "-" + std::to_string(n) + target.extension().string();
    const int error = renameNoReplace(temporary_.c_str(), beside.c_str());
    if (error == 0) {
      path_ = beside;
      movedAside_ = true;
      return;
    }
    if (error != EEXIST)
      throw std::runtime_error("cannot move the output beside " + path_ + " (as " + beside +
                               "): " + std::strerror(error));
  }
  throw std::runtime_error("cannot move the output beside " + path_ +
                           ": every name up to -999 is taken");
}

void AtomicFile::publish() {
  if (!finished_) throw std::logic_error("AtomicFile::publish before finish");
  if (temporary_.empty()) return;  // already published
  if (keepOthers_ && writtenByAnother()) {
    publishBeside();
  } else if (keepOthers_ && !existed_) {  // none there: keep one that appears at the last moment
    const int error = renameNoReplace(temporary_.c_str(), path_.c_str());
    if (error == EEXIST) {
      publishBeside();
    } else if (error != 0) {
      throw std::runtime_error("cannot move the output onto " + path_ + ": " +
                               std::strerror(error));
    }
  } else if (std::rename(temporary_.c_str(), path_.c_str()) != 0) {
    throw std::runtime_error("cannot move the output onto " + path_ + ": " + std::strerror(errno));
  }
  temporary_.clear();
  removeLive(slot_);
}

void AtomicFile::commit() {
  finish();
  publishHeld([this] { publish(); });
}

void commitTogether(std::initializer_list<AtomicFile*> files) {
  for (AtomicFile* file : files)
    if (file) file->finish();  // the first failure throws; the destructors remove them all
  publishHeld([&files] {
    std::vector<AtomicFile*> created;  // published where no file was: removed again on a failure
    for (AtomicFile* file : files) {
      if (!file) continue;
      struct stat existing {};
      const bool isNew = ::lstat(file->path().c_str(), &existing) != 0;
      try {
        file->publish();
      } catch (...) {
        for (AtomicFile* done : created) ::unlink(done->path().c_str());
        throw;
      }
      if (isNew) created.push_back(file);
    }
  });
}

}  // namespace hamiltone::cli
