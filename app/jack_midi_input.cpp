// JackMidiInput: the client's life (open inactive, register, activate; deactivate, close), the port
// list, and the process callback that hands each event on with its arrival time.
#include "jack_midi_input.h"

#include <jack/midiport.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>

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
  if (!client_)
    throw MidiError("MIDI input on jack: no JACK server answers (jack_client_open status " +
                    hex(static_cast<unsigned>(status)) +
                    "); start one (jackd, or qjackctl) or choose --api alsa");
  // Both before activation, as libjack asks.
  jack_set_process_callback(client_, &JackMidiInput::process, this);
  jack_on_shutdown(client_, &JackMidiInput::serverGone, this);
  nsPerFrame_ = 1e9 / jack_get_sample_rate(client_);
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
    // Not active yet, so the port may go now without a latency recompute to race with.
    jack_port_unregister(client_, port_);
    port_ = nullptr;
    throw MidiError("cannot activate the JACK client of MIDI port \"" + portName + "\"");
  }
  if (!source.empty()) connect(source);
}

void JackMidiInput::connect(const std::string& source) {
  if (!port_) throw MidiError("no JACK MIDI input port is open");
  const int result = jack_connect(client_, source.c_str(), jack_port_name(port_));
  if (result != 0 && result != EEXIST)
    throw MidiError("cannot connect the MIDI port \"" + source + "\" to " + jack_port_name(port_) +
                    " (jack_connect returned " + std::to_string(result) + ")");
}

void JackMidiInput::close() noexcept {
  if (!client_) return;
  // Deactivated first: the server then leaves the client out of the graph before its port goes
  // with it, and calls none of its callbacks again.
  if (port_ && !gone_.load()) jack_deactivate(client_);
  jack_client_close(client_);
  client_ = nullptr;
  port_ = nullptr;
}

int JackMidiInput::process(jack_nframes_t frames, void* self) {
  auto* in = static_cast<JackMidiInput*>(self);
  void* buffer = jack_port_get_buffer(in->port_, frames);
  const jack_nframes_t count = jack_midi_get_event_count(buffer);
  if (count == 0) return 0;
  // The period this callback reads ended now: an event at frame t of it arrived (frames − t)
  // frames ago.
  const std::int64_t now = steadyNanoseconds();
  for (jack_nframes_t i = 0; i < count; ++i) {
    jack_midi_event_t event;
    if (jack_midi_event_get(&event, buffer, i) != 0) continue;
    const double ago = static_cast<double>(frames - std::min(event.time, frames)) * in->nsPerFrame_;
    const std::int64_t at = std::max<std::int64_t>(now - std::llround(ago), in->lastArrivalNs_);
    in->lastArrivalNs_ = at;
    in->arrival_(event.buffer, event.size, at, in->user_);
  }
  return 0;
}

void JackMidiInput::serverGone(void* self) { static_cast<JackMidiInput*>(self)->gone_.store(true); }

}  // namespace hamiltone::app
