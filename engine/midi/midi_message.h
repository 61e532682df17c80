// A MIDI channel voice message (note, controller, program, bend), the unit every source of
// events hands the synthesizer: a MIDI file, the --notes list, or a live port.
#pragma once

#include <cstdint>

namespace hamiltone {

struct MidiMessage {
  std::uint8_t status = 0;  // 0x80 … 0xEF: the kind in the high nibble, the channel in the low
  std::uint8_t data1 = 0;   // 0 … 127
  std::uint8_t data2 = 0;   // 0 … 127 (unused by program change and channel pressure)

  int kind() const { return status & 0xF0; }
  int channel() const { return status & 0x0F; }
};

namespace midi {
inline constexpr int noteOff = 0x80, noteOn = 0x90, polyPressure = 0xA0, controller = 0xB0,
                     program = 0xC0, channelPressure = 0xD0, pitchBend = 0xE0;
inline constexpr int sustainPedal = 64, sostenutoPedal = 66, softPedal = 67, volume = 7,
                     allSoundOff = 120, resetControllers = 121, allNotesOff = 123;
}  // namespace midi

// A message at a time in seconds from the start of a performance.
struct TimedMessage {
  double seconds = 0.0;
  MidiMessage message;
};

}  // namespace hamiltone
