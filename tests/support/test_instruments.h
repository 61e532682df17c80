// Small instruments built in code for the synthesizer's tests: a few piano keys (RT-425 strings,
// one string per key, cheap to run) and a small plate.
#pragma once

#include <string>

#include "instruments/piano_scale.h"
#include "synth/instrument.h"

namespace hamiltone::testing {

inline Instrument pianoKeys(int lowest, int highest, int polyphony = 8) {
  Instrument instrument;
  instrument.name = "test piano";
  instrument.source = "pianoKeys(" + std::to_string(lowest) + ", " + std::to_string(highest) + ")";
  instrument.lowestNote = lowest;
  instrument.highestNote = highest;
  instrument.polyphony = polyphony;
  for (int note = lowest; note <= highest; ++note) {
    StringKey key;
    key.patch.string = pianoString(note);
    key.patch.t60Low = 8.0;
    key.patch.t60High = 2.0;
    instrument.keys.push_back(key);
  }
  return instrument;
}

inline Instrument smallPlate() {
  Instrument instrument;
  instrument.name = "test plate";
  instrument.source = "smallPlate()";
  instrument.model = InstrumentModel::plate;
  instrument.plate.plate.lx = instrument.plate.plate.ly = 0.12;
  instrument.plate.referenceNote = 60;
  instrument.plate.lowestNote = instrument.lowestNote = 60;
  instrument.plate.highestNote = instrument.highestNote = 62;
  return instrument;
}

}  // namespace hamiltone::testing
