// The DPF plugin: parameters and state in, PlayingSynth on the audio thread, SynthLoader building
// away from it. DPF makes the LV2, CLAP and VST3 plugins of this one class.
#include <pthread.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <span>
#include <vector>

#include "DistrhoPlugin.hpp"
#include "bundled_presets.h"
#include "playing_synth.h"
#include "plugin_parameters.h"

START_NAMESPACE_DISTRHO

namespace {

using namespace hamiltone::plugin;

// A parameter's default and range, as DPF takes them.
struct Range {
  float def, min, max;
};
constexpr Range range(const hamiltone::plugin::ControlRange& r) {
  return {static_cast<float>(r.def), static_cast<float>(r.min), static_cast<float>(r.max)};
}

class HamiltonePlugin : public Plugin {
 public:
  HamiltonePlugin() : Plugin(kParameterCount, 0, kStateCount) {
    for (unsigned i = 0; i < kParameterCount; ++i) {
      Parameter p;
      describe(i, p);
      values_[i].store(p.ranges.def, std::memory_order_relaxed);
    }
  }

 protected:
  const char* getLabel() const override { return "Hamiltone"; }
  const char* getDescription() const override {
    return "Physical-modelling instrument: struck nonlinear strings and plates, simulated sample "
           "by "
           "sample on explicit energy-conserving schemes.";
  }
  const char* getMaker() const override { return "The Hamiltone authors"; }
  const char* getLicense() const override { return "MIT"; }
  uint32_t getVersion() const override {
    return d_version(HAMILTONE_VERSION_MAJOR, HAMILTONE_VERSION_MINOR, HAMILTONE_VERSION_PATCH);
  }
  int64_t getUniqueId() const override { return d_cconst('H', 'm', 't', 'n'); }

  void initAudioPort(bool input, uint32_t index, AudioPort& port) override {
    if (input) return;
    port.groupId = kPortGroupStereo;
    port.name = index == 0 ? "Left" : "Right";
    port.symbol = index == 0 ? "out_left" : "out_right";
  }

  void initParameter(uint32_t index, Parameter& p) override { describe(index, p); }

  void initState(uint32_t index, State& state) override {
    state.key = kStateKeys[index];
    state.defaultValue = "";
    state.hints = kStateIsOnlyForDSP;
    if (index == kPresetIndex) {
      state.label = "Preset index";
      state.description =
          "The Preset parameter, saved again so that it is restored before the "
          "first block; empty: the parameter alone.";
    } else if (index == kPresetFile) {
      state.hints |= kStateIsFilenamePath;
      state.label = "Preset file";
      state.description =
          "A preset (TOML) to play instead of the bundled one the Preset parameter chooses; "
          "empty: the bundled one.";
    } else {
      state.hints |= kStateIsHostWritable;
      state.label = "Overrides";
      state.description =
          "Preset parameters set over the preset, NAME=VALUE separated by ; or new lines, as "
          "hamiltone-render --set takes them: hammer.velocity_max_m_s=4; a4_Hz=432";
    }
  }

  float getParameterValue(uint32_t index) const override {
    if (index == kStatus) return static_cast<float>(loader_.status());
    return values_[index].load(std::memory_order_relaxed);
  }

  // From any thread, the audio thread among them: atomics only.
  void setParameterValue(uint32_t index, float value) override {
    if (index >= kStatus) return;
    values_[index].store(value, std::memory_order_relaxed);
    // An index out of range is refused by the loader, naming it: held within ±1e9 before it is
    // rounded, so that it reaches the loader with its sign and near what was sent (lround of
    // 1e10 wraps where long has 32 bits; of ±inf it is unspecified).
    if (index == kPreset)
      loader_.setBundled(
          std::isnan(value) ? -1 : static_cast<int>(std::lround(std::clamp(value, -1e9f, 1e9f))));
  }

  // Not the audio thread (DPF calls it from the host's main or worker thread).
  void setState(const char* key, const char* value) override {
    if (String(key) == kStateKeys[kPresetFile]) {
      loader_.setFile(value);
    } else if (String(key) == kStateKeys[kOverrides]) {
      loader_.setOverrides(value);
    } else if (String(key) == kStateKeys[kPresetIndex]) {
      // A whole number, or nothing (a session saved before the key existed): the parameter's.
      char* end = nullptr;
      const long index = std::strtol(value, &end, 10);
      if (end == value || *end != '\0' || !bundledIndex(static_cast<double>(index))) return;
      setParameterValue(kPreset, static_cast<float>(index));
    }
  }

  // Not the audio thread: what the session saves (DISTRHO_PLUGIN_WANT_FULL_STATE).
  String getState(const char* key) const override {
    if (String(key) == kStateKeys[kPresetFile]) return String(loader_.file().c_str());
    if (String(key) == kStateKeys[kOverrides]) return String(loader_.overrides().c_str());
    if (String(key) == kStateKeys[kPresetIndex]) {
      const float index = values_[kPreset].load();  // a host's NaN or 99: the parameter alone
      return bundledIndex(index) ? String(static_cast<int>(std::lround(index))) : String();
    }
    return String();
  }

  // A number that rounds to a bundled preset's index.
  static bool bundledIndex(double index) {
    return index > -0.5 && index < static_cast<double>(bundledPresets().size()) - 0.5;
  }

  void activate() override {
    playing_.prepare(getSampleRate());
    loader_.start(getSampleRate());
  }

  void deactivate() override {
    playing_.release();
    loader_.stop();
  }

  // A host may cancel its audio thread — JACK2's jack_client_close does, asynchronously, when a
  // process call is slow to return (jalv quitting under load) — and that cancellation's unwinding
  // cannot cross the engine's noexcept frames: std::terminate (jalv aborted 4 times of 4). So it
  // waits while the synthesizer renders and acts, if one came, where run() enables it again: a
  // frame it may unwind through. Setting the state is a flag in the thread's own data.
  void run(const float**, float** outputs, uint32_t frames, const MidiEvent* midiEvents,
           uint32_t midiEventCount) override {
    int cancellation = PTHREAD_CANCEL_ENABLE;
    ::pthread_setcancelstate(PTHREAD_CANCEL_DISABLE, &cancellation);
    const auto value = [this](unsigned i) { return values_[i].load(std::memory_order_relaxed); };
    playing_.setControls(
        {.gainDb = value(kGainDb),
         .velocityCurve = value(kVelocityCurve),
         .damperScale = value(kDamperScale),
         .polyphony = static_cast<int>(std::lround(kPolyphonyRange.held(value(kPolyphony)))),
         .lightTails = value(kLightTails) >= 0.5f});  // NaN: off
    playing_.process(std::span(outputs[0], frames), std::span(outputs[1], frames),
                     std::span(midiEvents, midiEventCount));
    ::pthread_setcancelstate(cancellation, nullptr);
  }

 private:
  // What each parameter is; the preset's maximum and every enumeration are added by describe().
  struct Description {
    uint32_t hints;
    const char *name, *symbol, *unit;
    Range range;
    const char* description;
  };
  static constexpr uint32_t kKnob = kParameterIsAutomatable;
  static constexpr Description kDescriptions[kParameterCount] = {
      {kKnob | kParameterIsInteger,
       "Preset",
       "preset",
       "",
       {0.0f, 0.0f, 0.0f},
       "The bundled instrument (the preset_file state, when set, plays instead)."},
      {kKnob, "Gain", "gain", "dB", range(kGainDbRange),
       "Output level, after the instrument's own limiter."},
      {kKnob | kParameterIsLogarithmic, "Velocity curve", "velocity_curve", "",
       range(kVelocityCurveRange),
       "Key velocity v becomes 127 (v/127)^curve: above 1 the keyboard plays softer (harder to "
       "reach forte), below 1 louder."},
      {kKnob | kParameterIsLogarithmic, "Damper decay", "damper", "", range(kDamperScaleRange),
       "How long a released key rings, as a multiple of the preset's damper decay time (T60), "
       "for the keys released after it changes."},
      {kKnob | kParameterIsInteger, "Polyphony", "polyphony", "", range(kPolyphonyRange),
       "Keys sounding at once (each costs CPU); 0: the preset's own."},
      {kParameterIsOutput | kParameterIsInteger,
       "Status",
       "status",
       "",
       {0.0f, 0.0f, 2.0f},
       "0 loading, 1 ready, 2 the preset or overrides were refused (the reason is on stderr; the "
       "instrument before plays on, or with none before, a bundled one)."},
      {kKnob | kParameterIsBoolean | kParameterIsInteger,
       "Light tails",
       "light_tails",
       "",
       {0.0f, 0.0f, 1.0f},
       "On: decaying strings go linear once their tension modulation is under 1e-3, not the "
       "preset's 5e-5 (pitch moved by under a cent), for about a quarter less CPU in a dense "
       "pedalled passage; an export sounds as the playback does."},
  };

  // An enumeration of `labels`, valued 0, 1, …
  static void enumerate(Parameter& p, std::span<const char* const> labels, bool restricted) {
    p.enumValues.count = static_cast<uint8_t>(labels.size());
    p.enumValues.restrictedMode = restricted;
    p.enumValues.values = new ParameterEnumerationValue[labels.size()];
    for (size_t i = 0; i < labels.size(); ++i)
      p.enumValues.values[i] = {static_cast<float>(i), labels[i]};
  }

  static void describe(uint32_t index, Parameter& p) {
    const Description& d = kDescriptions[index];
    p.hints = d.hints;
    p.name = d.name;
    p.symbol = d.symbol;
    p.unit = d.unit;
    p.description = d.description;
    p.ranges = {d.range.def, d.range.min, d.range.max};
    if (index == kPreset) {
      const auto presets = bundledPresets();
      std::vector<const char*> names;
      for (const BundledPreset& preset : presets) names.push_back(preset.name);
      p.ranges.max = static_cast<float>(presets.size() - 1);
      enumerate(p, names, true);
    } else if (index == kPolyphony) {
      static constexpr const char* kPresets[] = {"preset's"};
      enumerate(p, kPresets, false);
    } else if (index == kStatus) {
      static constexpr const char* kStatuses[] = {"loading", "ready", "failed"};
      enumerate(p, kStatuses, true);
    }
  }

  SynthLoader loader_;
  PlayingSynth playing_{loader_};
  std::atomic<float> values_[kParameterCount];
};

}  // namespace

Plugin* createPlugin() { return new HamiltonePlugin(); }

END_NAMESPACE_DISTRHO
