// Standard MIDI File reader: formats 0 and 1 into one time-ordered list of channel messages in
// seconds, through the file's tempo map. Hardened for untrusted files: every read is
// bounds-checked, memory grows with the file's size only (never with a count the file declares),
// and every rejection is a MidiFileError naming the byte at fault.
//
// Where real files and the SMF 1.0 specification disagree, the reader is tolerant:
//  - Running status survives meta (FF) and sysex (F0, F7) events. The specification says they
//    cancel it, but files in the wild omit the status byte after a meta event; no valid file
//    reads differently for it, since after a cancelled status a data byte would be an error.
//  - A track chunk may end without an End of Track event (FF 2F 00): the track ends with its
//    chunk. Bytes after an End of Track inside its chunk are ignored.
//  - Chunks of unknown type are skipped, and so is anything after the last declared track.
//  - Set-tempo events (FF 51) apply to all tracks whichever track holds them (format 1 files keep
//    them in track 0 by convention).
// SMPTE timing (division with its top bit set) is supported: a tick lasts 1 / (frames per second
// × ticks per frame), with 29 meaning drop-frame 29.97 fps, and set-tempo events do not change it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "midi/midi_message.h"

namespace hamiltone {

struct MidiFile {
  int format = 0;    // 0 (one track) or 1 (simultaneous tracks); format 2 is rejected
  int tracks = 0;    // track chunks read: as many as the header declares
  int division = 0;  // ticks per quarter note; with SMPTE timing, the header's raw word (≥ 0x8000)
  // Channel voice messages (status 0x80–0xEF) only, in time order; messages at the same time keep
  // track order, then their order in the track, but for a note-on that another track's note-off
  // at that time would follow: the note-off goes first (a key released in one track and struck
  // in another sounds). Note-on with velocity 0 is kept as it is (and is a note-off).
  std::vector<TimedMessage> messages;
  double lengthSeconds = 0.0;  // time of the last event of any kind, End of Track included
};

// A file that cannot be read or is not a Standard MIDI File we accept. The message reads
// "<name>: byte <offset>: <what is wrong and what is valid>"; when the file itself cannot be read,
// "<path>: <why>".
class MidiFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Larger files are refused before they are read.
inline constexpr std::size_t maxMidiFileBytes = std::size_t{64} << 20;
// Channel messages and tempo changes a file may hold. Each takes 2 bytes of a file at least and
// 16 of memory, about 2.5 times over while the tracks merge: without the cap a 64 MiB file could
// take over 1 GiB, with it about 100 MiB at most.
inline constexpr std::size_t maxMidiEvents = std::size_t{1} << 21;

// `name` is used in error messages only.
MidiFile parseMidiFile(std::span<const std::uint8_t> bytes, const std::string& name);
MidiFile readMidiFile(const std::filesystem::path& path);

}  // namespace hamiltone
