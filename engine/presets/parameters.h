// The preset parameter table: every key a preset file may hold, with its type, unit, range,
// default, model and doc — the one source the loader validates against, takes its defaults from,
// and `hamiltone-render --list-params` prints. MIDI note names are read and written here too.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "synth/instrument.h"

namespace hamiltone {

enum class ParameterType {
  real,     // a TOML integer or float; inf where the range allows it, never nan
  integer,  // a TOML integer (and one of `choices` when they are given)
  choice,   // a quoted word out of `choices`
  boolean,  // true or false
  note,     // a MIDI number 0 … 127 or a name in quotes, "C4" = 60 (see parseNoteName)
  text,     // any quoted text
};

enum class ParameterModel { string, plate, both };

enum class DefaultKind {
  value,     // defaultText is the default, written as in a file
  required,  // the file must set it
  derived,   // defaultText says how it follows from other parameters
};

// Every field has a default, so a row names only what it sets.
struct Parameter {
  std::string_view name = {};  // dotted, as written in the file: "string.tension_N"
  ParameterType type = ParameterType::real;
  std::string_view unit = {};   // "" when dimensionless
  double min = 0.0, max = 0.0;  // inclusive bounds of a real, integer or note
  // A parameter whose value bounds this one from below or above too ("" none).
  std::string_view minOf = {}, maxOf = {};
  std::string_view choices = {};  // choice: "string|plate"; integer: the allowed values "1|2|4"
  std::string_view defaultText = {};
  DefaultKind defaultKind = DefaultKind::value;
  ParameterModel model = ParameterModel::both;
  // May vary across the keys of a string instrument: allowed in [[key]] anchor tables. Between two
  // anchors that set it, a key's value is interpolated log-linearly in the note number
  // (geometrically) when the range is positive, linearly when it includes 0, and an integer holds
  // from its anchor up to the next one.
  bool perKey = false;
  std::string_view doc = {};
};

std::span<const Parameter> parameters();

// The section a name belongs to: "string" for "string.tension_N", "" for a top-level key.
std::string_view sectionOf(std::string_view name);
bool appliesTo(const Parameter& p, InstrumentModel model);
// The row `name` has for `model`, or nullptr (unknown, or a parameter of the other model only).
const Parameter* findParameter(std::string_view name, InstrumentModel model);
// The first row called `name` whatever its model, or nullptr.
const Parameter* findParameter(std::string_view name);

// The default of a real, integer, note or boolean (1 for true) row whose defaultKind is value.
double defaultNumber(const Parameter& p);

// The shortest text that reads back as x, its exponent without '+' or leading zeros: 1e5, 1e-4.
std::string compactNumber(double x);

// The table as text for --list-params: grouped by section, no line wider than 100 columns.
std::string parameterTable();

// "C4" = 60, "A0" = 21, "C#4" = "Db4" = 61, "C-1" = 0, "G9" = 127: a letter (either case), an
// optional # or b, and an octave −1 … 9. Nothing (std::nullopt) for anything else or outside 0 …
// 127.
std::optional<int> parseNoteName(std::string_view name);
std::string noteName(int midiNote);  // with sharps: 61 → "C#4"

}  // namespace hamiltone
