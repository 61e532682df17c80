// How an instrument's key becomes the patches of its unison strings.
#include "synth/instrument.h"

#include <cmath>
#include <complex>
#include <numbers>

#include "instruments/piano_scale.h"

namespace hamiltone {

double bridgeLoadCents(const StringKey& key, double hz) {
  if (!(key.bridge.mass > 0.0)) return 0.0;
  const double w = 2.0 * std::numbers::pi * hz;
  const std::complex<double> bridge(key.bridge.resistance,
                                    w * key.bridge.mass - key.bridge.stiffness / w);
  const std::complex<double> admittance = static_cast<double>(key.unisons) / bridge;
  const StringPhysics& s = key.patch.string;
  const double z0 = std::sqrt(s.tension * s.linearDensity());
  return 1200.0 * std::log2(1.0 - z0 * admittance.imag() / std::numbers::pi);
}

StringPatch unisonPatch(const Instrument& instrument, int note, int string) {
  const StringKey& key = instrument.keys.at(note - instrument.lowestNote);
  StringPatch patch = key.patch;
  patch.detuneCents =
      (key.unisons == 1 ? 0.0 : key.detuneCents * (string / (key.unisons - 1.0) - 0.5)) -
      bridgeLoadCents(key, equalTemperament(note, patch.a4Hz));
  patch.bendRange = instrument.bendRange;
  patch.hammer.mass /= key.unisons;
  patch.hammer.stiffness /= key.unisons;
  return patch;
}

}  // namespace hamiltone
