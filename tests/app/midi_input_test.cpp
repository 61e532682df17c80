// The names the player watches a chosen MIDI port by (app/midi_input.h): ALSA's client:port
// numbers left out, and a2j's [client] number, so a keyboard plugged in again is found again;
// JACK's names as they are.
#include "midi_input.h"

#include <gtest/gtest.h>

namespace hamiltone::app {
namespace {

TEST(MidiInput, StablePortNamesLeaveOutAlsasClientAndPortNumbers) {
  EXPECT_EQ(stablePortName("Keystation 88:Keystation 88 MIDI 1 24:0"),
            "Keystation 88:Keystation 88 MIDI 1");
  EXPECT_EQ(stablePortName("Midi Through:Midi Through Port-0 14:0"),
            "Midi Through:Midi Through Port-0");
  EXPECT_EQ(stablePortName("hamiltone-keys:out"), "hamiltone-keys:out");  // JACK
  // a2j (ALSA MIDI bridged into JACK) puts the ALSA client number in brackets: plugged in again,
  // the keyboard may come back as [28], and was never connected again.
  EXPECT_EQ(stablePortName("a2j:Keystation [24] (capture): Keystation 88 MIDI 1"),
            "a2j:Keystation (capture): Keystation 88 MIDI 1");
  EXPECT_EQ(stablePortName("a2j:Keystation [28] (capture): Keystation 88 MIDI 1"),
            stablePortName("a2j:Keystation [24] (capture): Keystation 88 MIDI 1"));
  EXPECT_EQ(stablePortName("a2j:Synth [x] (capture): out"), "a2j:Synth [x] (capture): out");
  EXPECT_EQ(stablePortName("other:Synth [24] (capture): out"), "other:Synth [24] (capture): out");
  EXPECT_EQ(stablePortName("Synth 1:2x"), "Synth 1:2x");
  EXPECT_EQ(stablePortName("port 12:"), "port 12:");
  EXPECT_EQ(stablePortName(""), "");
}

TEST(MidiInput, PortListNumbersThePortsOrSaysNone) {
  EXPECT_EQ(portList({}), "none");
  EXPECT_EQ(portList({"a:out", "b:out"}), "0: a:out; 1: b:out");
}

}  // namespace
}  // namespace hamiltone::app
