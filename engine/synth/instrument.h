// An instrument: what one preset file describes, ready for the synthesizer to build voices from —
// a string per key (with its unisons) or a plate sized to each note.
#pragma once

#include <string>
#include <vector>

#include "voices/plate_voice.h"
#include "voices/string_voice.h"

namespace hamiltone {

enum class InstrumentModel { string, plate };

// One key of a string instrument: 1 to 3 unison strings from one patch, spread in pitch.
struct StringKey {
  StringPatch patch;         // tuned to the key's note by the voice
  int unisons = 1;           // 1, 2 or 3
  double detuneCents = 0.0;  // between the outermost strings: they sit at ±detune/2 (and 0)
  BridgePhysics bridge;      // the strings' common end; mass 0: rigid ends, each string alone
};

// The piano's body (string instruments): the soundboard the keys' bridges drive, with every key's
// strings ringing in sympathy on it (instruments/piano_body.h), heard at the board's two pickups
// beside the strings' own.
struct BodyPatch {
  bool enabled = false;
  double gain = 1.0;                 // output units per m/s of the board at its pickups
  double maxModeHz = 1000.0;         // the board's modes up to here (its cost: modes × keys)
  double sympatheticMaxHz = 4500.0;  // the sympathetic strings' partials up to here (< fs/4)
};

struct Instrument {
  std::string name;    // shown to the player
  std::string source;  // the preset file it came from
  InstrumentModel model = InstrumentModel::string;
  int lowestNote = 21, highestNote = 108;  // MIDI; notes outside are ignored
  std::vector<StringKey> keys;             // string model: keys[note − lowestNote]
  PlatePatch plate;                        // plate model: PlateVoice sizes it to each note
  int polyphony = 64;                      // keys sounding at once, at most
  double gainDb = 0.0;                     // applied to the sum of the voices
  double bendRange = 2.0;                  // semitones each way of the pitch wheel (strings)
  double panSpread = 0.5;                  // 0: all centred; 1: lowest key left … highest right
  BodyPatch body;                          // string instruments only
};

// The patch of unison string `string` (0 … unisons−1) of `note`, as the synthesizer plays it: the
// strings spread evenly across ±detune/2 (one at 0; two at ±d/2; three at −d/2, 0, +d/2), each
// with the instrument's bend range, and sharing one hammer — M_H/n and K_H/n each, the same hammer
// while the strings move alike (F = K δ^p). The loader checks these very patches.
StringPatch unisonPatch(const Instrument& instrument, int note, int string);
// How far the key's bridge pulls its strings' fundamental at `hz`, cents (negative: flat), struck
// together (in phase); 0 without a bridge.
double bridgeLoadCents(const StringKey& key, double hz);

}  // namespace hamiltone
