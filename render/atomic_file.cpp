// mkstemp in the target's directory, so the final rename(2) is atomic on the same file system.
#include "atomic_file.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "usage_error.h"

namespace hamiltone::cli {

AtomicFile::AtomicFile(std::string path, const std::string& flag) : path_(std::move(path)) {
  if (path_.empty()) throw UsageError(flag + " is empty: expected a file path");
  struct stat existing {};
  if (::stat(path_.c_str(), &existing) == 0 && S_ISDIR(existing.st_mode))
    throw UsageError(flag + " = " + path_ + ": is a directory; expected a file path");
  std::string pattern = path_ + ".tmp-XXXXXX";
  std::vector<char> name(pattern.begin(), pattern.end());
  name.push_back('\0');
  const int fd = mkstemp(name.data());
  if (fd < 0)
    throw UsageError(flag + " = " + path_ + ": cannot write there (" + std::strerror(errno) +
                     "); expected a path in an existing, writable directory");
  temporary_ = name.data();
  // mkstemp makes the file 0600; the output gets the usual permissions (0666 less the umask).
  const mode_t mask = ::umask(0);
  ::umask(mask);
  ::fchmod(fd, 0666 & ~mask);
  file_ = fdopen(fd, "w");
  if (!file_) {
    const int err = errno;
    ::close(fd);
    std::remove(temporary_.c_str());
    throw UsageError(flag + " = " + path_ + ": cannot write there (" + std::strerror(err) + ")");
  }
}

AtomicFile::~AtomicFile() {
  if (file_) std::fclose(file_);
  if (!temporary_.empty()) std::remove(temporary_.c_str());
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
}

}  // namespace hamiltone::cli
