// --preset and --set for both players: the overrides are the loader's (PresetOptions::overrides);
// this reads them off the command line and gathers every preset's errors into one UsageError.
#include "preset_arguments.h"

#include "preset_search.h"
#include "presets/parameters.h"
#include "usage_error.h"

namespace hamiltone::cli {

void addSetOption(CLI::App* app, std::vector<std::string>& sets) {
  app->add_option("--set", sets,
                  "set a preset parameter in every loaded preset, over its file; repeatable. NAME "
                  "as hamiltone-render --list-params lists it, VALUE as in a file (3.5, inf, "
                  "true, \"C4\"; a word may go unquoted: scheme.grid_rule=longitudinal). A "
                  "per-key parameter set here holds at every key, over the file's [[key]] "
                  "anchors; a narrower lowest_note/highest_note builds those keys only.")
      ->type_name("NAME=VALUE")
      ->allow_extra_args(false);
}

std::vector<PresetOverride> parseSets(const std::vector<std::string>& sets) {
  std::vector<PresetOverride> out;
  for (const std::string& set : sets) {
    if (auto o = parseOverride(set)) {
      out.push_back(std::move(*o));
      continue;
    }
    const std::string name = set.substr(0, set.find('='));
    // A parameter's name alone: the value is what is missing.
    if (findParameter(name))
      throw UsageError("--set " + set + ": expected " + name +
                       "=VALUE (hamiltone-render --list-params gives its type and range)");
    throw UsageError("--set " + set +
                     ": expected NAME=VALUE, e.g. --set scheme.grid_rule=longitudinal or --set "
                     "hammer.velocity_max_m_s=4 (hamiltone-render --list-params lists every NAME, "
                     "its type and range)");
  }
  return out;
}

std::vector<Instrument> loadPresets(const std::vector<std::string>& files,
                                    const std::vector<std::string>& sets, double checkRate) {
  // MIDI program change selects one of 128: a preset past them could never be played.
  if (files.size() > 128)
    throw UsageError("--preset given " + std::to_string(files.size()) +
                     " times: MIDI program change reaches 128 presets (programs 0 … 127); "
                     "expected at most 128");
  PresetOptions options;
  options.checkRate = checkRate;
  options.overrides = parseSets(sets);
  std::vector<Instrument> instruments;
  std::string errors;
  for (const std::string& file : files) {
    try {
      instruments.push_back(loadPreset(resolvePreset(file), options));
    } catch (const PresetError& e) {
      errors += std::string(errors.empty() ? "" : "\n") + e.what();
    }
  }
  if (!errors.empty()) throw UsageError("bad preset:\n" + errors);
  return instruments;
}

std::string unplayedNotes(std::span<const TimedMessage> messages,
                          const std::vector<Instrument>& instruments) {
  // As Synth::handle does: a program change selects one of the loaded presets (others are
  // ignored), and a note-on of velocity > 0 strikes the key in the preset then in force.
  std::vector<bool> silent(128, false);
  size_t program = 0;
  for (const TimedMessage& m : messages) {
    if (m.message.kind() == midi::program && m.message.data1 < instruments.size())
      program = m.message.data1;
    if (m.message.kind() != midi::noteOn || m.message.data2 == 0 || instruments.empty()) continue;
    const int note = m.message.data1 & 0x7F;
    const Instrument& i = instruments[program];
    if (note < i.lowestNote || note > i.highestNote) silent[note] = true;
  }
  return numberList(silent);
}

std::string unloadedPrograms(std::span<const TimedMessage> messages, size_t loaded) {
  std::vector<bool> asked(128, false);
  for (const TimedMessage& m : messages)
    if (m.message.kind() == midi::program && m.message.data1 >= loaded)
      asked[m.message.data1 & 0x7F] = true;
  return numberList(asked);
}

std::string numberList(const std::vector<bool>& set) {
  std::string list;
  for (size_t n = 0; n < set.size(); ++n) {
    if (!set[n]) continue;
    list += ' ';
    list += std::to_string(n);
  }
  return list;
}

std::string ignoredProgramText(const std::string& programs, size_t loaded) {
  const bool several = programs.find(' ', 1) != std::string::npos;
  const std::string range =
      loaded == 1 ? "program 0" : "programs 0 to " + std::to_string(loaded - 1);
  return std::string(several ? "program changes to" : "program change to") + programs +
         (several ? " are" : " is") + " ignored: " + std::to_string(loaded) +
         (loaded == 1 ? " preset is" : " presets are") + " loaded (" + range +
         "); give --preset once per program (the first is program 0)";
}

}  // namespace hamiltone::cli
