// The string plan of a concert grand across the keyboard: per-key length, core diameter, linear
// density and tension, from Chabassier & Duruflé's Steinway D model (RT-425).
#pragma once

#include "instruments/string.h"

namespace hamiltone {

// Equal temperament: 440 · 2^((note − 69)/12) for A4 = 440 Hz.
double equalTemperament(int midiNote, double a4Hz = 440.0);

// The string of key `midiNote` (21 … 108) before tuning: L, core d (EI = E π d⁴/64, A = π d²/4) and
// an effective density that carries a wound string's copper (ρA from RT-425), T0 from RT-425.
// Between the table's keys every quantity is interpolated geometrically; A0–B0 (not in RT-425)
// take C1's string. Throws std::invalid_argument outside 21 … 108.
StringPhysics pianoString(int midiNote);

}  // namespace hamiltone
