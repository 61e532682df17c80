// The presets of presets/ compiled into the plugin (cmake/embed_presets.cmake writes their text
// into a source file at build time), so a plugin bundle copied anywhere has its instruments and
// reads no file to load one.
#pragma once

#include <span>

namespace hamiltone::plugin {

struct BundledPreset {
  const char* file;  // "grand-piano.toml"
  const char* name;  // its `name`, shown to the player: "Grand piano"
  const char* text;  // the TOML
};

// In the order of HAMILTONE_PLUGIN_PRESETS in plugin/CMakeLists.txt; the first is the default.
std::span<const BundledPreset> bundledPresets();

}  // namespace hamiltone::plugin
