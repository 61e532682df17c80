// The string instrument's builder: a read preset's values made into one StringKey per key (the
// per-key parameters between the [[key]] anchors), and the voices' check at a few keys.
#pragma once

#include <functional>
#include <span>
#include <string_view>

#include "presets/preset_values.h"
#include "synth/instrument.h"

namespace hamiltone {

// Fills the string model's part of `instrument`: its bend range and keys lowestNote … highestNote.
void buildStringKeys(const PresetValues& values, Instrument& instrument);

// Prepares, at `rate`, the outermost unison strings of the lowest and highest key, of every 12th
// key from the lowest and of every anchor in range; each refusal goes to `refused` with its note.
void checkStringVoices(const Instrument& instrument, const PresetValues& values,
                       const std::function<void(std::string_view message, int note)>& refused,
                       double rate);

// The preset parameter behind each field a StringVoice's complaint names.
std::span<const VoiceField> stringVoiceFields();

}  // namespace hamiltone
