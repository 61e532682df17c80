// Every bundled preset plays clean: at its lowest, middle and highest notes (a string instrument
// at every 6th key too), pianissimo to fortissimo, each voice stays finite, never trips its guard,
// and peaks at most at full scale once the instrument's gain is applied.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <vector>

#include "presets/preset_loader.h"

namespace hamiltone {
namespace {

constexpr double kRate = 48000.0;
constexpr double kSeconds = 0.3;  // the strike and the first few hundred periods of the lowest note

struct Played {
  double peak = 0.0;
  bool finite = true;
  int guardEvents = 0;
};

template <class Voice>
Played play(Voice& voice, double velocity) {
  voice.noteOn(velocity);
  std::vector<float> left(256), right(256);
  Played out;
  for (long n = 0; n < std::lround(kSeconds * kRate / 256); ++n) {
    voice.process(left, right);
    for (size_t i = 0; i < left.size(); ++i) {
      out.finite = out.finite && std::isfinite(left[i]) && std::isfinite(right[i]);
      out.peak = std::max({out.peak, std::abs(double(left[i])), std::abs(double(right[i]))});
    }
  }
  out.guardEvents = voice.guardEvents();
  return out;
}

// One voice per key, the first unison string as the synthesizer plays it (the strings differ by a
// few cents only).
Played playNote(const Instrument& instrument, int note, double velocity) {
  if (instrument.model == InstrumentModel::plate) {
    PlateVoice voice;
    voice.prepare(instrument.plate, note, kRate);
    return play(voice, velocity);
  }
  StringVoice voice;
  voice.prepare(unisonPatch(instrument, note, 0), note, kRate);
  return play(voice, velocity);
}

TEST(BundledPresets, RenderClean) {
  for (const char* name :
       {"paper-c3-string", "grand-piano", "grand-piano-strings", "steel-plate", "gong",
        "thunder-sheet", "small-cymbal"}) {
    const Instrument instrument =
        loadPreset(std::string(HAMILTONE_SOURCE_DIR) + "/presets/" + name + ".toml");
    const int lo = instrument.lowestNote, hi = instrument.highestNote;
    // Strings: every key, softest and hardest, and mezzo-forte every 6th; plates (slow to
    // prepare, their size a smooth function of the note): the lowest, middle and highest notes.
    std::set<int> notes{lo, (lo + hi) / 2, hi};
    if (instrument.model == InstrumentModel::string)
      for (int note = lo; note <= hi; ++note) notes.insert(note);
    const double gain = std::pow(10.0, instrument.gainDb / 20.0);
    for (int note : notes)
      for (double velocity : {1.0 / 127.0, 64.0 / 127.0, 1.0}) {
        if (velocity == 64.0 / 127.0 && instrument.model == InstrumentModel::string &&
            (note - lo) % 6 != 0)
          continue;
        const Played p = playNote(instrument, note, velocity);
        EXPECT_TRUE(p.finite) << name << " note " << note << " velocity " << velocity;
        EXPECT_EQ(p.guardEvents, 0) << name << " note " << note << " velocity " << velocity;
        EXPECT_GT(p.peak, 0.0) << name << " note " << note << " velocity " << velocity;
        EXPECT_LE(p.peak * gain, 1.0) << name << " note " << note << " velocity " << velocity;
      }
  }
}

}  // namespace
}  // namespace hamiltone
