// MIDI input on a libjack client of its own: one input port, registered before the client is
// activated and never unregistered while it is active — the client is deactivated, then closed.
// RtMidi's JACK input unregisters its port on an active client, which raced with libjack's latency
// recompute (jackd2 1.9.21) and crashed the player at its stop, losing its recording.
#pragma once

#include <jack/jack.h>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "synth/nonblocking.h"

namespace hamiltone::app {

class JackMidiInput {
 public:
  // Called on JACK's process thread for each event, with its bytes and its time on the steady
  // clock (ns): the cycle's start plus the event's frame in the period, so that a period's events
  // keep their spacing and the player plays them one period later whichever of its client and ours
  // the server runs first (app/player.h). Must not allocate, lock or block.
  using Arrival = void (*)(const unsigned char* bytes, size_t size, std::int64_t arrivalNs,
                           void* user);

  // A client named `clientName` (JACK appends a number when the name is taken: make it before the
  // audio client of the same name) on the running server; throws MidiError when there is none.
  // The client stays inactive until a port opens.
  explicit JackMidiInput(const std::string& clientName);
  ~JackMidiInput();
  JackMidiInput(const JackMidiInput&) = delete;
  JackMidiInput& operator=(const JackMidiInput&) = delete;

  // The MIDI output ports of the server's clients ("client:port"); none once the server is gone.
  std::vector<std::string> sources() const;
  // Registers the input port `portName`, activates the client and connects `source` to the port
  // (none: a port for others to connect to). Throws MidiError naming the port; a client that
  // could not be activated is closed.
  void open(const std::string& portName, const std::string& source, Arrival arrival, void* user);
  // Connects `source` to the open port again (a keyboard that came back). Throws MidiError.
  void connect(const std::string& source);
  // Whether a port of the last connected source's stable name (stablePortName) registered since
  // the last call (a keyboard unplugged and plugged in again, its client restarted) and no one
  // connected it to ours since: the connection went with the old port. A source the user
  // disconnected, whose port stayed, is not.
  bool sourceReturned();
  // Deactivates the client, then closes it: no callback runs after this returns. jackd2 cancels
  // the process thread on deactivation, so a callback must not be inside ours then (cancelled in a
  // noexcept function the program would terminate): the callbacks are first told to return at once,
  // and one that has is waited for (250 ms at most: a server that stopped calling).
  void close() noexcept;
  bool isOpen() const { return port_ != nullptr; }

 private:
  static int process(jack_nframes_t frames, void* self) HAMILTONE_NONBLOCKING;  // tests/rtsan
  static void serverGone(void* self);
  static void registered(jack_port_id_t port, int registering, void* self);  // notifications
  static void connected(jack_port_id_t a, jack_port_id_t b, int connecting, void* self);

  jack_client_t* client_ = nullptr;
  jack_port_t* port_ = nullptr;
  Arrival arrival_ = nullptr;
  void* user_ = nullptr;
  std::int64_t lastArrivalNs_ = 0;  // the process thread's: arrivals never go back
  std::atomic<bool> gone_{false};   // the server shut the client down
  std::atomic<bool> closing_{false};
  std::atomic<int> returnedClosing_{0};  // callbacks that returned at once, closing_ set
  // source_ (the port last connected) and returned_ (the port of its stable name that registered
  // since), between connect() and the notification thread.
  std::mutex sourceLock_;
  std::string source_, returned_;
  std::atomic<bool> sourceRegistered_{false};
};

}  // namespace hamiltone::app
