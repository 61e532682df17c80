// Preset files: the TOML description of an instrument (every key is a row of parameters.h), read,
// checked against the parameter table and against the voices themselves, and built into an
// Instrument — or refused with every problem found, one line each.
#pragma once

#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "synth/instrument.h"

namespace hamiltone {

// Everything wrong with a preset, one line per problem, in file order:
//   FILE:LINE:COL: key = value: what is valid
// e.g. "presets/x.toml:12:1: string.tension_n = 759: unknown key; did you mean string.tension_N?".
// A line about a --set says it instead of LINE:COL: "presets/x.toml: --set scheme.oversampling=3:
// expected one of 1, 2, 4, 8, 16, 32, 64". what() is the lines joined with '\n'.
struct PresetError : std::runtime_error {
  explicit PresetError(std::vector<std::string> messages);
  std::vector<std::string> lines;
};

// A parameter given on the command line (--set NAME=VALUE) over the file's: VALUE is written as
// on the right of `=` in a file (3.5, inf, true, "C4"); a word that is not TOML (longitudinal, C4)
// is taken as quoted text.
struct PresetOverride {
  std::string name, value;
};

// "NAME=VALUE" split at the first '=', blanks around each dropped; nothing without '=' or NAME.
std::optional<PresetOverride> parseOverride(std::string_view argument);

// `s` as the messages quote a name or a value: at most 40 bytes, cut at a character boundary with
// "…" after the cut, control characters as '?'; `quoted`: in double quotes, " and \ escaped.
std::string shownInMessage(std::string_view s, bool quoted);

// The rate the loader prepares voices at to check a preset when the playing rate is not known.
constexpr double kCheckRate = 48000.0;

struct PresetOptions {
  // Prepare a voice for some keys and report what it refuses (a tuning with no solution, a grid
  // too coarse for the string or too fine for the plate): the lowest, the highest, every 12th key
  // from the lowest and every anchor of a string instrument; the lowest, reference and highest
  // note of a plate. Made at checkRate, a few milliseconds a key (a large plate's more): a voice
  // prepared at another rate can still refuse a patch this check passed.
  bool checkVoices = true;
  // The sample rate those voices are checked at: the one they will play at, where it is known
  // (hamiltone-render's --sample-rate); the usual 48 kHz otherwise.
  double checkRate = kCheckRate;
  // Set over the file, in order, each checked as a key of the file is (name, type, range, model)
  // and blamed by its "--set NAME=VALUE" in the messages. A per-key parameter set here holds at
  // every key: it replaces the file's value and the [[key]] anchors' — what a user comparing
  // settings means. Anchors are checked against the file's own lowest_note … highest_note, so a
  // narrower range set here keeps the piano's per-key values and builds only its keys. The model
  // cannot be set: it decides what every other key of the file means. A voice refused with the
  // overrides is reported at the setting it names, with every --set listed after it.
  std::vector<PresetOverride> overrides = {};
  // How the messages name an override, before its NAME=VALUE: the command lines' "--set ", the
  // plugin's "overrides: ".
  std::string overrideLabel = "--set ";
};

// Reads `file` (at most 1 MiB) and parses it; its path, as given, names it in the messages.
// Throws PresetError.
Instrument loadPreset(const std::filesystem::path& file, const PresetOptions& options = {});

// The work of loadPreset on text already read. Never crashes or hangs on any input: anything but
// a valid preset throws PresetError (at most 100 lines, the last saying how many more there were).
Instrument parsePreset(std::string_view text, const std::string& sourceName,
                       const PresetOptions& options = {});

}  // namespace hamiltone
