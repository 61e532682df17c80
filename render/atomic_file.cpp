// mkstemp beside the target, so the final rename(2) is atomic on the same file system; a symlink
// is followed (its target is replaced, the link kept); a device or other special file is refused.
#include "atomic_file.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "usage_error.h"

namespace hamiltone::cli {

namespace {

// The temporary being written, for the signal handler: a fixed buffer, as only async-signal-safe
// calls (unlink, _exit) may touch it there.
char pendingTemporary[PATH_MAX + 32] = {};

extern "C" void removeTemporaryAndExit(int signal) {
  if (pendingTemporary[0] != '\0') ::unlink(pendingTemporary);
  ::_exit(128 + signal);
}

void setPending(const std::string& path) {
  if (path.size() + 1 > sizeof pendingTemporary) return;
  std::memcpy(pendingTemporary, path.c_str(), path.size() + 1);
  std::signal(SIGINT, removeTemporaryAndExit);
  std::signal(SIGTERM, removeTemporaryAndExit);
  std::signal(SIGHUP, removeTemporaryAndExit);
  std::signal(SIGXFSZ, removeTemporaryAndExit);  // past the file-size limit (ulimit -f)
}

void clearPending() { pendingTemporary[0] = '\0'; }

}  // namespace

AtomicFile::AtomicFile(std::string path, const std::string& flag) : path_(std::move(path)) {
  if (path_.empty()) throw UsageError(flag + " is empty: expected a file path");
  mode_t mode = 0;
  struct stat existing {};
  if (::stat(path_.c_str(), &existing) == 0) {
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
    // mkstemp makes the file 0600; a new output gets the usual 0666 less the umask.
    const mode_t mask = ::umask(0);
    ::umask(mask);
    mode = 0666 & ~mask;
  }
  std::string pattern = path_ + ".tmp-XXXXXX";
  std::vector<char> name(pattern.begin(), pattern.end());
  name.push_back('\0');
  const int fd = mkstemp(name.data());
  if (fd < 0)
    throw UsageError(flag + " = " + path_ + ": cannot write there (" + std::strerror(errno) +
                     "); expected a path in an existing, writable directory");
  temporary_ = name.data();
  setPending(temporary_);
  ::fchmod(fd, mode);
  file_ = fdopen(fd, "w");
  if (!file_) {
    const int err = errno;
    ::close(fd);
    std::remove(temporary_.c_str());
    clearPending();
    throw UsageError(flag + " = " + path_ + ": cannot write there (" + std::strerror(err) + ")");
  }
}

AtomicFile::~AtomicFile() {
  if (file_) std::fclose(file_);
  if (!temporary_.empty()) std::remove(temporary_.c_str());
  clearPending();
}

void AtomicFile::commit() {
  const bool written = std::fflush(file_) == 0 && !std::ferror(file_);
  const bool closed = std::fclose(file_) == 0;
  file_ = nullptr;
  if (!written || !closed)
    throw std::runtime_error("writing " + path_ + " failed: " + std::strerror(errno));
  if (std::rename(temporary_.c_str(), path_.c_str()) != 0)
    throw std::runtime_error("cannot move the output onto " + path_ + ": " + std::strerror(errno));
  temporary_.clear();
  clearPending();
}

}  // namespace hamiltone::cli
