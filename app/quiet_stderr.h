// Silences the process's stderr (file descriptor 2) for a scope: the ALSA and JACK client
// libraries print their probing failures there ("Cannot connect to server socket", "ALSA lib …"),
// which a player that reports its own clear line must not show.
#pragma once

#include <fcntl.h>
#include <unistd.h>

namespace hamiltone::app {

class QuietStderr {
 public:
  QuietStderr() : saved_(::dup(2)) {
    const int null = ::open("/dev/null", O_WRONLY | O_CLOEXEC);
    if (null >= 0) {
      ::dup2(null, 2);
      ::close(null);
    }
  }
  ~QuietStderr() {
    if (saved_ >= 0) {
      ::dup2(saved_, 2);
      ::close(saved_);
    }
  }
  QuietStderr(const QuietStderr&) = delete;
  QuietStderr& operator=(const QuietStderr&) = delete;

 private:
  int saved_;
};

}  // namespace hamiltone::app
