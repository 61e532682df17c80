// The --notes argument: notes typed on the command line, turned into timed MIDI messages.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "midi/midi_message.h"

namespace hamiltone::cli {

// Comma-separated items NOTE[@START][:VELOCITY[:DURATION]], spaces allowed around items:
//   NOTE      a name — C D E F G A B (either case), an optional # or b, an octave -1…9 in
//             scientific pitch (C4 = MIDI 60, A4 = 69; so B#3 = C4, Cb4 = B3) — or a MIDI
//             number 0…127
//   START     seconds >= 0 from the start, default 0: "C3, E3, G3" is a chord
//   VELOCITY  1…127, default 100
//   DURATION  seconds to the note-off, default 1; at least 1 µs, as times are rounded to
//             whole microseconds (so 0.1 + 0.2 ends exactly where 0.3 starts)
// e.g. "C3, E3@0.5:80, G3@1:100:2.5, 72@2".
struct NoteList {
  // A note-on and a note-off (release velocity 64, MIDI's value for "not measured") per item,
  // all on channel 0, sorted by time. At equal times note-offs come first, so a note that
  // starts as the same note ends is struck again rather than cut off; otherwise items keep
  // their order.
  std::vector<TimedMessage> messages;
  double endSeconds = 0.0;  // the latest note-off
};

inline constexpr std::size_t kMaxNoteItems = 10000;
inline constexpr double kMaxNoteEndSeconds = 24.0 * 3600.0;  // no note-off later than 24 h

// Throws UsageError("--notes: item N \"TEXT\": …") naming the first bad item and what is valid:
// an unknown or out-of-range note, a start, velocity or duration that is not a finite number
// in range, an empty item, a fourth field, spaces inside an item, more than kMaxNoteItems
// items, or a note-off after kMaxNoteEndSeconds.
NoteList parseNoteList(const std::string& text);

}  // namespace hamiltone::cli
