// MIDI input: a real port or a virtual one the player creates, on ALSA through RtMidi 5 and on JACK
// through a libjack client of its own (jack_midi_input.h). Each channel message is timestamped on
// arrival and copied into a lock-free queue that the audio thread drains; anything else — sysex,
// clock, active sensing — is left out.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "midi/midi_message.h"
#include "synth/spsc_queue.h"

namespace hamiltone::app {

struct MidiError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A message and its arrival on the steady clock, in nanoseconds.
struct StampedMessage {
  std::int64_t arrivalNs = 0;
  MidiMessage message;
};

std::int64_t steadyNanoseconds();

// "0: NAME; 1: NAME …", or "none".
std::string portList(const std::vector<std::string>& names);

// A port's name without the " CLIENT:PORT" numbers RtMidi appends on ALSA ("Keystation 88:
// Keystation 88 MIDI 1 24:0"), or the " [CLIENT]" of a2j's JACK names ("a2j:Keystation [24]
// (capture): Keystation 88 MIDI 1"), which a keyboard plugged in again may change.
std::string stablePortName(const std::string& name);

class MidiInput {
 public:
  static constexpr size_t kQueueSize = 4096;

  // api: "jack" or "alsa" (PulseAudio has no MIDI: it uses ALSA's sequencer). Throws MidiError.
  // On JACK the client is made here, or when first needed if no server answered: without one,
  // ports() is empty and opening a port throws.
  explicit MidiInput(const std::string& api);
  ~MidiInput();
  std::vector<std::string> ports();
  void openPort(int port);  // throws MidiError listing the ports
  void openVirtualPort(const std::string& name);
  void close();
  // The port openPort() connected to ("" with none, or a virtual port), and whether it is still
  // there — asked of a client of its own, from the main thread, polled. Names are compared without
  // the client:port numbers ALSA's carry, which change when a keyboard is plugged in again.
  const std::string& portName() const { return portName_; }
  bool portPresent();
  // Connects again to the port of that name (as portPresent() compares them), wherever it is now.
  // Throws MidiError.
  void reconnect();
  // On JACK: the port went and came back since the last call, too fast for a poll of
  // portPresent() to see it gone, and is not connected now (JackMidiInput::sourceReturned()); it
  // takes reconnect(). Elsewhere false: RtMidi does not say whether its subscription still holds.
  bool portReturned();

  SpscQueue<StampedMessage>& queue() { return queue_; }
  long dropped() const { return dropped_.load(); }  // the queue was full

 private:
  static void arrived(double, std::vector<unsigned char>* bytes, void* self);  // RtMidi's thread
  static void arrivedOnJack(const unsigned char* bytes, size_t size, std::int64_t arrivalNs,
                            void* self) noexcept;  // JACK's process thread
  void push(const unsigned char* bytes, size_t size, std::int64_t arrivalNs) noexcept;
  void openOnJack(const std::string& portName, const std::string& source);

  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::string api_, portName_;
  SpscQueue<StampedMessage> queue_{kQueueSize};
  std::atomic<long> dropped_{0};
};

}  // namespace hamiltone::app
