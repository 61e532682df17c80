// The signals that stop hamiltone-play, taken by a thread of their own. The first asks the main
// thread to stop; the main thread then closes the MIDI input and the stream and completes the
// recording. A JACK server that is stopped (SIGSTOP) or hung blocks those calls, and did so for as
// long as it stayed hung, with every further signal held and the recording unfinished. So if the
// program has not ended kGraceSeconds after the first signal, or a second one comes, this thread
// completes the recording itself and ends the program without waiting for the server.
#pragma once

#include <semaphore.h>
#include <signal.h>

#include <atomic>
#include <string>
#include <thread>

namespace hamiltone::app {

class Recorder;

class StopSignals {
 public:
  static constexpr double kGraceSeconds = 5.0;

  // `signals` must be blocked in every thread (the caller's, and those it starts afterwards).
  explicit StopSignals(const sigset_t& signals);
  ~StopSignals();  // the program ended on its own: the thread ends too
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  // Waits up to `timeout` for the first signal; returns it, or −1.
  int wait(const timespec& timeout);
  // The recording to complete on a forced end (null: none), from its temporary's creation.
  void setRecorder(Recorder* recorder) { recorder_.store(recorder); }
  // The stream is closed: nothing is left that a hung server could hold, and what the main thread
  // does now (the recording's last write and fsync, which a slow disk can stretch past the grace
  // period) is left to it.
  void released() { released_.store(true); }

 private:
  void watch();
  [[noreturn]] void forceEnd(int signal, const char* why);

  sigset_t signals_;
  sem_t first_;  // posted once, at the first signal
  std::atomic<int> signal_{-1};
  std::atomic<bool> ended_{false}, released_{false};
  std::atomic<Recorder*> recorder_{nullptr};
  std::thread thread_;
};

// The exit code for a stop by `signal`: 0 for the signals meant to stop a program (SIGINT,
// SIGTERM, SIGHUP), 128 + N for another, as a shell reports it.
int stopExitCode(int signal);

std::string signalName(int signal);

}  // namespace hamiltone::app
