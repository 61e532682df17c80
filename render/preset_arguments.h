// --preset FILE and --set NAME=VALUE as hamiltone-render and hamiltone-play both take them: one
// help text, one reading of the arguments, every preset loaded with the same overrides.
#pragma once

#include <CLI/App.hpp>
#include <span>
#include <string>
#include <vector>

#include "midi/midi_message.h"
#include "presets/preset_loader.h"

namespace hamiltone::cli {

// Registers the repeatable --set NAME=VALUE, its help saying what wins over what.
void addSetOption(CLI::App* app, std::vector<std::string>& sets);

// The --set arguments, in order; UsageError for the first without NAME=, saying what is valid.
std::vector<PresetOverride> parseSets(const std::vector<std::string>& sets);

// Every file (or preset name, resolvePreset) loaded with every --set over it
// (PresetOptions::overrides), its voices checked at `checkRate` (the rate they will play at, when
// known); UsageError "bad preset:" with every error line of every file, or of a malformed --set,
// or for the first name that names no preset; UsageError for more than 128 files, more than
// program change reaches.
std::vector<Instrument> loadPresets(const std::vector<std::string>& files,
                                    const std::vector<std::string>& sets,
                                    double checkRate = kCheckRate);

// The MIDI notes that `messages` strike while the preset in force (program changes followed as
// the synthesizer does) does not play them, as " 5 120" (empty when every one is played): the
// players warn of them, as they are silent.
std::string unplayedNotes(std::span<const TimedMessage> messages,
                          const std::vector<Instrument>& instruments);

// The programs `messages` change to that are not loaded (Synth ignores them), as " 3 7", each
// once, in order (empty when every one is loaded).
std::string unloadedPrograms(std::span<const TimedMessage> messages, size_t loaded);
// The numbers n with set[n], as " 3 7", in order (empty for none): the lists of the warnings.
std::string numberList(const std::vector<bool>& set);
// Why such a change is ignored and what would play it: "program change to 3 is ignored: 1 preset
// is loaded (program 0); give --preset once per program (the first is program 0)".
std::string ignoredProgramText(const std::string& programs, size_t loaded);

}  // namespace hamiltone::cli
