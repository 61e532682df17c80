// The stop signals' thread: a poll of a tenth of a second, so that it ends soon after the program.
#include "stop_signals.h"

#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <ctime>

#include "recorder.h"

namespace hamiltone::app {

namespace {

constexpr timespec kPoll{0, 100'000'000};

double secondsSince(const timespec& start) {
  timespec now{};
  ::clock_gettime(CLOCK_MONOTONIC, &now);
  return double(now.tv_sec - start.tv_sec) + 1e-9 * double(now.tv_nsec - start.tv_nsec);
}

}  // namespace

std::string signalName(int signal) {
  const char* abbreviation = ::sigabbrev_np(signal);
  return abbreviation ? std::string("SIG") + abbreviation : "signal " + std::to_string(signal);
}

int stopExitCode(int signal) {
  return signal == SIGINT || signal == SIGTERM || signal == SIGHUP ? 0 : 128 + signal;
}

StopSignals::StopSignals(const sigset_t& signals) : signals_(signals) {
  ::sem_init(&first_, 0, 0);
  thread_ = std::thread([this] { watch(); });
}

StopSignals::~StopSignals() {
  ended_.store(true);
  thread_.join();
  ::sem_destroy(&first_);
}

int StopSignals::wait(const timespec& timeout) {
  timespec until{};
  ::clock_gettime(CLOCK_MONOTONIC, &until);
  until.tv_sec += timeout.tv_sec;
  until.tv_nsec += timeout.tv_nsec;
  if (until.tv_nsec >= 1'000'000'000) {
    until.tv_sec += 1;
    until.tv_nsec -= 1'000'000'000;
  }
  if (::sem_clockwait(&first_, CLOCK_MONOTONIC, &until) != 0) return -1;
  ::sem_post(&first_);  // so that a later wait returns at once too
  return signal_.load();
}

void StopSignals::watch() {
  timespec first{};
  while (!ended_.load()) {
    const int s = ::sigtimedwait(&signals_, nullptr, &kPoll);
    if (released_.load()) continue;
    if (s > 0 && signal_.load() < 0) {
      signal_.store(s);
      ::clock_gettime(CLOCK_MONOTONIC, &first);
      ::sem_post(&first_);
    } else if (s > 0) {
      forceEnd(signal_.load(), ("a second signal, " + signalName(s) + ", came").c_str());
    } else if (signal_.load() > 0 && secondsSince(first) > kGraceSeconds) {
      forceEnd(signal_.load(), "the program has not ended 5 s later");
    }
  }
}

void StopSignals::forceEnd(int signal, const char* why) {
  int code = stopExitCode(signal);
  std::string done = "nothing to record";
  if (Recorder* recorder = recorder_.load()) {
    done = recorder->outcome(recorder->finish(), false);
    if (recorder->failed()) code = 1;
  }
  std::fprintf(stderr,
               "\nhamiltone-play: stopped by %s, but %s: an audio server that is stopped or hung "
               "holds the stream; %s; ending without waiting for it\n",
               signalName(signal).c_str(), why, done.c_str());
  std::fflush(stderr);
  ::_exit(code);
}

}  // namespace hamiltone::app
