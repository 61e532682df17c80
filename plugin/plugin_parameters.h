// The plugin's parameters (DPF indices, also CLAP's parameter ids) and state keys, for the plugin
// and for the tests that host it.
#pragma once

namespace hamiltone::plugin {

enum Parameter : unsigned {
  kPreset,         // which bundled preset, 0 … bundledPresets().size() − 1
  kGainDb,         // −60 … +12 dB
  kVelocityCurve,  // 0.25 … 4, Controls::velocityCurve
  kDamperScale,    // 0.25 … 4, Controls::damperScale
  kPolyphony,      // 0 … 64; 0: the preset's
  kStatus,         // output: LoadStatus (0 loading, 1 ready, 2 failed)
  kLightTails,     // 0 or 1, Controls::lightTails (last, so that older sessions keep their ids)
  kParameterCount
};

// The values of kStatus.
enum class LoadStatus { loading = 0, ready = 1, failed = 2 };

// State, saved and restored with the session: two host-writable strings, and the Preset
// parameter's value again — an LV2 host restores state before the plugin plays, but its control
// ports only with the first block, so that the first build was always the default preset.
enum StateKey : unsigned { kPresetFile, kOverrides, kPresetIndex, kStateCount };
inline constexpr const char* kStateKeys[kStateCount] = {"preset_file", "overrides", "preset_index"};

}  // namespace hamiltone::plugin
