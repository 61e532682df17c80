// Items are split at commas, each at ':' into note/start, velocity and duration, the first at
// '@'; numbers go through parseReal/parseInteger, whose messages get the item as their prefix.
#include "note_list.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string_view>

#include "number_arguments.h"
#include "usage_error.h"

namespace hamiltone::cli {

namespace {

constexpr int kDefaultVelocity = 100;
constexpr double kDefaultDuration = 1.0;
constexpr int kReleaseVelocity = 64;

constexpr const char* kValidNotes =
    "use C, D, E, F, G, A, B with optional # or b and an octave -1…9, or a MIDI number 0…127";
constexpr const char* kValidItem = "expected NOTE[@START][:VELOCITY[:DURATION]], e.g. E3@0.5:80:2";

bool isSpace(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v';
}

std::string_view trimmed(std::string_view s) {
  while (!s.empty() && isSpace(s.front())) s.remove_prefix(1);
  while (!s.empty() && isSpace(s.back())) s.remove_suffix(1);
  return s;
}

// Times are kept in whole microseconds, so decimal times that are equal compare equal: an item
// at 0.1 lasting 0.2 s ends exactly when one at 0.3 starts. A note lasts at least one tick, so
// its note-off cannot round onto its note-on and be sorted before it.
constexpr double kTicksPerSecond = 1e6;

double onTickGrid(double seconds) {
  return std::round(seconds * kTicksPerSecond) / kTicksPerSecond;
}

// The MIDI note of a number or a name in scientific pitch (C-1 = 0, C4 = 60).
int parseNote(std::string_view text, const std::string& where) {
  std::string quoted = "\"";  // appended, not "\"" + …: GCC 12 warns falsely on that (-Wrestrict)
  quoted.append(text) += '"';
  if (!text.empty() &&
      std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    int number = 0;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), number);
    if (error != std::errc{} || number > 127)
      throw UsageError(where + ": MIDI number " + std::string(text) +
                       " is out of range; use 0…127");
    return number;
  }
  const auto unknown = [&] {
    return UsageError(where + ": unknown note name " + quoted + ": " + kValidNotes);
  };
  // Semitones above the octave's C of A B C D E F G; the letter may be either case.
  static constexpr int kLetterSemitones[] = {9, 11, 0, 2, 4, 5, 7};
  const char letter = text.empty() ? '\0' : static_cast<char>(text.front() & ~0x20);
  if (letter < 'A' || letter > 'G') throw unknown();
  int note = kLetterSemitones[letter - 'A'];
  text.remove_prefix(1);
  if (!text.empty() && (text.front() == '#' || text.front() == 'b')) {
    note += text.front() == '#' ? 1 : -1;
    text.remove_prefix(1);
  }
  int octave = 0;
  if (text == "-1")
    octave = -1;
  else if (text.size() == 1 && text.front() >= '0' && text.front() <= '9')
    octave = text.front() - '0';
  else
    throw unknown();
  note += 12 * (octave + 1);
  if (note < 0 || note > 127)
    throw UsageError(where + ": note " + quoted + " would be MIDI " + std::to_string(note) +
                     "; names run from C-1 (0) to G9 (127)");
  return note;
}

std::string formatted(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", x);
  return text;
}

struct Note {
  int number, velocity;
  double start, end;
};

// `where` is "--notes: item N \"TEXT\"", the prefix of every message about the item.
Note parseItem(std::string_view item, const std::string& where) {
  if (item.empty()) throw UsageError(where + ": empty; " + kValidItem);
  if (std::any_of(item.begin(), item.end(), isSpace))
    throw UsageError(where + ": contains a space; spaces are allowed only around items");

  const std::size_t colon = item.find(':');
  const std::string_view head = item.substr(0, colon);
  std::string_view tail = colon == std::string_view::npos ? "" : item.substr(colon + 1);
  const std::size_t at = head.find('@');
  const std::string_view name = head.substr(0, at);

  Note note{parseNote(name, where), kDefaultVelocity, 0.0, 0.0};
  if (at != std::string_view::npos)
    note.start = onTickGrid(parseReal(where + ": start", std::string(head.substr(at + 1)),
                                      Range::nonNegative, "seconds"));
  double duration = kDefaultDuration;
  if (colon != std::string_view::npos) {
    const std::size_t second = tail.find(':');
    note.velocity = static_cast<int>(
        parseInteger(where + ": velocity", std::string(tail.substr(0, second)), 1, 127));
    if (second != std::string_view::npos) {
      tail.remove_prefix(second + 1);
      const std::size_t third = tail.find(':');
      if (third != std::string_view::npos)
        throw UsageError(where + ": unexpected \"" + std::string(tail.substr(third)) +
                         "\" after the duration; " + kValidItem);
      const std::string text(tail);
      duration = parseReal(where + ": duration", text, Range::positive, "seconds");
      if (duration * kTicksPerSecond < 1.0)
        throw UsageError(where + ": duration = " + text +
                         ": shorter than 1 µs, the time resolution of --notes");
    }
  }
  note.end = onTickGrid(note.start + duration);
  if (!(note.end <= kMaxNoteEndSeconds))
    throw UsageError(where + ": ends at " + formatted(note.end) + " s, after the limit of " +
                     formatted(kMaxNoteEndSeconds) + " s (24 h)");
  return note;
}

}  // namespace

NoteList parseNoteList(const std::string& text) {
  const std::size_t items = 1 + static_cast<std::size_t>(std::count(text.begin(), text.end(), ','));
  if (items > kMaxNoteItems)
    throw UsageError("--notes: " + std::to_string(items) + " items; at most " +
                     std::to_string(kMaxNoteItems));

  NoteList list;
  list.messages.reserve(2 * items);
  std::string_view rest = text;
  for (std::size_t position = 1; position <= items; ++position) {
    const std::size_t comma = rest.find(',');
    const std::string_view item = trimmed(rest.substr(0, comma));
    rest.remove_prefix(comma == std::string_view::npos ? rest.size() : comma + 1);

    const Note note = parseItem(
        item, "--notes: item " + std::to_string(position) + " \"" + std::string(item) + "\"");
    const auto number = static_cast<std::uint8_t>(note.number);
    list.messages.push_back(
        {note.start, {midi::noteOn, number, static_cast<std::uint8_t>(note.velocity)}});
    list.messages.push_back({note.end, {midi::noteOff, number, kReleaseVelocity}});
    list.endSeconds = std::max(list.endSeconds, note.end);
  }
  std::stable_sort(list.messages.begin(), list.messages.end(),
                   [](const TimedMessage& a, const TimedMessage& b) {
                     if (a.seconds != b.seconds) return a.seconds < b.seconds;
                     return a.message.kind() == midi::noteOff && b.message.kind() == midi::noteOn;
                   });
  return list;
}

}  // namespace hamiltone::cli
