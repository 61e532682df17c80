// The body of a string instrument as the synthesizer builds it (BodyPatch): the soundboard of
// docs/instrument-data.md §6, the keys' points on its bridges, and every key's strings, from the
// key's own patch, ringing in sympathy on it.
#pragma once

#include "instruments/piano_body.h"
#include "synth/instrument.h"

namespace hamiltone {

// Each key's sympathetic strings: its note's equal-tempered pitch, its first unison string's
// length, linear density, tension guess and B = π² EI / (T L²), its unisons, losses and damper.
std::vector<SympatheticKey> sympatheticKeys(const Instrument& instrument);

// May allocate. Throws std::invalid_argument naming the field (from the board and the strings),
// or if no key of the instrument has a bridge to drive the board.
void prepareBody(PianoBody& body, const Instrument& instrument, double sampleRate);

}  // namespace hamiltone
