// parseNoteList: the --notes grammar, the order of the messages it yields, and a message for
// every kind of bad item that names the item and what is valid.
#include "note_list.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "usage_error.h"

namespace {

using hamiltone::MidiMessage;
using hamiltone::TimedMessage;
using hamiltone::cli::kMaxNoteItems;
using hamiltone::cli::parseNoteList;
using hamiltone::cli::UsageError;
namespace midi = hamiltone::midi;

int noteOf(const std::string& item) { return parseNoteList(item).messages.front().message.data1; }

// The message of the UsageError the text must raise.
std::string errorOf(const std::string& text) {
  try {
    parseNoteList(text);
  } catch (const UsageError& e) {
    return e.what();
  }
  ADD_FAILURE() << "\"" << text << "\" was accepted";
  return "";
}

// A compact picture of a message list: "on 48 100 @0" (note, velocity, seconds), "off 48 @1".
std::vector<std::string> picture(const std::vector<TimedMessage>& messages) {
  std::vector<std::string> lines;
  for (const TimedMessage& m : messages) {
    char line[64];
    if (m.message.kind() == midi::noteOn)
      std::snprintf(line, sizeof line, "on %d %d @%g", m.message.data1, m.message.data2, m.seconds);
    else
      std::snprintf(line, sizeof line, "off %d @%g", m.message.data1, m.seconds);
    lines.push_back(line);
  }
  return lines;
}

TEST(NoteList, NamesAreScientificPitchWithC4AtMidi60) {
  EXPECT_EQ(noteOf("C4"), 60);
  EXPECT_EQ(noteOf("C3"), 48);
  EXPECT_EQ(noteOf("A4"), 69);
  EXPECT_EQ(noteOf("C6"), 84);
  EXPECT_EQ(noteOf("B3"), 59);
  EXPECT_EQ(noteOf("c4"), 60);  // either case
  EXPECT_EQ(noteOf("C-1"), 0);
  EXPECT_EQ(noteOf("G9"), 127);
}

TEST(NoteList, AccidentalsMoveASemitoneAcrossOctaveBoundaries) {
  EXPECT_EQ(noteOf("C#3"), 49);
  EXPECT_EQ(noteOf("Db3"), 49);
  EXPECT_EQ(noteOf("Bb-1"), 10);
  EXPECT_EQ(noteOf("E#4"), 65);  // = F4
  EXPECT_EQ(noteOf("B#3"), 60);  // = C4: the octave number belongs to the letter
  EXPECT_EQ(noteOf("Cb4"), 59);  // = B3
  EXPECT_EQ(noteOf("bb3"), 58);  // B flat
}

TEST(NoteList, MidiNumbersStandForThemselves) {
  EXPECT_EQ(noteOf("0"), 0);
  EXPECT_EQ(noteOf("60"), 60);
  EXPECT_EQ(noteOf("127"), 127);
}

TEST(NoteList, DefaultsAreStartZeroVelocity100DurationOneSecond) {
  const auto list = parseNoteList("C3");
  ASSERT_EQ(list.messages.size(), 2u);
  const MidiMessage on = list.messages[0].message, off = list.messages[1].message;
  EXPECT_EQ(list.messages[0].seconds, 0.0);
  EXPECT_EQ(on.status, midi::noteOn);  // channel 0
  EXPECT_EQ(on.data1, 48);
  EXPECT_EQ(on.data2, 100);
  EXPECT_EQ(list.messages[1].seconds, 1.0);
  EXPECT_EQ(off.status, midi::noteOff);
  EXPECT_EQ(off.data1, 48);
  EXPECT_EQ(off.data2, 64);
  EXPECT_EQ(list.endSeconds, 1.0);
}

TEST(NoteList, StartVelocityAndDuration) {
  const auto list = parseNoteList("C3@0.5:80:2");
  EXPECT_EQ(picture(list.messages), (std::vector<std::string>{"on 48 80 @0.5", "off 48 @2.5"}));
  EXPECT_EQ(list.endSeconds, 2.5);
  EXPECT_EQ(picture(parseNoteList("60:90").messages),
            (std::vector<std::string>{"on 60 90 @0", "off 60 @1"}));
}

TEST(NoteList, ItemsWithoutAStartFormAChordInItemOrder) {
  EXPECT_EQ(picture(parseNoteList(" C3 ,\tE3,G3  ").messages),
            (std::vector<std::string>{"on 48 100 @0", "on 52 100 @0", "on 55 100 @0", "off 48 @1",
                                      "off 52 @1", "off 55 @1"}));
}

TEST(NoteList, MessagesAreSortedByTimeWithNoteOffsFirstAtEqualTimes) {
  // E3 starts as C3 ends: C3's note-off comes first.
  EXPECT_EQ(picture(parseNoteList("E3@1, C3").messages),
            (std::vector<std::string>{"on 48 100 @0", "off 48 @1", "on 52 100 @1", "off 52 @2"}));
}

TEST(NoteList, ARepeatedNoteIsStruckAgainNotCutOff) {
  // 0.1 + 0.2 is not 0.3 in binary; times on the microsecond grid make them equal, so the
  // first note-off still comes before the second note-on.
  const auto list = parseNoteList("C3@0.3, C3@0.1:100:0.2");
  ASSERT_EQ(list.messages.size(), 4u);
  EXPECT_EQ(list.messages[1].seconds, list.messages[2].seconds);
  EXPECT_EQ(list.messages[1].message.kind(), midi::noteOff);
  EXPECT_EQ(list.messages[2].message.kind(), midi::noteOn);
}

TEST(NoteList, EndIsTheLatestNoteOffNotTheLastItems) {
  EXPECT_EQ(parseNoteList("C3:100:5, E3@1").endSeconds, 5.0);
}

TEST(NoteList, LimitsAreInclusive) {
  std::string many = "C3";
  for (std::size_t i = 1; i < kMaxNoteItems; ++i) many += ",C3";
  EXPECT_EQ(parseNoteList(many).messages.size(), 2 * kMaxNoteItems);
  EXPECT_EQ(parseNoteList("C3@86399:100:1").endSeconds, 86400.0);
}

TEST(NoteList, UnknownNameSaysWhatIsValid) {
  EXPECT_EQ(errorOf("C3, H3:100"),
            "--notes: item 2 \"H3:100\": unknown note name \"H3\": use C, D, E, F, G, A, B with "
            "optional # or b and an octave -1…9, or a MIDI number 0…127");
  for (const char* name : {"C", "C#", "Cx4", "C##4", "C10", "C-2", "-5", "+5", "60x", "@1"})
    EXPECT_NE(errorOf(name).find("unknown note name"), std::string::npos) << name;
}

TEST(NoteList, NotesOutOfRangeAreRefused) {
  EXPECT_EQ(errorOf("128"), "--notes: item 1 \"128\": MIDI number 128 is out of range; use 0…127");
  EXPECT_NE(errorOf("99999999999999").find("out of range"), std::string::npos);
  EXPECT_EQ(errorOf("G#9"),
            "--notes: item 1 \"G#9\": note \"G#9\" would be MIDI 128; names run from C-1 (0) to "
            "G9 (127)");
  EXPECT_NE(errorOf("Cb-1").find("would be MIDI -1"), std::string::npos);
}

TEST(NoteList, StartMustBeAFiniteNumberNotBelowZero) {
  EXPECT_EQ(errorOf("C3@-1"),
            "--notes: item 1 \"C3@-1\": start = -1: out of range; expected a finite number >= 0 "
            "(seconds)");
  EXPECT_NE(errorOf("C3@nan").find("start = nan: not finite"), std::string::npos);
  EXPECT_NE(errorOf("C3@inf").find("start = inf: not finite"), std::string::npos);
  EXPECT_NE(errorOf("C3@1x").find("start = '1x': not a number"), std::string::npos);
  EXPECT_NE(errorOf("C3@").find("start = '': not a number"), std::string::npos);
  EXPECT_NE(errorOf("C3@1@2").find("start = '1@2': not a number"), std::string::npos);
}

TEST(NoteList, VelocityMustBeAWholeNumberFrom1To127) {
  EXPECT_EQ(errorOf("C3:0"),
            "--notes: item 1 \"C3:0\": velocity = 0: out of range; expected a whole number from 1 "
            "to 127");
  EXPECT_NE(errorOf("C3:128").find("velocity = 128: out of range"), std::string::npos);
  EXPECT_NE(errorOf("C3:1.5").find("velocity = '1.5': not a whole number"), std::string::npos);
  EXPECT_NE(errorOf("C3:").find("velocity = '': not a whole number"), std::string::npos);
}

TEST(NoteList, DurationMustBePositiveFiniteAndAtLeastOneMicrosecond) {
  EXPECT_NE(errorOf("C3:100:0").find("duration = 0: out of range; expected a finite number > 0"),
            std::string::npos);
  EXPECT_NE(errorOf("C3:100:-1").find("duration = -1: out of range"), std::string::npos);
  EXPECT_NE(errorOf("C3:100:inf").find("duration = inf: not finite"), std::string::npos);
  EXPECT_NE(errorOf("C3:100:1e-7").find("shorter than 1 µs"), std::string::npos);
}

TEST(NoteList, MalformedItemsAreRefused) {
  EXPECT_EQ(errorOf("C3:100:1:5"),
            "--notes: item 1 \"C3:100:1:5\": unexpected \":5\" after the duration; expected "
            "NOTE[@START][:VELOCITY[:DURATION]], e.g. E3@0.5:80:2");
  EXPECT_NE(errorOf("C3,,E3").find("item 2 \"\": empty"), std::string::npos);
  EXPECT_NE(errorOf("C3,").find("item 2 \"\": empty"), std::string::npos);
  EXPECT_NE(errorOf("").find("item 1 \"\": empty"), std::string::npos);
  EXPECT_NE(errorOf("C3 @1").find("item 1 \"C3 @1\": contains a space"), std::string::npos);
}

TEST(NoteList, TooManyItemsOrTooLateAreRefused) {
  std::string many = "C3";
  for (std::size_t i = 0; i < kMaxNoteItems; ++i) many += ",C3";
  EXPECT_EQ(errorOf(many), "--notes: 10001 items; at most 10000");
  EXPECT_EQ(errorOf("C3@86399.5:100:1"),
            "--notes: item 1 \"C3@86399.5:100:1\": ends at 86400.5 s, after the limit of 86400 s "
            "(24 h)");
}

}  // namespace
