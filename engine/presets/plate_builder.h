// The plate instrument's builder: a read preset's values made into the PlatePatch, and the voices'
// check at a few notes.
#pragma once

#include <functional>
#include <span>
#include <string_view>

#include "presets/preset_values.h"
#include "synth/instrument.h"

namespace hamiltone {

// Fills the plate model's part of `instrument`: its PlatePatch.
void buildPlatePatch(const PresetValues& values, Instrument& instrument);

// Prepares, at `rate`, the plate at the lowest, reference (when in range) and highest note; each
// refusal goes to `refused` with its note.
void checkPlateVoices(const Instrument& instrument,
                      const std::function<void(std::string_view message, int note)>& refused,
                      double rate);

// The preset parameter behind each field a PlateVoice's complaint names.
std::span<const VoiceField> plateVoiceFields();

}  // namespace hamiltone
