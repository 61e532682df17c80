// JackMidiInput: the client's life (open inactive, register, activate; deactivate, close), the port
// list, and the process callback that hands each event on with its arrival time.
#include "jack_midi_input.h"

#include <jack/midiport.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <thread>

#include "midi_input.h"

namespace hamiltone::app {

namespace {

std::string hex(unsigned value) {
  char text[16];
  std::snprintf(text, sizeof text, "0x%x", value);
  return text;
}

}  // namespace

JackMidiInput::JackMidiInput(const std::string& clientName) {
  jack_status_t status{};
  client_ = jack_client_open(clientName.c_str(), JackNoStartServer, &status);
  if (!client_ && (status & JackServerFailed))
    throw MidiError(
        "MIDI input on jack: no JACK server answers; start one (jackd, or qjackctl) "
        "or choose --api alsa");
  if (!client_)
    throw MidiError("MIDI input on jack: the server refused the client \"" + clientName +
                    "\" (jack_client_open status " + hex(static_cast<unsigned>(status)) + ")");
  // All before activation, as libjack asks.
  jack_set_process_callback(client_, &JackMidiInput::process, this);
  jack_set_port_registration_callback(client_, &JackMidiInput::registered, this);
  jack_set_port_connect_callback(client_, &JackMidiInput::connected, this);
  jack_on_shutdown(client_, &JackMidiInput::serverGone, this);
}

JackMidiInput::~JackMidiInput() { close(); }

std::vector<std::string> JackMidiInput::sources() const {
  std::vector<std::string> names;
  if (!client_ || gone_.load()) return names;
  const char** ports = jack_get_ports(client_, nullptr, JACK_DEFAULT_MIDI_TYPE, JackPortIsOutput);
  for (const char** p = ports; p && *p; ++p) names.emplace_back(*p);
  jack_free(ports);
  return names;
}

void JackMidiInput::open(const std::string& portName, const std::string& source, Arrival arrival,
                         void* user) {
  if (port_) throw MidiError("the JACK MIDI input port is open already");
  if (gone_.load()) throw MidiError("the JACK server has shut down");
  arrival_ = arrival;
  user_ = user;
  port_ = jack_port_register(client_, portName.c_str(), JACK_DEFAULT_MIDI_TYPE, JackPortIsInput, 0);
  if (!port_)
    throw MidiError("cannot register the JACK MIDI port \"" + portName +
                    "\" (a port of that name exists, or the name is too long)");
  if (jack_activate(client_) != 0) {
    // libjack may take the client for active already: the port goes with the whole client.
    port_ = nullptr;
    close();
    throw MidiError("cannot activate the JACK client of MIDI port \"" + portName + "\"");
  }
  if (!source.empty()) connect(source);
}

void JackMidiInput::connect(const std::string& source) {
  if (!port_) throw MidiError("no JACK MIDI input port is open");
  {
    // Before jack_connect (and not around it): a registration of the source from here on is seen.
    const std::lock_guard lock(sourceLock_);
    source_ = source;
    sourceRegistered_.store(false);
  }
  const int result = jack_connect(client_, source.c_str(), jack_port_name(port_));
  if (result != 0 && result != EEXIST)
    throw MidiError("cannot connect the MIDI port \"" + source + "\" to " + jack_port_name(port_) +
                    " (jack_connect returned " + std::to_string(result) + ")");
}

bool JackMidiInput::sourceReturned() {
  if (!port_ || gone_.load() || !sourceRegistered_.exchange(false)) return false;
  const std::lock_guard lock(sourceLock_);
  return jack_port_by_name(client_, returned_.c_str()) &&
         !jack_port_connected_to(port_, returned_.c_str());
}

// On the client's notification thread (not the process thread), in the order the graph changed:
// a port of the source's stable name (an a2j port's ALSA client number may change) registered.
void JackMidiInput::registered(jack_port_id_t port, int registering, void* self) {
  auto* in = static_cast<JackMidiInput*>(self);
  const jack_port_t* p = registering ? jack_port_by_id(in->client_, port) : nullptr;
  if (!p) return;
  const std::string name = jack_port_name(p);
  const std::lock_guard lock(in->sourceLock_);
  if (in->source_.empty() || stablePortName(name) != stablePortName(in->source_)) return;
  in->returned_ = name;
  in->sourceRegistered_.store(true);
}

// Likewise: a port of the source's name connected to ours (by us, or by anyone) — nothing left to
// do, so a later disconnection by hand is not undone.
void JackMidiInput::connected(jack_port_id_t a, jack_port_id_t b, int connecting, void* self) {
  auto* in = static_cast<JackMidiInput*>(self);
  const jack_port_t* pa = jack_port_by_id(in->client_, a);
  const jack_port_t* pb = jack_port_by_id(in->client_, b);
  if (!connecting || !pa || !pb || !in->port_) return;
  const std::string ours = jack_port_name(in->port_), nameA = jack_port_name(pa),
                    nameB = jack_port_name(pb);
  if (nameA != ours && nameB != ours) return;
  const std::string& other = nameA == ours ? nameB : nameA;
  const std::lock_guard lock(in->sourceLock_);
  if (!in->source_.empty() && stablePortName(other) == stablePortName(in->source_))
    in->sourceRegistered_.store(false);
}

void JackMidiInput::close() noexcept {
  if (!client_) return;
  if (port_ && !gone_.load()) {
    closing_.store(true);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(250);
    while (returnedClosing_.load() == 0 && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    // Deactivated before it is closed: the port never leaves an active client.
    jack_deactivate(client_);
  }
  jack_client_close(client_);
  client_ = nullptr;
  port_ = nullptr;
}

int JackMidiInput::process(jack_nframes_t frames, void* self) {
  auto* in = static_cast<JackMidiInput*>(self);
  if (in->closing_.load()) {
    in->returnedClosing_.fetch_add(1);
    return 0;
  }
  void* buffer = jack_port_get_buffer(in->port_, frames);
  const jack_nframes_t count = jack_midi_get_event_count(buffer);
  if (count == 0) return 0;
  // An event at frame t of this period is stamped t frames after the cycle's start, on the
  // steady clock (wherever in the cycle the server runs this client). The player's callback, in
  // this cycle or the next, then places the period's events one period later at their spacing.
  std::int64_t start = steadyNanoseconds();
  jack_nframes_t cycleFrames = 0;
  jack_time_t cycleStart = 0, nextStart = 0;
  float periodUs = 0.0f;
  const jack_time_t now = jack_get_time();
  if (jack_get_cycle_times(in->client_, &cycleFrames, &cycleStart, &nextStart, &periodUs) == 0 &&
      now >= cycleStart && now - cycleStart < 1'000'000)
    start -= 1000 * static_cast<std::int64_t>(now - cycleStart);
  const double nsPerFrame = 1e9 / jack_get_sample_rate(in->client_);
  for (jack_nframes_t i = 0; i < count; ++i) {
    jack_midi_event_t event;
    if (jack_midi_event_get(&event, buffer, i) != 0) continue;
    const double after = static_cast<double>(std::min(event.time, frames)) * nsPerFrame;
    const std::int64_t stamp =
        std::max<std::int64_t>(start + std::llround(after), in->lastArrivalNs_);
    in->lastArrivalNs_ = stamp;
    in->arrival_(event.buffer, event.size, stamp, in->user_);
  }
  return 0;
}

void JackMidiInput::serverGone(void* self) { static_cast<JackMidiInput*>(self)->gone_.store(true); }

}  // namespace hamiltone::app
