// A plate instrument from a preset: the plate, its scheme, loss, strike and pickups, and which
// preset parameter each PlateVoice field comes from.
#include "presets/plate_builder.h"

#include <exception>
#include <set>

#include "voices/plate_voice.h"

namespace hamiltone {

namespace {

constexpr VoiceField kPlateFields[] = {
    {"oversampling", "scheme.oversampling"},
    {"strike_position", "strike.position_x"},
    {"strike_position_high", "strike.position_x_high"},
    {"pickup_position", "pickups.left_x"},
    {"strike_width_m", "strike.width_m"},
    {"force_max_n", "strike.force_max_N"},
    {"duration_max_s", "strike.duration_max_s"},
    {"velocity_curve", "strike.velocity_curve"},
    {"damper_t60_s", "loss.damper_t60_s"},
    {"gain", "pickups.gain"},
    {"guard_energy_multiple", "scheme.guard_energy_multiple"},
    {"t60_low_s", "loss.t60_low_s"},
    {"t60_high_s", "loss.t60_high_s"},
    {"t60_high_hz", "loss.t60_high_Hz"},
    {"grid points per side", "plate.lx_m", true},
    {"plate side", "plate.lx_m", true},
    {"grid factor", "scheme.grid_factor"},
    {"young", "plate.young_Pa"},
    {"density", "plate.density_kg_m3"},
    {"thickness", "plate.thickness_m"},
    {"lx", "plate.lx_m"},
    {"ly", "plate.ly_m"},
    {"poisson", "plate.poisson"},
};

}  // namespace

void buildPlatePatch(const PresetValues& values, Instrument& instrument) {
  PlatePatch& p = instrument.plate;
  auto number = [&](std::string_view name) { return values.number(name); };
  p.plate = {.young = number("plate.young_Pa"),
             .density = number("plate.density_kg_m3"),
             .poisson = number("plate.poisson"),
             .thickness = number("plate.thickness_m"),
             .lx = number("plate.lx_m"),
             .ly = number("plate.ly_m")};
  p.referenceNote = static_cast<int>(number("plate.reference_note"));
  p.lowestNote = instrument.lowestNote;
  p.highestNote = instrument.highestNote;
  p.gridFactor = number("scheme.grid_factor");
  p.oversampling = static_cast<int>(number("scheme.oversampling"));
  p.t60Low = number("loss.t60_low_s");
  p.t60High = number("loss.t60_high_s");
  p.t60HighHz = number("loss.t60_high_Hz");
  p.damperT60 = number("loss.damper_t60_s");
  p.strike[0] = number("strike.position_x");
  p.strike[1] = number("strike.position_y");
  p.strikeWidth = number("strike.width_m");
  p.forceMax = number("strike.force_max_N");
  p.durationMin = number("strike.duration_min_s");
  p.durationMax = number("strike.duration_max_s");
  p.velocityCurve = number("strike.velocity_curve");
  p.noteMovesStrike = number("strike.note_moves_strike") != 0.0;
  p.strikeHigh[0] = number("strike.position_x_high");
  p.strikeHigh[1] = number("strike.position_y_high");
  p.pickups[0][0] = number("pickups.left_x");
  p.pickups[0][1] = number("pickups.left_y");
  p.pickups[1][0] = number("pickups.right_x");
  p.pickups[1][1] = number("pickups.right_y");
  p.signal = values.word("pickups.signal") == "velocity" ? PickupSignal::velocity
                                                         : PickupSignal::displacement;
  p.gain = number("pickups.gain");
  p.guardEnergyMultiple = number("scheme.guard_energy_multiple");
}

void checkPlateVoices(const Instrument& instrument,
                      const std::function<void(std::string_view message, int note)>& refused,
                      double rate) {
  const int lo = instrument.lowestNote, hi = instrument.highestNote;
  std::set<int> notes{lo, hi};
  const int reference = instrument.plate.referenceNote;
  if (reference >= lo && reference <= hi) notes.insert(reference);
  for (int note : notes) try {
      PlateVoice voice;
      voice.prepare(instrument.plate, note, rate);
    } catch (const std::exception& e) {
      refused(e.what(), note);
    }
}

std::span<const VoiceField> plateVoiceFields() { return kPlateFields; }

}  // namespace hamiltone
