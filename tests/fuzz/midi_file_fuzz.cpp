// libFuzzer target for the Standard MIDI File reader: any input must either parse or be refused
// with a MidiFileError. Any other exception, a crash, or a sanitizer report is a finding.
#include <cstddef>
#include <cstdint>
#include <span>

#include "midi/midi_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const hamiltone::MidiFile midi = hamiltone::parseMidiFile({data, size}, "fuzz.mid");
    // What the reader promises of every file it accepts.
    double previous = 0.0;
    for (const hamiltone::TimedMessage& m : midi.messages) {
      if (m.message.status < 0x80 || m.message.status > 0xEF || m.message.data1 > 0x7F ||
          m.message.data2 > 0x7F || !(m.seconds >= previous) || m.seconds > midi.lengthSeconds)
        __builtin_trap();
      previous = m.seconds;
    }
  } catch (const hamiltone::MidiFileError&) {
  }
  return 0;
}
