// How an instrument's key becomes the patches of its unison strings.
#include "synth/instrument.h"

namespace hamiltone {

StringPatch unisonPatch(const Instrument& instrument, int note, int string) {
  const StringKey& key = instrument.keys.at(note - instrument.lowestNote);
  StringPatch patch = key.patch;
  patch.detuneCents =
      key.unisons == 1 ? 0.0 : key.detuneCents * (string / (key.unisons - 1.0) - 0.5);
  patch.bendRange = instrument.bendRange;
  patch.hammer.mass /= key.unisons;
  patch.hammer.stiffness /= key.unisons;
  return patch;
}

}  // namespace hamiltone
