// A string instrument's body: the board and its sympathetic strings from the instrument's keys.
#include "synth/instrument_body.h"

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "instruments/piano_scale.h"
#include "voices/string_voice.h"

namespace hamiltone {

std::vector<SympatheticKey> sympatheticKeys(const Instrument& instrument) {
  std::vector<SympatheticKey> keys;
  for (int note = instrument.lowestNote; note <= instrument.highestNote; ++note) {
    const StringKey& key = instrument.keys[note - instrument.lowestNote];
    const StringPhysics& s = key.patch.string;
    keys.push_back({.f0 = equalTemperament(note, key.patch.a4Hz),
                    .inharmonicityB = std::numbers::pi * std::numbers::pi * s.young * s.inertia /
                                      (s.tension * s.length * s.length),
                    .linearDensity = s.linearDensity(),
                    .length = s.length,
                    .tension = s.tension,
                    .unisons = key.unisons,
                    .t60Low = key.patch.t60Low,
                    .t60High = key.patch.t60High,
                    .t60HighHz = key.patch.t60HighHz,
                    // The preset's 1000 s says "no damper" (F6 up): such a key never sleeps.
                    .damperT60 = key.patch.damperT60 >= kNoDamperT60
                                     ? std::numeric_limits<double>::infinity()
                                     : key.patch.damperT60});
  }
  return keys;
}

void prepareBody(PianoBody& body, const Instrument& instrument, double sampleRate) {
  bool bridged = false;
  for (const StringKey& key : instrument.keys) bridged = bridged || key.bridge.mass > 0.0;
  if (!bridged)
    throw std::invalid_argument(
        "body.enabled = true: no key has a bridge to drive the soundboard (set bridge.mass_kg > "
        "0)");
  PianoBodySpec spec;
  spec.board.maxModeHz = instrument.body.maxModeHz;
  spec.sampleRate = sampleRate;
  spec.sympatheticMaxHz = std::min(instrument.body.sympatheticMaxHz, 0.24 * sampleRate);
  const std::vector<BoardPoint> points =
      bridgeLine(instrument.lowestNote, instrument.highestNote, spec.board);
  // Damped keys whose strings have gone quiet, where the board is still, sleep out of the coupling
  // (PianoBody) and wake when a voice strikes or the board moves them: the sound is that of every
  // key kept in (setQuietFloor(-1)) but for the floor's share (−54 dB for C4 after silence in
  // sympathetic_strings_test.cpp; A0 struck hard in the synth renders the same bits), at the cost
  // of the keys the board moves.
  body.prepare(spec, points, sympatheticKeys(instrument));
}

}  // namespace hamiltone
