// Programs a test starts and stops itself, by their PID, and what such a test needs around them:
// whether a program is installed, and a file's text.
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace hamiltone::testing {

inline std::string slurp(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

inline bool onPath(const std::string& program) {
  std::stringstream path(std::getenv("PATH") ? std::getenv("PATH") : "");
  for (std::string dir; std::getline(path, dir, ':');)
    if (::access((std::filesystem::path(dir) / program).c_str(), X_OK) == 0) return true;
  return false;
}

// A process started with posix_spawnp, stdin from /dev/null — or from a pipe this end holds open
// until closeStdin() or the end, for a program that stops at the end of its input — stdout and
// stderr to files. The destructor stops it if it still runs: SIGTERM, then SIGKILL after 3 s.
class Child {
 public:
  enum class Stdin { null, pipe };

  Child(const std::vector<std::string>& argv, const std::vector<std::string>& env,
        const std::filesystem::path& out, const std::filesystem::path& err,
        Stdin in = Stdin::null) {
    std::vector<char*> args, vars;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    for (const std::string& v : env) vars.push_back(const_cast<char*>(v.c_str()));
    args.push_back(nullptr);
    vars.push_back(nullptr);
    posix_spawn_file_actions_t files;
    posix_spawn_file_actions_init(&files);
    int pipe[2] = {-1, -1};
    if (in == Stdin::pipe && ::pipe2(pipe, O_CLOEXEC) == 0) {
      posix_spawn_file_actions_adddup2(&files, pipe[0], 0);
      stdin_ = pipe[1];
    } else {
      posix_spawn_file_actions_addopen(&files, 0, "/dev/null", O_RDONLY, 0);
    }
    posix_spawn_file_actions_addopen(&files, 1, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addopen(&files, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (posix_spawnp(&pid_, args[0], &files, nullptr, args.data(), vars.data()) != 0) pid_ = -1;
    posix_spawn_file_actions_destroy(&files);
    if (pipe[0] >= 0) ::close(pipe[0]);
  }
  ~Child() {
    closeStdin();
    if (pid_ <= 0 || status_) return;
    signal(SIGTERM);
    if (!wait(3.0)) {
      signal(SIGKILL);
      wait(60.0);
    }
  }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  bool started() const { return pid_ > 0; }
  void closeStdin() {
    if (stdin_ >= 0) ::close(stdin_);
    stdin_ = -1;
  }
  void signal(int number) const {
    if (pid_ > 0 && !status_) ::kill(pid_, number);
  }
  // The exit code (128 + N when killed by signal N), or nothing while it runs after `seconds`.
  std::optional<int> wait(double seconds) {
    using Clock = std::chrono::steady_clock;
    const auto deadline = Clock::now() + std::chrono::duration<double>(seconds);
    while (pid_ > 0 && !status_) {
      int raw = 0;
      if (::waitpid(pid_, &raw, WNOHANG) == pid_)
        status_ = WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + WTERMSIG(raw);
      else if (Clock::now() >= deadline)
        break;
      else
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return status_;
  }

 private:
  pid_t pid_ = -1;
  int stdin_ = -1;  // the pipe's end to the child's stdin
  std::optional<int> status_;
};

}  // namespace hamiltone::testing
