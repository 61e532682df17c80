// libFuzzer target for the preset loader: any text must either load or be refused with a
// PresetError. Any other exception, a crash, a hang or a sanitizer report is a finding. The
// voices' own check is left out: it prepares real voices, milliseconds per input. After a NUL
// byte, each line is a --set NAME=VALUE over the text before it (its VALUE goes to toml++ too).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <utility>
#include <vector>

#include "presets/preset_loader.h"

namespace {

bool positive(double x) { return std::isfinite(x) && x > 0.0; }

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace hamiltone;
  std::string_view text(reinterpret_cast<const char*>(data), size);
  std::vector<PresetOverride> overrides;
  if (const std::size_t nul = text.rfind('\0'); nul != std::string_view::npos) {
    for (std::string_view sets = text.substr(nul + 1); !sets.empty();) {
      const std::size_t end = std::min(sets.find('\n'), sets.size());
      if (auto o = parseOverride(sets.substr(0, end))) overrides.push_back(std::move(*o));
      sets.remove_prefix(std::min(end + 1, sets.size()));
    }
    text = text.substr(0, nul);
  }
  try {
    const Instrument instrument =
        parsePreset(text, "fuzz.toml", {.checkVoices = false, .overrides = overrides});
    // What the loader promises of every preset it accepts.
    if (instrument.lowestNote < 0 || instrument.highestNote > 127 ||
        instrument.lowestNote > instrument.highestNote)
      __builtin_trap();
    if (instrument.model == InstrumentModel::string) {
      if (instrument.keys.size() !=
          static_cast<std::size_t>(instrument.highestNote - instrument.lowestNote + 1))
        __builtin_trap();
      for (const StringKey& key : instrument.keys) {
        const StringPatch& p = key.patch;
        if (key.unisons < 1 || key.unisons > 3 || !(key.detuneCents >= 0.0) ||
            !(key.detuneCents <= 20.0) || !positive(p.string.length) || !positive(p.string.area) ||
            !positive(p.string.density) || !positive(p.string.tension) ||
            !positive(p.hammer.mass) || !(p.t60High <= p.t60Low) || !positive(p.damperT60))
          __builtin_trap();
      }
    } else if (!positive(instrument.plate.plate.lx) || !positive(instrument.plate.plate.ly) ||
               !(instrument.plate.durationMin <= instrument.plate.durationMax)) {
      __builtin_trap();
    }
  } catch (const PresetError& e) {
    if (e.lines.empty() || e.lines.size() > 100) __builtin_trap();
  }
  return 0;
}
