// The player's JACK MIDI input under RealtimeSanitizer: JackMidiInput::process, which libjack runs
// on the server's real-time process thread, is [[clang::nonblocking]], so in this binary (its
// sources compiled with -fsanitize=realtime) any allocation, lock or blocking syscall made while
// it hands a period's events to MidiInput's lock-free queue — by our code, the C++ library or
// libjack's own calls into libc — ends the process with a report and a nonzero exit.
// A JACK server of its own (jackd on the dummy driver, named for this process) runs for the test;
// a client here plays seven note-ons and offs a period at spread frames into the player's input
// port for 2 s, and every one must arrive (at least 100 where the server's dummy driver reported
// an xrun, which may lose some). Exit 77 (skipped) without jackd, a failure with CI=true. Without
// GoogleTest: nothing but the code under test runs.
#include <jack/jack.h>
#include <jack/midiport.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>

#include "midi_input.h"
#include "support/child_process.h"

namespace {

constexpr int kPerPeriod = 7;  // note-ons and offs written a period

// The keyboard: kPerPeriod events at spread frames of every period, counted as written.
struct Keys {
  jack_port_t* out = nullptr;
  std::atomic<long> written{0};
  std::atomic<bool> playing{false};
  std::atomic<int> xruns{0};  // the dummy driver's on a busy host: events may be lost then
  int note = 0;

  static int xrun(void* self) {
    static_cast<Keys*>(self)->xruns.fetch_add(1);
    return 0;
  }

  static int process(jack_nframes_t frames, void* self) {
    auto* keys = static_cast<Keys*>(self);
    void* buffer = jack_port_get_buffer(keys->out, frames);
    jack_midi_clear_buffer(buffer);
    if (!keys->playing.load()) return 0;
    for (int i = 0; i < kPerPeriod; ++i) {
      const unsigned char event[3] = {static_cast<unsigned char>(i % 2 ? 0x80 : 0x90),
                                      static_cast<unsigned char>(36 + keys->note++ % 60), 100};
      if (jack_midi_event_write(buffer, frames * i / kPerPeriod, event, sizeof event) == 0)
        keys->written.fetch_add(1);
    }
    return 0;
  }
};

}  // namespace

int main() {
  using namespace std::chrono_literals;
  if (!hamiltone::testing::onPath("jackd")) {
    // CI installs it (scripts/install-deps.sh): there its absence is a failure, not a skip.
    const char* ci = std::getenv("CI");
    std::printf("jackd (Debian's jackd2) is not installed: %s\n",
                ci && std::string(ci) == "true" ? "FAILED (CI=true)" : "skipped");
    return ci && std::string(ci) == "true" ? 1 : 77;
  }
  const std::string server = "hamiltone-rtsan-" + std::to_string(getpid());
  setenv("JACK_DEFAULT_SERVER", server.c_str(), 1);
  setenv("JACK_NO_START_SERVER", "1", 1);
  const char* argv[] = {"jackd", "-n",    server.c_str(), "--no-realtime", "-d",   "dummy",
                        "-r",    "48000", "-p",           "256",           nullptr};
  // The server ends with this process, whichever way it ends (RTSan's report exits at once).
  const pid_t parent = getpid();
  const pid_t jackd = fork();
  if (jackd == 0) {
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(1);
    execvp("jackd", const_cast<char**>(argv));
    _exit(127);
  }
  if (jackd < 0) {
    std::printf("cannot start jackd\n");
    return 1;
  }
  int failures = 0;
  {
    jack_client_t* client = nullptr;
    bool exited = false;  // jackd gave up (its reason above, e.g. too many servers registered)
    for (int i = 0; i < 150 && !client && !exited; ++i) {
      client = jack_client_open("rtsan-keys", JackNoStartServer, nullptr);
      if (!client) std::this_thread::sleep_for(100ms);
      exited = !client && waitpid(jackd, nullptr, WNOHANG) == jackd;
    }
    if (!client) {
      std::printf("the JACK server did not come up%s\n", exited ? ": jackd exited" : " in 15 s");
      if (!exited) {
        kill(jackd, SIGTERM);
        waitpid(jackd, nullptr, 0);
      }
      return 1;
    }
    Keys keys;
    keys.out = jack_port_register(client, "out", JACK_DEFAULT_MIDI_TYPE, JackPortIsOutput, 0);
    jack_set_process_callback(client, &Keys::process, &keys);
    jack_set_xrun_callback(client, &Keys::xrun, &keys);
    long received = 0;
    try {
      hamiltone::app::MidiInput input("jack");
      input.openVirtualPort("hamiltone-in");
      if (!keys.out || jack_activate(client) != 0 ||
          jack_connect(client, jack_port_name(keys.out), "hamiltone:hamiltone-in") != 0) {
        std::printf("cannot connect the keys to the player's input\n");
        ++failures;
      }
      // The graph takes the connection at a cycle's start: played from then on, every event
      // written reaches the port.
      for (int i = 0; i < 100 && keys.out && jack_port_connected(keys.out) == 0; ++i)
        std::this_thread::sleep_for(10ms);
      std::this_thread::sleep_for(100ms);
      keys.xruns.store(0);
      keys.playing.store(true);
      hamiltone::app::StampedMessage messages[256];
      auto drain = [&] {
        for (size_t n; (n = input.queue().pop(messages, 256)) > 0;)
          received += static_cast<long>(n);
      };
      const auto end = std::chrono::steady_clock::now() + 2s;
      while (std::chrono::steady_clock::now() < end) {
        drain();
        std::this_thread::sleep_for(5ms);
      }
      keys.playing.store(false);
      // The last periods' events, within a second.
      for (int i = 0; i < 200 && received < keys.written.load(); ++i) {
        std::this_thread::sleep_for(5ms);
        drain();
      }
      const int xruns = keys.xruns.load();
      std::printf("%ld events written, %ld received, %ld dropped, %d xruns\n", keys.written.load(),
                  received, input.dropped(), xruns);
      // The callback ran (RTSan watched it) whatever the host; every event is asked for only
      // where the server kept time.
      if (received < 100 || input.dropped() != 0 || (xruns == 0 && received != keys.written.load()))
        ++failures;
      input.close();
    } catch (const hamiltone::app::MidiError& e) {
      std::printf("%s\n", e.what());
      ++failures;
    }
    jack_client_close(client);
  }
  kill(jackd, SIGTERM);
  waitpid(jackd, nullptr, 0);
  std::printf("%s\n", failures ? "FAILED" : "passed");
  return failures ? 1 : 0;
}
