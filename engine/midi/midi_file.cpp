// Standard MIDI File reader: the chunk layout, the event grammar of a track, and the tempo map that
// turns ticks into seconds. See midi_file.h for the tolerances chosen.
#include "midi/midi_file.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <set>
#include <system_error>
#include <utility>

namespace hamiltone {
namespace {

constexpr std::uint32_t defaultTempo = 500000;  // µs per quarter note (120 bpm) until an FF 51
constexpr std::size_t chunkHeaderBytes = 8;     // 4-byte type, 4-byte big-endian length

// A channel message, and a tempo change, at a tick: the file's time, before the tempo map.
struct TickedMessage {
  std::uint64_t tick;
  MidiMessage message;
  int track;
};
struct TempoChange {
  std::uint64_t tick;
  std::uint32_t microsPerQuarter;
};

std::string hex(std::uint8_t b) {
  char text[8];
  std::snprintf(text, sizeof text, "0x%02X", static_cast<unsigned>(b));
  return text;
}

// Reads the bytes [begin, end) of a file, throwing a MidiFileError that names the offset of any
// read past `end`. `region` names what ends at `end`, for that message ("the file", "the track").
class Cursor {
 public:
  Cursor(std::span<const std::uint8_t> file, std::size_t begin, std::size_t end,
         const std::string& name, const char* region)
      : file_(file), pos_(begin), end_(end), name_(name), region_(region) {}

  std::size_t offset() const { return pos_; }
  std::size_t remaining() const { return end_ - pos_; }
  bool atEnd() const { return pos_ == end_; }

  [[noreturn]] void fail(std::size_t at, const std::string& what) const {
    throw MidiFileError(name_ + ": byte " + std::to_string(at) + ": " + what);
  }

  std::uint8_t peek(const char* what) const {
    if (atEnd()) fail(pos_, std::string(region_) + " ends inside " + what);
    return file_[pos_];
  }
  std::uint8_t next(const char* what) {
    const std::uint8_t b = peek(what);
    ++pos_;
    return b;
  }
  // A big-endian number of `count` ≤ 4 bytes.
  std::uint32_t fixed(int count, const char* what) {
    std::uint32_t value = 0;
    for (int i = 0; i < count; ++i) value = (value << 8) | next(what);
    return value;
  }
  // A variable-length number: 7 bits a byte, most significant first, the top bit set on all but
  // the last byte; at most 4 bytes (0x0FFFFFFF), as the specification allows.
  std::uint32_t variable(const char* what) {
    const std::size_t start = pos_;
    std::uint32_t value = 0;
    for (int i = 0; i < 4; ++i) {
      const std::uint8_t b = next(what);
      value = (value << 7) | (b & 0x7Fu);
      if ((b & 0x80u) == 0) return value;
    }
    fail(start, std::string(what) +
                    " is a variable-length number longer than 4 bytes; at most 4 "
                    "are valid (up to 0x0FFFFFFF)");
  }
  void skip(std::uint32_t count, const char* what) {
    if (count > remaining())
      fail(pos_, std::string(what) + " of " + std::to_string(count) +
                     " bytes runs past the end of " + region_ + " (" + std::to_string(remaining()) +
                     " bytes left)");
    pos_ += count;
  }

 private:
  std::span<const std::uint8_t> file_;
  std::size_t pos_, end_;
  const std::string& name_;
  const char* region_;
};

// A chunk's type as text for messages: printable ASCII as is, other bytes in hex.
std::string chunkType(std::span<const std::uint8_t> type) {
  std::string text = "\"";
  for (std::uint8_t b : type) text += (b >= 0x20 && b < 0x7F) ? std::string(1, char(b)) : hex(b);
  return text + "\"";
}

struct Chunk {
  std::span<const std::uint8_t> type;
  std::size_t begin, end;  // of its data
};

// The chunk at the cursor, whose data must fit in the file; leaves the cursor after it.
Chunk readChunk(Cursor& file, std::span<const std::uint8_t> bytes) {
  const std::size_t at = file.offset();
  if (file.remaining() < chunkHeaderBytes)
    file.fail(at, "the file ends inside a chunk header (8 bytes: type and length), " +
                      std::to_string(file.remaining()) + " bytes left");
  const std::span<const std::uint8_t> type = bytes.subspan(at, 4);
  file.skip(4, "a chunk type");
  const std::uint32_t length = file.fixed(4, "a chunk length");
  const std::size_t begin = file.offset();
  if (length > file.remaining())
    file.fail(at + 4, "chunk " + chunkType(type) + " declares " + std::to_string(length) +
                          " bytes but only " + std::to_string(file.remaining()) +
                          " remain in the file");
  file.skip(length, "a chunk");
  return {type, begin, begin + length};
}

bool isType(const Chunk& chunk, const char* type) {
  return std::equal(chunk.type.begin(), chunk.type.end(), type);
}

// What a file's tracks hold once read: everything still in ticks.
struct TrackEvents {
  std::vector<TickedMessage> messages;  // all tracks, each in file order, track after track
  std::vector<TempoChange> tempos;      // likewise
  std::uint64_t lastTick = 0;           // of the last event of any track
};

// One data byte of a channel message: 0–127.
std::uint8_t dataByte(Cursor& track, std::uint8_t status) {
  const std::size_t at = track.offset();
  const std::uint8_t b = track.next("a channel message");
  if (b >= 0x80)
    track.fail(at, "byte " + hex(b) + " where a data byte of channel message " + hex(status) +
                       " is expected; data bytes are 0x00-0x7F");
  return b;
}

void countEvent(const Cursor& track, std::size_t at, const TrackEvents& events) {
  if (events.messages.size() + events.tempos.size() >= maxMidiEvents)
    track.fail(at, "more than " + std::to_string(maxMidiEvents) +
                       " channel messages and tempo changes; that is the most this reader accepts");
}

// At one tick, tracks in order, each in its file order — except that a note-on waits while another
// track's next event at that tick is a note-off: a key one track releases and another strikes at
// the same tick then sounds, as a sequencer plays it (track order had the strike damped at once).
// Nothing else moves, and each track keeps its own order: a note a track starts and ends at one
// tick stays a strike and a release. `m` is sorted by tick, then track, then file order.
void noteOffsBeforeOtherTracksNoteOns(std::vector<TickedMessage>& m) {
  auto isNoteOff = [](const MidiMessage& x) {
    return x.kind() == midi::noteOff || (x.kind() == midi::noteOn && x.data2 == 0);
  };
  std::vector<TickedMessage> merged;
  std::vector<std::size_t> next, end;  // per track of the tick: its events still to place
  // The tracks of the tick (by rank) with events left, and those with a note-off next.
  std::set<std::size_t> heads, offHeads;
  for (std::size_t begin = 0; begin < m.size();) {
    std::size_t stop = begin + 1;
    while (stop < m.size() && m[stop].tick == m[begin].tick) ++stop;
    if (m[begin].track == m[stop - 1].track) {  // one track at this tick: its order stands
      begin = stop;
      continue;
    }
    next.clear(), end.clear(), heads.clear(), offHeads.clear();
    for (std::size_t i = begin; i < stop; ++i) {
      if (i == begin || m[i].track != m[i - 1].track) next.push_back(i), end.push_back(i);
      ++end.back();
    }
    auto enter = [&](std::size_t t) {
      if (next[t] == end[t]) return;
      heads.insert(t);
      if (isNoteOff(m[next[t]].message)) offHeads.insert(t);
    };
    for (std::size_t t = 0; t < next.size(); ++t) enter(t);
    merged.clear();
    while (!heads.empty()) {
      std::size_t t = *heads.begin();
      const MidiMessage& head = m[next[t]].message;
      if (head.kind() == midi::noteOn && head.data2 > 0 && !offHeads.empty()) t = *offHeads.begin();
      heads.erase(t), offHeads.erase(t);
      merged.push_back(m[next[t]++]);
      enter(t);
    }
    std::copy(merged.begin(), merged.end(), m.begin() + static_cast<std::ptrdiff_t>(begin));
    begin = stop;
  }
}

// The events of one track chunk, appended to `events` with the track's index.
void readTrack(Cursor track, int index, TrackEvents& events) {
  // A delta is < 2^28 and takes ≥ 2 bytes with its event, so in a file of ≤ 64 MiB the tick stays
  // below 2^53: no overflow, and exact as a double.
  std::uint64_t tick = 0;
  // The last channel status. Kept across meta and sysex events — see midi_file.h.
  std::uint8_t runningStatus = 0;
  while (!track.atEnd()) {
    tick += track.variable("a delta time");
    const std::size_t at = track.offset();
    std::uint8_t status = track.peek("an event (a delta time with no event after it)");
    if (status < 0x80) {
      if (runningStatus == 0)
        track.fail(at, "data byte " + hex(status) +
                           " with no running status: no channel message (0x80-0xEF) precedes it "
                           "in this track, so the event needs a status byte");
      status = runningStatus;
    } else {
      track.next("an event");
    }

    if (status < 0xF0) {
      runningStatus = status;
      MidiMessage m{status, dataByte(track, status), 0};
      const int kind = m.kind();
      if (kind != midi::program && kind != midi::channelPressure) m.data2 = dataByte(track, status);
      countEvent(track, at, events);
      events.messages.push_back({tick, m, index});
    } else if (status == 0xF0 || status == 0xF7) {
      // A sysex message, or an escape (F7): its length, then data we skip unread.
      track.skip(track.variable("a sysex length"), "sysex data");
    } else if (status == 0xFF) {
      const std::uint8_t type = track.next("a meta event type");
      const std::size_t lengthAt = track.offset();
      const std::uint32_t length = track.variable("a meta event length");
      if (type == 0x51) {
        if (length != 3)
          track.fail(lengthAt, "set-tempo meta event (FF 51) of length " + std::to_string(length) +
                                   "; its length must be 3");
        const std::uint32_t micros = track.fixed(3, "a set-tempo meta event");
        if (micros == 0)
          track.fail(lengthAt + 1,
                     "tempo of 0 microseconds per quarter note; valid tempos are 1-16777215");
        countEvent(track, at, events);
        events.tempos.push_back({tick, micros});
      } else {
        track.skip(length, "meta event data");
      }
      if (type == 0x2F) break;  // End of Track: whatever follows in the chunk is ignored
    } else {
      track.fail(at, "system common or real-time byte " + hex(status) +
                         " inside a track; a track holds only channel messages (0x80-0xEF), sysex "
                         "(0xF0, 0xF7) and meta events (0xFF)");
    }
  }
  // A chunk that ends without End of Track ends the track there.
  events.lastTick = std::max(events.lastTick, tick);
}

// Seconds per tick before any tempo change, and whether tempo changes apply (not with SMPTE).
struct Timing {
  double secondsPerTick;
  bool tempoApplies;
  double ticksPerQuarter;
};

Timing readDivision(const Cursor& file, std::size_t at, std::uint32_t division) {
  if ((division & 0x8000u) == 0) {
    if (division == 0)
      file.fail(at, "division of 0 ticks per quarter note; valid divisions are 1-32767");
    const double ticks = division;
    return {defaultTempo * 1e-6 / ticks, true, ticks};
  }
  // SMPTE: the high byte is minus the frames per second (two's complement), the low byte the
  // ticks per frame.
  const int framesPerSecond = 256 - static_cast<int>(division >> 8);
  const int ticksPerFrame = static_cast<int>(division & 0xFFu);
  if (framesPerSecond != 24 && framesPerSecond != 25 && framesPerSecond != 29 &&
      framesPerSecond != 30)
    file.fail(at, "SMPTE division with " + std::to_string(framesPerSecond) +
                      " frames per second; valid rates are 24, 25, 29 (29.97 drop-frame) and 30");
  if (ticksPerFrame == 0)
    file.fail(at + 1, "SMPTE division with 0 ticks per frame; valid counts are 1-255");
  const double fps = framesPerSecond == 29 ? 30000.0 / 1001.0 : framesPerSecond;
  return {1.0 / (fps * ticksPerFrame), false, 0.0};
}

// Ticks to seconds through the merged tempo map, for ticks given in nondecreasing order.
class TempoMap {
 public:
  TempoMap(const Timing& timing, std::vector<TempoChange> changes)
      : timing_(timing), changes_(std::move(changes)), secondsPerTick_(timing.secondsPerTick) {
    if (!timing.tempoApplies) changes_.clear();
    // Changes at the same tick apply in track order, then file order: the last one stands.
    std::stable_sort(changes_.begin(), changes_.end(),
                     [](const TempoChange& a, const TempoChange& b) { return a.tick < b.tick; });
  }

  double seconds(std::uint64_t tick) {
    for (; next_ < changes_.size() && changes_[next_].tick <= tick; ++next_) {
      const TempoChange& c = changes_[next_];
      startSeconds_ += static_cast<double>(c.tick - startTick_) * secondsPerTick_;
      startTick_ = c.tick;
      secondsPerTick_ = c.microsPerQuarter * 1e-6 / timing_.ticksPerQuarter;
    }
    return startSeconds_ + static_cast<double>(tick - startTick_) * secondsPerTick_;
  }

 private:
  Timing timing_;
  std::vector<TempoChange> changes_;
  std::size_t next_ = 0;
  std::uint64_t startTick_ = 0;  // of the tempo in force
  double startSeconds_ = 0.0, secondsPerTick_;
};

}  // namespace

MidiFile parseMidiFile(std::span<const std::uint8_t> bytes, const std::string& name) {
  Cursor file(bytes, 0, bytes.size(), name, "the file");
  if (bytes.size() > maxMidiFileBytes)
    file.fail(0, std::to_string(bytes.size()) + " bytes; a MIDI file may have at most " +
                     std::to_string(maxMidiFileBytes) + " (64 MiB)");
  if (bytes.size() < 4 || !std::equal(bytes.begin(), bytes.begin() + 4, "MThd"))
    file.fail(0, "missing MThd: a Standard MIDI File starts with the header chunk \"MThd\"");

  const Chunk header = readChunk(file, bytes);
  if (header.end - header.begin < 6)
    file.fail(4, "header chunk of " + std::to_string(header.end - header.begin) +
                     " bytes; it must hold at least 6 (format, tracks, division)");
  // Bytes after the 6 that SMF 1.0 defines are skipped, as the specification asks.
  Cursor fields(bytes, header.begin, header.end, name, "the header chunk");
  MidiFile midi;
  midi.format = static_cast<int>(fields.fixed(2, "the format"));
  midi.tracks = static_cast<int>(fields.fixed(2, "the track count"));
  midi.division = static_cast<int>(fields.fixed(2, "the division"));
  const std::size_t formatAt = header.begin, tracksAt = header.begin + 2;
  if (midi.format == 2)
    file.fail(formatAt,
              "format 2 (independent sequences) is not supported; valid formats are 0 and 1");
  if (midi.format > 2)
    file.fail(formatAt, "format " + std::to_string(midi.format) + "; valid formats are 0 and 1");
  if (midi.tracks == 0) file.fail(tracksAt, "0 tracks; a file needs at least 1");
  if (midi.format == 0 && midi.tracks != 1)
    file.fail(tracksAt, "format 0 with " + std::to_string(midi.tracks) +
                            " tracks; format 0 has exactly 1 (format 1 allows more)");
  // Each track chunk takes at least its 8-byte header, so the count is checked against the bytes
  // left before any track is read (and nothing is ever sized by it).
  const std::size_t room = file.remaining() / chunkHeaderBytes;
  if (static_cast<std::size_t>(midi.tracks) > room)
    file.fail(tracksAt, "the header declares " + std::to_string(midi.tracks) + " tracks but the " +
                            std::to_string(file.remaining()) + " bytes after it can hold at most " +
                            std::to_string(room) + " (8 bytes a track chunk at least)");
  const Timing timing =
      readDivision(file, header.begin + 4, static_cast<std::uint32_t>(midi.division));

  TrackEvents events;
  for (int found = 0; found < midi.tracks;) {
    if (file.atEnd())
      file.fail(file.offset(), "the file ends after " + std::to_string(found) + " of the " +
                                   std::to_string(midi.tracks) + " tracks the header declares");
    const Chunk chunk = readChunk(file, bytes);
    if (!isType(chunk, "MTrk")) continue;  // a chunk type we do not know: skipped
    readTrack(Cursor(bytes, chunk.begin, chunk.end, name, "the track chunk"), found, events);
    ++found;
  }

  // Merge the tracks: a stable sort keeps track order, then file order, at equal ticks; then
  // another track's note-off goes before a note-on there.
  std::stable_sort(events.messages.begin(), events.messages.end(),
                   [](const TickedMessage& a, const TickedMessage& b) { return a.tick < b.tick; });
  noteOffsBeforeOtherTracksNoteOns(events.messages);
  TempoMap map(timing, std::move(events.tempos));
  midi.messages.reserve(events.messages.size());
  for (const TickedMessage& m : events.messages)
    midi.messages.push_back({map.seconds(m.tick), m.message});
  midi.lengthSeconds = map.seconds(events.lastTick);
  return midi;
}

MidiFile readMidiFile(const std::filesystem::path& path) {
  const std::string name = path.string();
  std::error_code error;
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  if (error) throw MidiFileError(name + ": cannot read the file: " + error.message());
  if (size > maxMidiFileBytes)
    throw MidiFileError(name + ": " + std::to_string(size) +
                        " bytes; a MIDI file may have at most " + std::to_string(maxMidiFileBytes) +
                        " (64 MiB)");
  std::ifstream in(path, std::ios::binary);
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(size));
  if (!in || !in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(size)))
    throw MidiFileError(name + ": cannot read the file: reading its " + std::to_string(size) +
                        " bytes failed");
  return parseMidiFile(bytes, name);
}

}  // namespace hamiltone
