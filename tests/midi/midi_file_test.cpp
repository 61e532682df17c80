// The Standard MIDI File reader: files written here read back with every event at its time in
// seconds through the tempo map, the tolerances of midi_file.h hold, and each malformed file is
// refused with a message naming the byte and what is wrong.
#include "midi/midi_file.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "support/midi_writer.h"

namespace hamiltone {
namespace {

using testing::Bytes;
using testing::chunk;
using testing::concat;
using ::testing::HasSubstr;
using testing::header;
using testing::midiFile;
using testing::TrackWriter;

// Times are a few products and sums of numbers near 1 s: exact to well within 1e-12.
constexpr double timeTolerance = 1e-12;

struct Expected {
  double seconds;
  int status, data1, data2;
};

void expectMessages(const MidiFile& midi, const std::vector<Expected>& expected) {
  ASSERT_EQ(midi.messages.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    const TimedMessage& m = midi.messages[i];
    EXPECT_NEAR(m.seconds, expected[i].seconds, timeTolerance) << "message " << i;
    EXPECT_EQ(m.message.status, expected[i].status) << "message " << i;
    EXPECT_EQ(m.message.data1, expected[i].data1) << "message " << i;
    EXPECT_EQ(m.message.data2, expected[i].data2) << "message " << i;
  }
}

MidiFile parse(const Bytes& bytes) { return parseMidiFile(bytes, "test.mid"); }

// The message of the MidiFileError parsing `bytes` throws; any other exception fails the test.
std::string errorOf(const Bytes& bytes) {
  try {
    parse(bytes);
  } catch (const MidiFileError& e) {
    return e.what();
  }
  return "(no error)";
}

// A file of one track whose chunk holds `data` as given.
Bytes oneTrack(const Bytes& data, int division = 480) {
  return concat({header(0, 1, division), chunk("MTrk", data)});
}

// At 480 ticks a quarter: 500000 µs a quarter is 1/960 s a tick, 600000 µs is 1/800 s.
TEST(MidiFile, Format0ReadsBackThroughATempoChange) {
  TrackWriter track;
  track.tempo(0, 500000)
      .event(0, {0x90, 60, 100})
      .event(480, {0x80, 60, 64})
      .tempo(480, 600000)
      .event(0, {0x91, 62, 90})
      .event(480, {0x81, 62, 0})
      .endOfTrack(480);
  const MidiFile midi = parse(midiFile(0, 480, {track}));
  EXPECT_EQ(midi.format, 0);
  EXPECT_EQ(midi.tracks, 1);
  EXPECT_EQ(midi.division, 480);
  expectMessages(
      midi, {{0.0, 0x90, 60, 100}, {0.5, 0x80, 60, 64}, {1.0, 0x91, 62, 90}, {1.6, 0x81, 62, 0}});
  EXPECT_NEAR(midi.lengthSeconds, 2.2, timeTolerance);  // the End of Track, 480 ticks on
}

TEST(MidiFile, TempoDefaultsTo120BeatsPerMinute) {
  TrackWriter track;
  track.event(96, {0x90, 60, 100}).endOfTrack(96);
  const MidiFile midi = parse(midiFile(0, 96, {track}));
  expectMessages(midi, {{0.5, 0x90, 60, 100}});
  EXPECT_NEAR(midi.lengthSeconds, 1.0, timeTolerance);
}

// Track 0 holds the tempo map (500000 µs, then 1000000 µs from tick 960); the other tracks merge
// in time order, and at equal times in track order, then file order.
TEST(MidiFile, Format1MergesTracksThroughTheTempoMapOfTrack0) {
  TrackWriter tempo, piano, bass;
  tempo.tempo(0, 500000).tempo(960, 1000000).endOfTrack();
  piano.event(0, {0x90, 60, 100})
      .event(960, {0x90, 64, 80})
      .event(0, {0x80, 60, 0})
      .event(480, {0x80, 64, 0})
      .endOfTrack();
  bass.event(960, {0x91, 36, 70}).event(960, {0x81, 36, 0}).endOfTrack(0);
  const MidiFile midi = parse(midiFile(1, 480, {tempo, piano, bass}));
  EXPECT_EQ(midi.format, 1);
  EXPECT_EQ(midi.tracks, 3);
  expectMessages(midi, {{0.0, 0x90, 60, 100},
                        {1.0, 0x90, 64, 80},
                        {1.0, 0x80, 60, 0},
                        {1.0, 0x91, 36, 70},
                        {2.0, 0x80, 64, 0},
                        {3.0, 0x81, 36, 0}});
  EXPECT_NEAR(midi.lengthSeconds, 3.0, timeTolerance);
}

// At one tick a note-on waits for another track's note-off due then: C4 released by the second
// track and struck by the first at 1 s sounds (in track order it was damped at once). Each track
// keeps its own order — the first track's D4 started and ended at that tick stays on, off — and
// nothing but a note-on moves: the pedal (CC64) in the first track stays before the off.
TEST(MidiFile, AtOneTickAnotherTracksNoteOffGoesBeforeANoteOn) {
  TrackWriter first, second;
  first.event(480, {0xB0, 64, 127})
      .event(0, {0x90, 60, 90})
      .event(0, {0x90, 62, 80})
      .event(0, {0x80, 62, 0})
      .event(480, {0x80, 60, 0})
      .endOfTrack();
  second.event(0, {0x90, 60, 70}).event(480, {0x90, 60, 0}).event(0, {0x90, 62, 50}).endOfTrack();
  const MidiFile midi = parse(midiFile(1, 480, {first, second}));
  expectMessages(midi, {{0.0, 0x90, 60, 70},
                        {0.5, 0xB0, 64, 127},
                        {0.5, 0x90, 60, 0},
                        {0.5, 0x90, 60, 90},
                        {0.5, 0x90, 62, 80},
                        {0.5, 0x80, 62, 0},
                        {0.5, 0x90, 62, 50},
                        {1.0, 0x80, 60, 0}});
}

// Tempo changes in any track apply to all; at the same tick the later track's stands.
TEST(MidiFile, TempoChangesInAnyTrackApplyToAll) {
  TrackWriter conductor, notes, late;
  conductor.endOfTrack();
  notes.event(480, {0x90, 60, 100}).event(480, {0x80, 60, 0}).endOfTrack();
  late.tempo(480, 1000000).tempo(0, 250000).endOfTrack();
  TrackWriter lateInOtherTrack;
  lateInOtherTrack.tempo(480, 250000).endOfTrack();
  TrackWriter earlierTrack;
  earlierTrack.tempo(480, 1000000).endOfTrack();
  for (const Bytes& file : {midiFile(1, 480, {conductor, notes, late}),
                            midiFile(1, 480, {earlierTrack, notes, lateInOtherTrack})})
    expectMessages(parse(file), {{0.5, 0x90, 60, 100}, {0.75, 0x80, 60, 0}});
}

TEST(MidiFile, ReadsEveryChannelMessageWithItsDataBytes) {
  TrackWriter track;
  track.event(0, {0xA2, 60, 30})
      .event(0, {0xB3, 64, 127})
      .event(0, {0xC4, 5})
      .event(0, {0xD5, 90})
      .event(0, {0xEF, 0x00, 0x40})
      .endOfTrack();
  expectMessages(parse(midiFile(0, 480, {track})), {{0.0, 0xA2, 60, 30},
                                                    {0.0, 0xB3, 64, 127},
                                                    {0.0, 0xC4, 5, 0},
                                                    {0.0, 0xD5, 90, 0},
                                                    {0.0, 0xEF, 0x00, 0x40}});
}

// Running status continues after meta and sysex events (midi_file.h says why), for one- and
// two-data-byte messages; a note-on of velocity 0 stays a note-on.
TEST(MidiFile, RunningStatusContinuesAcrossMetaAndSysex) {
  TrackWriter track;
  track.event(0, {0x90, 60, 100})
      .event(0, {64, 90})
      .meta(480, 0x01, {'h', 'i'})
      .event(0, {60, 0})
      .sysex(0, 0xF0, {0x7E, 0x7F, 0x09, 0x01, 0xF7})
      .event(480, {64, 0})
      .event(0, {0xC0, 5})
      .event(0, {6})
      .endOfTrack();
  expectMessages(parse(midiFile(0, 480, {track})), {{0.0, 0x90, 60, 100},
                                                    {0.0, 0x90, 64, 90},
                                                    {0.5, 0x90, 60, 0},
                                                    {1.0, 0x90, 64, 0},
                                                    {1.0, 0xC0, 5, 0},
                                                    {1.0, 0xC0, 6, 0}});
}

// Sysex data is skipped by its length, whatever it holds: an F7 escape may carry bytes that would
// be an End of Track or a real-time byte if read as events.
TEST(MidiFile, SkipsSysexByLength) {
  TrackWriter track;
  track
      .sysex(0, 0xF0, Bytes(200, 0x11))  // a two-byte length
      .sysex(0, 0xF7, {0xFF, 0x2F, 0x00, 0xF8})
      .event(480, {0x90, 60, 100})
      .endOfTrack();
  expectMessages(parse(midiFile(0, 480, {track})), {{0.5, 0x90, 60, 100}});
}

// Unknown chunks before, between and after the tracks, and bytes after the last track, are skipped.
TEST(MidiFile, SkipsUnknownChunks) {
  TrackWriter first, second;
  first.event(0, {0x90, 60, 100}).endOfTrack();
  second.event(480, {0x80, 60, 0}).endOfTrack();
  const Bytes file =
      concat({header(1, 2, 480), chunk("XFIH", Bytes(300, 0xFF)), chunk("MTrk", first.bytes()),
              chunk("\x01\x02\x03\x04", {'M', 'T', 'r', 'k'}), chunk("MTrk", second.bytes()),
              chunk("XFKM", {1, 2, 3}), Bytes{0x00, 0x00}});
  expectMessages(parse(file), {{0.0, 0x90, 60, 100}, {0.5, 0x80, 60, 0}});
}

// A header chunk longer than 6 bytes: the extra bytes are skipped.
TEST(MidiFile, SkipsExtraHeaderBytes) {
  TrackWriter track;
  track.event(480, {0x90, 60, 100}).endOfTrack();
  const Bytes file =
      concat({chunk("MThd", {0, 0, 0, 1, 0x01, 0xE0, 0xAA, 0xBB}), chunk("MTrk", track.bytes())});
  expectMessages(parse(file), {{0.5, 0x90, 60, 100}});
}

// SMPTE division: 25 fps × 40 ticks a frame is 1 ms a tick; 29 means 30000/1001 fps. Tempo events
// do not change SMPTE time.
TEST(MidiFile, SmpteDivisionCountsFramesNotQuarters) {
  TrackWriter track;
  track.tempo(0, 250000).event(1000, {0x90, 60, 100}).event(500, {0x80, 60, 0}).endOfTrack(500);
  const MidiFile at25 = parse(midiFile(0, 0xE728, {track}));  // 0xE7 = -25, 0x28 = 40
  EXPECT_EQ(at25.division, 0xE728);
  expectMessages(at25, {{1.0, 0x90, 60, 100}, {1.5, 0x80, 60, 0}});
  EXPECT_NEAR(at25.lengthSeconds, 2.0, timeTolerance);

  const MidiFile at2997 = parse(midiFile(0, 0xE350, {track}));  // -29, 80 ticks a frame
  expectMessages(at2997, {{1000 * 1001.0 / (30000 * 80), 0x90, 60, 100},
                          {1500 * 1001.0 / (30000 * 80), 0x80, 60, 0}});
}

// Without End of Track a track ends with its chunk; after one, the rest of the chunk is ignored.
TEST(MidiFile, TrackEndsWithItsChunkOrItsEndOfTrack) {
  TrackWriter open;
  open.event(0, {0x90, 60, 100}).event(480, {0x80, 60, 0});
  const MidiFile unterminated = parse(midiFile(0, 480, {open}));
  expectMessages(unterminated, {{0.0, 0x90, 60, 100}, {0.5, 0x80, 60, 0}});
  EXPECT_NEAR(unterminated.lengthSeconds, 0.5, timeTolerance);

  TrackWriter closed;
  closed.event(0, {0x90, 60, 100}).endOfTrack(960).event(0, {0xF8, 0xF1});
  const MidiFile terminated = parse(midiFile(0, 480, {closed}));
  expectMessages(terminated, {{0.0, 0x90, 60, 100}});
  EXPECT_NEAR(terminated.lengthSeconds, 1.0, timeTolerance);
}

TEST(MidiFile, LengthIsTheLastEventOfAnyTrack) {
  TrackWriter shortTrack, longTrack;
  shortTrack.event(0, {0x90, 60, 100}).endOfTrack(240);
  longTrack.meta(1920, 0x01, {'x'}).endOfTrack(0);
  const MidiFile midi = parse(midiFile(1, 480, {shortTrack, longTrack}));
  EXPECT_NEAR(midi.lengthSeconds, 2.0, timeTolerance);
}

// Errors carry the name and the offset: the header is 14 bytes and the track chunk header 8, so
// the track's second byte is byte 23.
TEST(MidiFile, ErrorsNameTheFileAndTheByte) {
  EXPECT_THAT(errorOf(oneTrack({0x00, 0xF8})), HasSubstr("test.mid: byte 23: system common"));
}

TEST(MidiFile, RejectsAFileWithoutMThd) {
  EXPECT_THAT(errorOf({}), HasSubstr("missing MThd"));
  EXPECT_THAT(errorOf({'R', 'I', 'F', 'F', 0, 0, 0, 6, 0, 0, 0, 1, 0, 96}),
              HasSubstr("byte 0: missing MThd"));
  EXPECT_THAT(errorOf(concat({chunk("MTrk", {}), header(0, 1, 96)})), HasSubstr("missing MThd"));
}

TEST(MidiFile, RejectsAHeaderChunkShorterThan6Bytes) {
  EXPECT_THAT(errorOf(concat({chunk("MThd", {0, 0, 0, 1}), chunk("MTrk", {0x00, 0xFF, 0x2F, 0})})),
              HasSubstr("byte 4: header chunk of 4 bytes; it must hold at least 6"));
}

TEST(MidiFile, RejectsTruncatedFiles) {
  const Bytes complete = oneTrack({0x00, 0x90, 60, 100, 0x00, 0xFF, 0x2F, 0x00});
  EXPECT_THAT(errorOf(Bytes(complete.begin(), complete.begin() + 10)),
              HasSubstr("byte 4: chunk \"MThd\" declares 6 bytes but only 2 remain"));
  EXPECT_THAT(errorOf(Bytes(complete.begin(), complete.begin() + 17)),
              HasSubstr("byte 10: the header declares 1 tracks but the 3 bytes after it can hold "
                        "at most 0"));
  EXPECT_THAT(errorOf(concat({header(0, 1, 96), chunk("XXXX", {}), Bytes{'M', 'T', 'r'}})),
              HasSubstr("byte 22: the file ends inside a chunk header"));
  EXPECT_THAT(errorOf(Bytes(complete.begin(), complete.end() - 1)),
              HasSubstr("byte 18: chunk \"MTrk\" declares 8 bytes but only 7 remain in the file"));
  EXPECT_THAT(errorOf(header(0, 1, 96)), HasSubstr("declares 1 tracks but the 0 bytes"));
}

TEST(MidiFile, RejectsAnEventCutByItsTrackChunk) {
  EXPECT_THAT(errorOf(oneTrack({0x00, 0x90, 60})),
              HasSubstr("byte 25: the track chunk ends inside a channel message"));
  EXPECT_THAT(errorOf(oneTrack({0x00})), HasSubstr("the track chunk ends inside an event"));
  EXPECT_THAT(errorOf(oneTrack({0x81})), HasSubstr("the track chunk ends inside a delta time"));
  EXPECT_THAT(errorOf(oneTrack({0x00, 0xF0, 0x10, 1})),
              HasSubstr("sysex data of 16 bytes runs past the end of the track chunk"));
  EXPECT_THAT(errorOf(oneTrack({0x00, 0xFF, 0x01, 0x05, 'a'})),
              HasSubstr("meta event data of 5 bytes runs past the end of the track chunk"));
  EXPECT_THAT(errorOf(oneTrack({0x00, 0xFF})), HasSubstr("ends inside a meta event type"));
}

TEST(MidiFile, RejectsTrackCountsTheFileCannotHold) {
  TrackWriter track;
  track.endOfTrack();
  const Bytes oneChunk = chunk("MTrk", track.bytes());
  EXPECT_THAT(errorOf(concat({header(1, 65535, 480), oneChunk})),
              HasSubstr("byte 10: the header declares 65535 tracks but the 12 bytes after it can "
                        "hold at most 1"));
  // Room for 2 chunks, but only 1 is a track.
  EXPECT_THAT(errorOf(concat({header(1, 2, 480), oneChunk, chunk("XXXX", {})})),
              HasSubstr("byte 34: the file ends after 1 of the 2 tracks the header declares"));
  EXPECT_THAT(errorOf(concat({header(1, 0, 480), oneChunk})),
              HasSubstr("0 tracks; a file needs at least 1"));
  EXPECT_THAT(errorOf(concat({header(0, 2, 480), oneChunk, oneChunk})),
              HasSubstr("format 0 with 2 tracks; format 0 has exactly 1"));
}

TEST(MidiFile, RejectsFormatsOtherThan0And1) {
  TrackWriter track;
  track.endOfTrack();
  EXPECT_THAT(errorOf(midiFile(2, 480, {track})),
              HasSubstr("byte 8: format 2 (independent sequences) is not supported"));
  EXPECT_THAT(errorOf(midiFile(7, 480, {track})), HasSubstr("format 7; valid formats are 0 and 1"));
}

TEST(MidiFile, RejectsInvalidDivisions) {
  const Bytes endOnly = {0x00, 0xFF, 0x2F, 0x00};
  EXPECT_THAT(errorOf(oneTrack(endOnly, 0)),
              HasSubstr("byte 12: division of 0 ticks per quarter note; valid divisions are "
                        "1-32767"));
  EXPECT_THAT(errorOf(oneTrack(endOnly, 0x9C28)),  // -100 fps
              HasSubstr("SMPTE division with 100 frames per second; valid rates are 24, 25, 29"));
  EXPECT_THAT(errorOf(oneTrack(endOnly, 0xE700)),
              HasSubstr("byte 13: SMPTE division with 0 ticks per frame"));
}

TEST(MidiFile, RejectsVariableLengthNumbersLongerThan4Bytes) {
  EXPECT_THAT(errorOf(oneTrack({0x81, 0x80, 0x80, 0x80, 0x00, 0x90, 60, 100})),
              HasSubstr("byte 22: a delta time is a variable-length number longer than 4 bytes"));
  EXPECT_THAT(errorOf(oneTrack({0x00, 0xF0, 0xFF, 0xFF, 0xFF, 0xFF, 0x7F})),
              HasSubstr("a sysex length is a variable-length number longer than 4 bytes"));
  EXPECT_THAT(errorOf(oneTrack({0x00, 0xFF, 0x01, 0x80, 0x80, 0x80, 0x80, 0x01})),
              HasSubstr("a meta event length is a variable-length number longer than 4 bytes"));
}

TEST(MidiFile, RejectsRunningStatusWithoutAStatus) {
  EXPECT_THAT(errorOf(oneTrack({0x00, 60, 100})),
              HasSubstr("byte 23: data byte 0x3C with no running status"));
  // Meta and sysex events keep a running status but do not start one.
  EXPECT_THAT(errorOf(oneTrack({0x00, 0xFF, 0x01, 0x00, 0x00, 60, 100})),
              HasSubstr("with no running status"));
  EXPECT_THAT(errorOf(oneTrack({0x00, 0xF0, 0x01, 0xF7, 0x00, 60, 100})),
              HasSubstr("with no running status"));
  // Each track starts without one.
  TrackWriter first, second;
  first.event(0, {0x90, 60, 100}).endOfTrack();
  second.event(0, {62, 100}).endOfTrack();
  EXPECT_THAT(errorOf(midiFile(1, 480, {first, second})), HasSubstr("with no running status"));
}

TEST(MidiFile, RejectsStatusBytesWhereDataBytesBelong) {
  EXPECT_THAT(errorOf(oneTrack({0x00, 0x90, 60, 0x80})),
              HasSubstr("byte 25: byte 0x80 where a data byte of channel message 0x90 is expected; "
                        "data bytes are 0x00-0x7F"));
  EXPECT_THAT(errorOf(oneTrack({0x00, 0xC0, 0xFF})), HasSubstr("byte 0xFF where a data byte"));
}

TEST(MidiFile, RejectsSystemCommonAndRealTimeBytesInATrack) {
  for (std::uint8_t status : {0xF1, 0xF2, 0xF3, 0xF4, 0xF5, 0xF6, 0xF8, 0xFA, 0xFC, 0xFE})
    EXPECT_THAT(errorOf(oneTrack({0x00, 0x90, 60, 100, 0x00, status, 0x00})),
                HasSubstr("byte 27: system common or real-time byte"))
        << int(status);
}

TEST(MidiFile, RejectsInvalidSetTempoEvents) {
  EXPECT_THAT(errorOf(oneTrack({0x00, 0xFF, 0x51, 0x02, 0x07, 0xA1})),
              HasSubstr("byte 25: set-tempo meta event (FF 51) of length 2; its length must be 3"));
  EXPECT_THAT(errorOf(oneTrack({0x00, 0xFF, 0x51, 0x03, 0x00, 0x00, 0x00})),
              HasSubstr("tempo of 0 microseconds per quarter note"));
}

// The event cap: maxMidiEvents two-byte program changes read, one more is refused.
TEST(MidiFile, CapsTheNumberOfEvents) {
  Bytes data = {0x00, 0xC0, 0x00};
  for (std::size_t i = 1; i < maxMidiEvents; ++i) data.insert(data.end(), {0x00, 0x01});
  EXPECT_EQ(parse(oneTrack(data)).messages.size(), maxMidiEvents);
  data.insert(data.end(), {0x00, 0x01});
  EXPECT_THAT(errorOf(oneTrack(data)),
              HasSubstr("more than 2097152 channel messages and tempo changes"));
}

TEST(MidiFile, RejectsFilesOver64MiB) {
  EXPECT_THAT(errorOf(Bytes(maxMidiFileBytes + 1, 0)),
              HasSubstr("byte 0: 67108865 bytes; a MIDI file may have at most 67108864"));
}

TEST(MidiFile, ReadsAFileAndNamesAPathItCannotRead) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("hamiltone-midi-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  TrackWriter track;
  track.event(480, {0x90, 60, 100}).endOfTrack();
  const Bytes file = midiFile(0, 480, {track});
  std::ofstream(dir / "one.mid", std::ios::binary)
      .write(reinterpret_cast<const char*>(file.data()), static_cast<std::streamsize>(file.size()));
  expectMessages(readMidiFile(dir / "one.mid"), {{0.5, 0x90, 60, 100}});

  const std::filesystem::path missing = dir / "missing.mid";
  try {
    readMidiFile(missing);
    ADD_FAILURE() << "no error for a missing file";
  } catch (const MidiFileError& e) {
    EXPECT_THAT(e.what(), HasSubstr(missing.string() + ": cannot read the file"));
  }
  EXPECT_THROW(readMidiFile(dir), MidiFileError);  // a directory
  std::filesystem::remove_all(dir);
}

// presets/demo.mid, written by scripts/make-demo-midi.py: a piano piece of 10-30 s in MIDI notes
// 36-96, with the features the reader must handle in a real file.
TEST(MidiFile, BundledDemoParses) {
  const MidiFile demo =
      readMidiFile(std::filesystem::path(HAMILTONE_SOURCE_DIR) / "presets/demo.mid");
  EXPECT_EQ(demo.format, 1);
  EXPECT_GE(demo.lengthSeconds, 10.0);
  EXPECT_LE(demo.lengthSeconds, 30.0);
  int notes = 0, releasesByVelocity0 = 0, pedals = 0;
  for (const TimedMessage& m : demo.messages) {
    const MidiMessage& msg = m.message;
    if (msg.kind() == midi::noteOn || msg.kind() == midi::noteOff) {
      EXPECT_GE(msg.data1, 36);
      EXPECT_LE(msg.data1, 96);
    }
    if (msg.kind() == midi::noteOn) (msg.data2 > 0 ? notes : releasesByVelocity0)++;
    if (msg.kind() == midi::controller && msg.data1 == midi::sustainPedal) ++pedals;
  }
  EXPECT_GT(notes, 20);
  EXPECT_GT(releasesByVelocity0, 0);
  EXPECT_GE(pedals, 2);
}

// presets/dense-pedalled.mid, written by scripts/make-dense-midi.py for the stealing test and the
// polyphony benchmark: at least 400 notes in 40 s over the keyboard, the pedal changed with the
// harmony, and at times 20 keys or more held at once, down or kept by the pedal.
TEST(MidiFile, BundledDensePerformanceIsDense) {
  const MidiFile dense =
      readMidiFile(std::filesystem::path(HAMILTONE_SOURCE_DIR) / "presets/dense-pedalled.mid");
  bool down[128] = {}, kept[128] = {}, pedal = false;
  int notes = 0, pedals = 0, most = 0, lowest = 127, highest = 0;
  for (const TimedMessage& m : dense.messages) {
    const MidiMessage& msg = m.message;
    const int key = msg.data1 & 0x7F;
    if (msg.kind() == midi::noteOn && msg.data2 > 0) {
      notes += m.seconds < 40.0;
      down[key] = true;
      kept[key] = false;
      lowest = std::min(lowest, key);
      highest = std::max(highest, key);
    } else if (msg.kind() == midi::noteOn || msg.kind() == midi::noteOff) {
      down[key] = false;
      kept[key] = pedal;
    } else if (msg.kind() == midi::controller && msg.data1 == midi::sustainPedal) {
      ++pedals;
      pedal = msg.data2 >= 64;
      if (!pedal) std::fill(std::begin(kept), std::end(kept), false);
    }
    int held = 0;
    for (int k = 0; k < 128; ++k) held += down[k] || kept[k];
    most = std::max(most, held);
  }
  EXPECT_GE(notes, 400);
  EXPECT_GE(pedals, 20);
  EXPECT_GE(most, 20);
  EXPECT_LE(lowest, 36);   // across the keyboard: C2 and below …
  EXPECT_GE(highest, 84);  // … to C6 and above
}

}  // namespace
}  // namespace hamiltone
