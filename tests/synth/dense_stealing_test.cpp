// The bundled grand piano at its default polyphony through the densest part of the bundled dense
// performance: stealing takes no key whose sound is still above −60 dB of its own peak.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "midi/midi_file.h"
#include "presets/preset_loader.h"
#include "support/synth_takes.h"
#include "synth/synth.h"

namespace hamiltone {
namespace {

constexpr double kAudible = 1e-3;  // −60 dB under a key's own peak: the T60 convention of "gone"

// Bars 13-16 of presets/dense-pedalled.mid (scripts/make-dense-midi.py): the climax, two bars of
// sextuplet arpeggios over four octaves under one pedal, then the B♭7 that follows while the
// climax's 25 keys damp — the most keys sounding at once in the piece (30). It starts where the
// pedal is up, so nothing before it is missing.
constexpr double kFrom = 30.0, kTo = 37.7;  // s

TEST(DenseStealing, TheDefaultPolyphonyStealsNoKeyStillAudible) {
  const MidiFile file = readMidiFile(HAMILTONE_SOURCE_DIR "/presets/dense-pedalled.mid");
  std::vector<TimedMessage> section;
  std::vector<bool> notes(128, false);
  for (const TimedMessage& m : file.messages)
    if (m.seconds >= kFrom && m.seconds < kTo) {
      section.push_back({m.seconds - kFrom, m.message});
      if (m.message.kind() == midi::noteOn) notes[m.message.data1 & 0x7F] = true;
    }
  Synth synth;
  synth.prepare({loadPreset(HAMILTONE_SOURCE_DIR "/presets/grand-piano.toml")},
                {.sampleRate = testing::kTakeRate, .maxBlock = 256, .notes = notes});
  int most = 0;
  testing::render(synth, section, kTo - kFrom, 256,
                  [&](long) { most = std::max(most, synth.activeVoices()); });
  EXPECT_GE(most, 25) << "the section is no longer dense";
  EXPECT_LE(synth.loudestSteal(), kAudible)
      << synth.steals() << " keys stolen at the limit of " << synth.polyphony() << ", the loudest "
      << 20.0 * std::log10(synth.loudestSteal()) << " dB under its peak";
  EXPECT_EQ(synth.guardEvents(), 0);
}

}  // namespace
}  // namespace hamiltone
