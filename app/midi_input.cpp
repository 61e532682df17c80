// MidiInput: the port on RtMidi 5 (ALSA) or on a libjack client of our own (JACK), the arrival
// callbacks that keep only channel voice messages, and errors that name the ports there are.
#include "midi_input.h"

#include <RtMidi.h>

#include <algorithm>
#include <chrono>

#include "jack_midi_input.h"
#include "quiet_stderr.h"

namespace hamiltone::app {

std::int64_t steadyNanoseconds() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

std::string portList(const std::vector<std::string>& names) {
  std::string list;
  for (size_t i = 0; i < names.size(); ++i)
    list += (i ? "; " : "") + std::to_string(i) + ": " + names[i];
  return list.empty() ? "none" : list;
}

std::string stablePortName(const std::string& name) {
  // a2j's "a2j:CLIENT [N] (capture): PORT": N is the ALSA client number.
  if (name.rfind("a2j:", 0) == 0) {
    const size_t open = name.find(" ["),
                 close = name.find("] (", open == std::string::npos ? 0 : open);
    if (open != std::string::npos && close != std::string::npos && close > open + 2 &&
        std::all_of(name.begin() + static_cast<long>(open) + 2,
                    name.begin() + static_cast<long>(close),
                    [](char c) { return c >= '0' && c <= '9'; }))
      return name.substr(0, open) + name.substr(close + 1);
  }
  const size_t space = name.rfind(' ');
  if (space == std::string::npos) return name;
  const std::string tail = name.substr(space + 1);
  const size_t colon = tail.find(':');
  const auto digits = [](const std::string& t) {
    return !t.empty() &&
           std::all_of(t.begin(), t.end(), [](char c) { return c >= '0' && c <= '9'; });
  };
  if (colon == std::string::npos || !digits(tail.substr(0, colon)) ||
      !digits(tail.substr(colon + 1)))
    return name;
  return name.substr(0, space);
}

struct MidiInput::Impl {
  // ALSA (and PulseAudio, which has no MIDI of its own): RtMidi.
  std::unique_ptr<RtMidiIn> in;
  std::unique_ptr<RtMidiIn> watcher;  // lists the ports while `in` has one open
  // JACK: a client of our own, made at once — before the audio client, which takes the name
  // "hamiltone" too, so that our ports keep it: "hamiltone:hamiltone-in" — or when first needed
  // (none while no server answers).
  std::unique_ptr<JackMidiInput> jack;
  bool open = false;  // RtMidi's port and callback are set (JACK's: jack->isOpen())

  JackMidiInput& jackClient() {
    if (!jack) {
      const QuietStderr quiet;  // libjack's own lines on a server that is not there
      jack = std::make_unique<JackMidiInput>("hamiltone");
    }
    return *jack;
  }
};

MidiInput::MidiInput(const std::string& api) : impl_(std::make_unique<Impl>()), api_(api) {
  if (api == "jack") {
    try {
      impl_->jackClient();
    } catch (const MidiError&) {  // no server yet: ports() is empty, opening a port says why
    }
    return;
  }
  const RtMidi::Api id = RtMidi::getCompiledApiByName(api == "pulse" ? "alsa" : api);
  if (id == RtMidi::UNSPECIFIED || id == RtMidi::RTMIDI_DUMMY)
    throw MidiError("MIDI API \"" + api + "\" is not available in this build");
  try {
    const QuietStderr quiet;
    impl_->in = std::make_unique<RtMidiIn>(id, "hamiltone");
    impl_->in->ignoreTypes(true, true, true);  // sysex, clock/timing, active sensing
  } catch (const RtMidiError& e) {
    throw MidiError("MIDI input on " + api + ": " + e.getMessage());
  }
}

MidiInput::~MidiInput() { close(); }

std::vector<std::string> MidiInput::ports() {
  if (api_ == "jack") {
    try {
      return impl_->jackClient().sources();
    } catch (const MidiError&) {
      return {};  // no server
    }
  }
  std::vector<std::string> names;
  const QuietStderr quiet;
  try {
    const unsigned count = impl_->in->getPortCount();
    for (unsigned i = 0; i < count; ++i) names.push_back(impl_->in->getPortName(i));
  } catch (const RtMidiError&) {
  }
  return names;
}

void MidiInput::openPort(int port) {
  const std::vector<std::string> names = ports();
  if (port < 0 || port >= static_cast<int>(names.size()))
    throw MidiError("--midi-port " + std::to_string(port) +
                    ": no such MIDI input port; ports: " + portList(names));
  const std::string& name = names[static_cast<size_t>(port)];
  if (api_ == "jack") {
    openOnJack("hamiltone-in", name);
  } else {
    try {
      const QuietStderr quiet;
      impl_->in->setCallback(&MidiInput::arrived, this);
      impl_->in->openPort(static_cast<unsigned>(port), "hamiltone-in");
    } catch (const RtMidiError& e) {
      throw MidiError("cannot open MIDI port " + std::to_string(port) + ": " + e.getMessage());
    }
    impl_->open = true;
  }
  portName_ = name;
}

void MidiInput::openVirtualPort(const std::string& name) {
  if (api_ == "jack") {
    openOnJack(name, "");
  } else {
    try {
      const QuietStderr quiet;
      impl_->in->setCallback(&MidiInput::arrived, this);
      impl_->in->openVirtualPort(name);
    } catch (const RtMidiError& e) {
      throw MidiError("cannot create the virtual MIDI port \"" + name + "\": " + e.getMessage());
    }
    impl_->open = true;
  }
}

// A port that failed to open takes its client along (made again when next needed): whatever
// state it failed in, no callback is left to fill the queue.
void MidiInput::openOnJack(const std::string& portName, const std::string& source) {
  try {
    impl_->jackClient().open(portName, source, &MidiInput::arrivedOnJack, this);
  } catch (const MidiError&) {
    impl_->jack.reset();
    throw;
  }
}

bool MidiInput::portPresent() {
  if (portName_.empty()) return true;
  std::vector<std::string> names;
  if (api_ == "jack") {
    names = ports();
  } else {
    const QuietStderr quiet;
    try {
      if (!impl_->watcher)
        impl_->watcher = std::make_unique<RtMidiIn>(
            RtMidi::getCompiledApiByName(api_ == "pulse" ? "alsa" : api_), "hamiltone-watch");
      const unsigned count = impl_->watcher->getPortCount();
      for (unsigned i = 0; i < count; ++i) names.push_back(impl_->watcher->getPortName(i));
    } catch (const RtMidiError&) {
      return true;  // cannot tell
    }
  }
  return std::any_of(names.begin(), names.end(), [&](const std::string& n) {
    return stablePortName(n) == stablePortName(portName_);
  });
}

bool MidiInput::portReturned() {
  return api_ == "jack" && impl_->jack && impl_->jack->sourceReturned();
}

void MidiInput::reconnect() {
  const std::string name = portName_;
  const std::vector<std::string> names = ports();
  const auto found = std::find_if(names.begin(), names.end(), [&](const std::string& n) {
    return stablePortName(n) == stablePortName(name);
  });
  if (found == names.end()) throw MidiError("MIDI input port \"" + name + "\" is not there");
  if (api_ == "jack" && impl_->jack && impl_->jack->isOpen()) {
    // The port stays registered; only the connection, which went with the keyboard, is made again.
    impl_->jack->connect(*found);
    portName_ = *found;
    return;
  }
  close();
  openPort(static_cast<int>(found - names.begin()));
}

void MidiInput::close() {
  if (api_ == "jack") {
    // Whether or not a port opened (connecting it may have failed on an active client):
    // deactivated, then closed, and no callback after this, before the queue it fills goes.
    impl_->jack.reset();
    return;
  }
  if (!impl_->open) return;
  impl_->open = false;
  const QuietStderr quiet;
  try {
    impl_->in->closePort();
    impl_->in->cancelCallback();
  } catch (const RtMidiError&) {
  }
}

// Channel voice messages (0x80–0xEF, whole) into the queue; anything else — system common, a
// stray data byte — is left out.
void MidiInput::push(const unsigned char* bytes, size_t size, std::int64_t arrivalNs) noexcept {
  if (size == 0) return;
  const unsigned status = bytes[0];
  if (status < 0x80 || status > 0xEF) return;
  const size_t length = (status & 0xF0) == 0xC0 || (status & 0xF0) == 0xD0 ? 2 : 3;
  if (size < length) return;
  const StampedMessage m{
      arrivalNs,
      {static_cast<std::uint8_t>(status), bytes[1], length == 3 ? bytes[2] : std::uint8_t{0}}};
  if (!queue_.push(m)) dropped_.fetch_add(1, std::memory_order_relaxed);
}

void MidiInput::arrived(double, std::vector<unsigned char>* bytes, void* self) {
  static_cast<MidiInput*>(self)->push(bytes->data(), bytes->size(), steadyNanoseconds());
}

void MidiInput::arrivedOnJack(const unsigned char* bytes, size_t size, std::int64_t arrivalNs,
                              void* self) noexcept {
  static_cast<MidiInput*>(self)->push(bytes, size, arrivalNs);
}

}  // namespace hamiltone::app
