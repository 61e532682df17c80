// A string instrument from a preset: the patch every key shares, each key's string, hammer and
// loss between the anchors, and which preset parameter each StringVoice field comes from.
#include "presets/string_builder.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <numbers>
#include <set>
#include <stdexcept>
#include <string>

#include "instruments/piano_scale.h"
#include "synth/instrument_body.h"
#include "util/format_number.h"
#include "voices/string_voice.h"

namespace hamiltone {

namespace {

constexpr VoiceField kStringFields[] = {
    {"oversampling", "scheme.oversampling"},
    {"a4_hz", "a4_Hz"},
    {"damper_t60_s", "loss.damper_t60_s"},
    {"damper_position", "damper.position"},
    {"damper_width_m", "damper.width_m"},
    {"pickup_position", "pickups.left_position"},
    {"channels", "pickups.channels"},
    {"gain", "pickups.gain"},
    {"hammer_velocity_max_m_s", "hammer.velocity_max_m_s"},
    {"velocity_curve", "hammer.velocity_curve"},
    {"guard_energy_multiple", "scheme.guard_energy_multiple"},
    {"epsilon_j", "scheme.epsilon_J"},
    {"tension_margin", "scheme.tension_margin"},
    {"linear_below", "scheme.linear_below"},
    {"bend_range_semitones", "bend_range_semitones"},
    {"tension scale range", "bend_range_semitones", true},
    {"t60_low_s", "loss.t60_low_s"},
    {"t60_high_s", "loss.t60_high_s"},
    {"t60_high_hz", "loss.t60_high_Hz"},
    {"longitudinal_t60_low_s", "loss.longitudinal_t60_low_s"},
    {"longitudinal_t60_high_s", "loss.longitudinal_t60_high_s"},
    {"tension", "string.tension_N"},
    {"length", "string.length_m"},
    {"young", "string.young_Pa"},
    {"grid factor", "scheme.grid_factor"},
    {"hammer mass", "hammer.mass_kg"},
    {"bridge_mass_kg", "bridge.mass_kg"},
    {"body.enabled", "body.enabled"},
    {"soundboard maxModeHz", "body.max_mode_Hz"},
    {"sympathetic maxHz", "body.sympathetic_max_Hz"},
    {"bridge_stiffness_N_m", "bridge.stiffness_N_m"},
    {"bridge_resistance_kg_s", "bridge.resistance_kg_s"},
    {"bridge_angle_deg", "bridge.angle_deg"},
    {"hammer stiffness", "hammer.stiffness_N_per_m_p"},
    {"hammer exponent", "hammer.exponent"},
    {"hammer position", "hammer.position"},
    {"hammer width", "hammer.width_m"},
};

// A key's strings are tuned through their detune, within ±kMaxDetuneCents (StringVoice): their
// spread, ±detune/2, and what the bridge's load pulls them (bridgeLoadCents) must fit in it.
// The least bridge mass, from `key`'s (or a milligram) upwards in steps of 5 % up to 1000 kg,
// whose load the tuning takes out at `hz`; 0 when none does.
double massThatTunes(StringKey key, double hz) {
  const double room = kMaxDetuneCents - std::abs(key.detuneCents) / 2.0;
  for (key.bridge.mass = std::max(key.bridge.mass, 1e-6); key.bridge.mass < 1e3;
       key.bridge.mass *= 1.05) {
    const double cents = bridgeLoadCents(key, hz);
    if (std::isfinite(cents) && std::abs(cents) <= room) return key.bridge.mass;
  }
  return 0.0;
}

// The bridge's fields, for a message.
std::string bridgeFields(const BridgePhysics& b) {
  return "bridge.mass_kg = " + formatApprox(b.mass) +
         ", bridge.stiffness_N_m = " + formatApprox(b.stiffness) +
         ", bridge.resistance_kg_s = " + formatApprox(b.resistance);
}

}  // namespace

void buildStringKeys(const PresetValues& values, Instrument& instrument) {
  auto number = [&](std::string_view name) { return values.number(name); };
  auto word = [&](std::string_view name) { return values.word(name); };
  instrument.bendRange = number("bend_range_semitones");
  StringPatch common;
  common.tuneBy = word("string.tune_by") == "tension" ? TuneBy::tension : TuneBy::length;
  common.feltDamper = word("damper.model") == "felt";
  common.a4Hz = number("a4_Hz");
  const std::string rule = word("scheme.grid_rule");
  common.grid = rule == "two-grid"     ? GridRule::twoGrid
                : rule == "transverse" ? GridRule::transverse
                                       : GridRule::longitudinal;
  common.gridFactor = number("scheme.grid_factor");
  common.tensionMargin = number("scheme.tension_margin");
  common.linearBelow = number("scheme.linear_below");
  common.oversampling = static_cast<int>(number("scheme.oversampling"));
  if (values.setting("scheme.epsilon_J")) common.epsilon = number("scheme.epsilon_J");
  common.t60HighHz = number("loss.t60_high_Hz");
  if (values.setting("loss.longitudinal_t60_low_s"))
    common.longitudinalT60Low = number("loss.longitudinal_t60_low_s");
  if (values.setting("loss.longitudinal_t60_high_s"))
    common.longitudinalT60High = number("loss.longitudinal_t60_high_s");
  common.pickups[0] = number("pickups.left_position");
  common.pickups[1] = number("pickups.right_position");
  common.channels = static_cast<int>(number("pickups.channels"));
  common.signal =
      word("pickups.signal") == "velocity" ? PickupSignal::velocity : PickupSignal::displacement;
  common.gain = number("pickups.gain");
  common.velocityMin = number("hammer.velocity_min_m_s");
  common.velocityMax = number("hammer.velocity_max_m_s");
  common.velocityCurve = number("hammer.velocity_curve");
  common.guardEnergyMultiple = number("scheme.guard_energy_multiple");
  common.bendRange = instrument.bendRange;
  common.hammer.width = number("hammer.width_m");
  common.string.young = number("string.young_Pa");
  const bool stiff = number("string.bending_stiffness") != 0.0;
  instrument.body = {.enabled = number("body.enabled") != 0.0,
                     .gain = number("body.gain"),
                     .maxModeHz = number("body.max_mode_Hz"),
                     .sympatheticMaxHz = number("body.sympathetic_max_Hz")};
  const Parameter& linearDensity = values.row("string.linear_density_kg_m");
  const bool densityGiven = values.setting(linearDensity.name) || values.anchored(linearDensity);

  for (int note = instrument.lowestNote; note <= instrument.highestNote; ++note) {
    auto at = [&](std::string_view name) { return values.atKey(values.row(name), note); };
    StringKey key{.patch = common, .unisons = 1, .detuneCents = 0.0, .bridge = {}};
    StringPatch& p = key.patch;
    const double d = at("string.diameter_m");
    p.string.area = std::numbers::pi * d * d / 4.0;
    p.string.density =
        densityGiven ? at(linearDensity.name) / p.string.area : number("string.density_kg_m3");
    p.string.length = at("string.length_m");
    p.string.tension = at("string.tension_N");
    p.string.inertia = stiff ? std::numbers::pi * std::pow(d, 4) / 64.0 : 0.0;
    p.hammer.mass = at("hammer.mass_kg");
    p.hammer.stiffness = at("hammer.stiffness_N_per_m_p");
    p.hammer.exponent = at("hammer.exponent");
    p.hammer.position = at("hammer.position");
    p.t60Low = at("loss.t60_low_s");
    p.t60High = at("loss.t60_high_s");
    p.damperT60 = at("loss.damper_t60_s");
    p.damperPosition = at("damper.position");
    p.damperWidth = at("damper.width_m");
    p.gain = at("pickups.gain");
    p.velocityMin = at("hammer.velocity_min_m_s");
    p.velocityMax = at("hammer.velocity_max_m_s");
    p.velocityCurve = at("hammer.velocity_curve");
    key.unisons = static_cast<int>(at("string.unisons"));
    key.detuneCents = at("string.detune_cents");
    key.bridge = {.mass = at("bridge.mass_kg"),
                  .stiffness = at("bridge.stiffness_N_m"),
                  .resistance = at("bridge.resistance_kg_s"),
                  .angle = at("bridge.angle_deg") * std::numbers::pi / 180.0};
    instrument.keys.push_back(key);
  }
}

void checkStringVoices(const Instrument& instrument, const PresetValues& values,
                       const std::function<void(std::string_view message, int note)>& refused,
                       double rate) {
  const int lo = instrument.lowestNote, hi = instrument.highestNote;
  std::set<int> notes{lo, hi};
  for (int note = lo; note <= hi; note += 12) notes.insert(note);
  for (const Anchor& a : values.anchors)
    if (a.note >= lo && a.note <= hi) notes.insert(a.note);  // a --set may narrow the range
  // The patches the synthesizer plays: the outermost unison strings carry the detune extremes.
  for (int note : notes) try {
      const StringKey& key = instrument.keys[note - lo];
      // A bridge so light (or soft) that its load detunes the strings beyond what the tuning
      // takes out is the bridge's fault, not the detune's the voice would name.
      const double hz = equalTemperament(note, key.patch.a4Hz);
      const double load = bridgeLoadCents(key, hz);
      if (!std::isfinite(load) ||
          std::abs(load) + std::abs(key.detuneCents) / 2.0 > kMaxDetuneCents) {
        const double mass = massThatTunes(key, hz);
        throw std::invalid_argument(
            bridgeFields(key.bridge) + ": the bridge's load moves the strings' pitch by " +
            (std::isfinite(load) ? formatApprox(load) + " cents"
                                 : std::string("more than an octave")) +
            ", more than the tuning takes out (" + formatApprox(kMaxDetuneCents) +
            " cents, less half the unisons' detune); expected a heavier bridge" +
            (mass > 0.0 ? " (bridge.mass_kg >= " + formatApprox(mass) + " with these)" : "") +
            ", a stiffer one or more resistance");
      }
      double added = 0.0;  // the outermost strings' K_s, the middle one's taken as theirs
      for (int string : {0, key.unisons - 1}) {
        StringVoice voice;
        voice.prepare(unisonPatch(instrument, note, string), note, rate);
        added += voice.coupling().selfStiffness() * key.unisons / 2.0;
      }
      if (key.bridge.mass > 0.0) {
        const double k = 1.0 / (rate * key.patch.oversampling);
        Bridge().prepare(key.bridge, k, added * std::pow(2.0, 2.0 * instrument.bendRange / 12.0));
      }
    } catch (const std::exception& e) {
      refused(e.what(), note);
    }
  if (instrument.body.enabled) try {
      PianoBody body;
      prepareBody(body, instrument, rate);
    } catch (const std::exception& e) {
      refused(e.what(), lo);
    }
}

std::span<const VoiceField> stringVoiceFields() { return kStringFields; }

}  // namespace hamiltone
