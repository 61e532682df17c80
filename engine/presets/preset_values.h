// What a preset sets, once read: each parameter's setting (from the file or a --set), the [[key]]
// anchors, and the value they give a parameter — at a key, between the anchors, for the per-key
// ones; the default where nothing sets it. The TOML reader fills it; the builders read it.
#pragma once

#include <compare>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "presets/parameters.h"
#include "synth/instrument.h"

namespace hamiltone {

// In the file, or the nth --set (n >= 1): those come after the file, in the order given.
struct Place {
  int set = 0;
  long line = 1, column = 1;
  auto operator<=>(const Place&) const = default;
};

// A value the file sets: a number (real, integer, note; a boolean as 1 or 0) or a word, where it
// stands, and how a message shows it.
struct Setting {
  double number = 0.0;
  std::string word = {};
  Place place;
  std::string shown;
};

using Settings = std::map<std::string_view, Setting>;  // by the table's name of the parameter

struct Anchor {
  int note = 0;
  Place place;        // of its note = …
  std::string shown;  // the note as written
  Settings values;
};

struct PresetValues {
  std::optional<InstrumentModel> model;  // none while unread or invalid
  Settings settings;                     // the file's top level and sections, then the --sets
  std::vector<Anchor> anchors;           // by note once read

  // The row `name` has for the model (any model's before it is known); throws std::logic_error
  // for a name the table does not hold.
  const Parameter& row(std::string_view name) const;
  const Setting* setting(std::string_view name) const;  // nullptr where nothing sets it
  double number(std::string_view name) const;           // the setting's, else the default
  std::string word(std::string_view name) const;
  bool anchored(const Parameter& p) const;  // an anchor sets it
  double atKey(const Parameter& p, int note) const;
};

// A voice's complaint ("damper_t60_s = 0.001: must be …") names its field; this is the preset
// parameter it comes from. `keep`: the voice's own "field = value" says more than the parameter's
// value would (a derived quantity), so the whole message is kept.
struct VoiceField {
  std::string_view field, parameter;
  bool keep = false;
};

}  // namespace hamiltone
