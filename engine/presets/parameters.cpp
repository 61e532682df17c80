// The rows of the preset parameter table, the lookups the loader uses, its printed form, and
// MIDI note names.
#include "presets/parameters.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "util/format_number.h"

namespace hamiltone {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

using enum ParameterType;
constexpr ParameterModel kString = ParameterModel::string;
constexpr ParameterModel kPlate = ParameterModel::plate;
constexpr DefaultKind kRequired = DefaultKind::required;
constexpr DefaultKind kDerived = DefaultKind::derived;

// Defaults are the voices' own (StringPatch, PlatePatch and the physics they hold): the string
// of BDZ §4.2 (C3 of RT-425) struck by the RT-425 hammer of C3, and the steel plate of BDZ §4.3.
// A row's section is the part of its name before the dot; rows print in this order.
constexpr Parameter kTable[] = {
    {.name = "name",
     .type = text,
     .defaultText = "file name",
     .defaultKind = kDerived,
     .doc = "Shown to the player; by default the file's name without .toml."},
    {.name = "model",
     .type = choice,
     .choices = "string|plate",
     .defaultKind = kRequired,
     .doc = "string: a struck string per key, with its unisons; plate: a struck plate sized to "
            "each note."},
    {.name = "lowest_note",
     .type = note,
     .min = 0,
     .max = 127,
     .defaultKind = kRequired,
     .doc = "The lowest key that sounds; notes outside lowest … highest are ignored."},
    {.name = "highest_note",
     .type = note,
     .min = 0,
     .max = 127,
     .minOf = "lowest_note",
     .defaultKind = kRequired,
     .doc = "The highest key that sounds."},
    {.name = "polyphony",
     .type = integer,
     .min = 1,
     .max = 128,
     .defaultText = "64",
     .doc = "Keys sounding at once; beyond, the key furthest below its own peak fades."},
    {.name = "gain_dB",
     .unit = "dB",
     .min = -60,
     .max = 24,
     .defaultText = "0",
     .doc = "Level of the summed voices."},
    {.name = "pan_spread",
     .min = 0,
     .max = 1,
     .defaultText = "0.5",
     .doc = "0: every key centred; 1: the lowest key hard left … the highest hard right."},
    {.name = "bend_range_semitones",
     .unit = "semitones",
     .min = 0,
     .max = 12,
     .defaultText = "2",
     .model = kString,
     .doc = "How far the pitch wheel bends each way (by retensioning); 0 keeps the finest grid."},
    {.name = "a4_Hz",
     .unit = "Hz",
     .min = 400,
     .max = 480,
     .defaultText = "440",
     .model = kString,
     .doc = "Tuning: key n sounds at a4_Hz · 2^((n − 69)/12), on the simulated fundamental."},

    {.name = "string.length_m",
     .unit = "m",
     .min = 0.01,
     .max = 10,
     .defaultText = "1.259",
     .model = kString,
     .perKey = true,
     .doc = "Speaking length L; with tune_by = \"length\", the guess the tuning starts from."},
    {.name = "string.diameter_m",
     .unit = "m",
     .min = 1e-4,
     .max = 0.01,
     .defaultText = "1.062715e-3",
     .model = kString,
     .perKey = true,
     .doc = "Core diameter d: area A = πd²/4 and, with bending stiffness, I = πd⁴/64 (a wound "
            "string's winding adds mass, not stiffness). The default gives BDZ §4.2's A = 8.87e-7 "
            "m²."},
    {.name = "string.linear_density_kg_m",
     .unit = "kg/m",
     .min = 1e-5,
     .max = 1,
     .defaultText = "density × A",
     .defaultKind = kDerived,
     .model = kString,
     .perKey = true,
     .doc = "Mass per length ρA, winding included: a wound string is a plain one of density ρA/A "
            "(docs/instrument-data.md §1.5)."},
    {.name = "string.density_kg_m3",
     .unit = "kg/m^3",
     .min = 500,
     .max = 1e5,
     .defaultText = "7850",
     .model = kString,
     .doc = "Density ρ, used where linear_density_kg_m is not given."},
    {.name = "string.young_Pa",
     .unit = "Pa",
     .min = 1e9,
     .max = 1e12,
     .defaultText = "2.02e11",
     .model = kString,
     .doc = "Young's modulus E of the core; E·A must exceed the tension."},
    {.name = "string.tension_N",
     .unit = "N",
     .min = 1,
     .max = 1e5,
     .defaultText = "759",
     .model = kString,
     .perKey = true,
     .doc = "Tension T0; with tune_by = \"tension\", the guess the tuning starts from."},
    {.name = "string.bending_stiffness",
     .type = boolean,
     .defaultText = "true",
     .model = kString,
     .doc = "false: EI = 0, the paper's string (56), harmonic partials."},
    {.name = "string.tune_by",
     .type = choice,
     .choices = "tension|length",
     .defaultText = "tension",
     .model = kString,
     .doc = "Which of T0 and L is solved so that the simulated fundamental is on the key's note."},
    {.name = "string.unisons",
     .type = integer,
     .min = 1,
     .max = 3,
     .defaultText = "1",
     .model = kString,
     .perKey = true,
     .doc = "Strings per key."},
    {.name = "string.detune_cents",
     .unit = "cents",
     .min = 0,
     .max = 20,
     .defaultText = "0",
     .model = kString,
     .perKey = true,
     .doc = "Spread between the outermost unison strings, which sit at ±detune/2."},

    {.name = "bridge.mass_kg",
     .unit = "kg",
     .min = 0,
     .max = 100,
     .defaultText = "0",
     .model = kString,
     .perKey = true,
     .doc = "Mass of the bridge the key's unison strings end on (the soundboard's driving point, "
            "docs/instrument-data.md §6); 0: rigid ends, each string alone."},
    {.name = "bridge.stiffness_N_m",
     .unit = "N/m",
     .min = 0,
     .max = 1e10,
     .defaultText = "0",
     .model = kString,
     .perKey = true,
     .doc = "The bridge's spring to the rim (with its mass: the driving point's resonance)."},
    {.name = "bridge.resistance_kg_s",
     .unit = "kg/s",
     .min = 0,
     .max = 1e6,
     .defaultText = "0",
     .model = kString,
     .perKey = true,
     .doc = "The bridge's resistance, where the strings' energy leaves for the soundboard: "
            "unisons in phase drain n times faster than alone (the prompt sound)."},
    {.name = "bridge.angle_deg",
     .unit = "degrees",
     .min = 0,
     .max = 10,
     .defaultText = "0",
     .model = kString,
     .perKey = true,
     .doc = "Angle of the speaking length to the board where it crosses the bridge (its share of "
            "the downbearing, docs/instrument-data.md §3.7): the strings' tension change pushes "
            "the bridge by sin(angle) of it, bringing their longitudinal end force — the phantom "
            "partials and longitudinal modes — to the board. 0: the transverse end force alone. "
            "Above 0 it needs bridge.resistance_kg_s > 0."},

    {.name = "body.enabled",
     .type = boolean,
     .defaultText = "false",
     .model = kString,
     .doc = "A soundboard driven by the keys' bridges (bridge.mass_kg > 0), every key's strings "
            "ringing in sympathy on it, heard at its pickups beside the strings' own."},
    {.name = "body.gain",
     .min = -1e6,
     .max = 1e6,
     .defaultText = "1",
     .model = kString,
     .doc = "Output units per m/s of the soundboard at its pickups."},
    {.name = "body.max_mode_Hz",
     .unit = "Hz",
     .min = 50,
     .max = 8000,
     .defaultText = "1000",
     .model = kString,
     .doc = "The soundboard's modes up to here: its cost grows with modes × keys in use "
            "(docs/instrument-data.md §6.4)."},
    {.name = "body.sympathetic_max_Hz",
     .unit = "Hz",
     .min = 50,
     .max = 20000,
     .defaultText = "4500",
     .model = kString,
     .doc = "The sympathetic strings' partials up to here, at most 16 a key; below a quarter of "
            "the sample rate."},

    {.name = "hammer.mass_kg",
     .unit = "kg",
     .min = 1e-4,
     .max = 0.1,
     .defaultText = "9.45e-3",
     .model = kString,
     .perKey = true,
     .doc = "Hammer mass M_H, of the whole hammer: each of n unison strings gets M_H/n."},
    {.name = "hammer.stiffness_N_per_m_p",
     .unit = "N/m^p",
     .min = 1,
     .max = 1e16,
     .defaultText = "1.347e9",
     .model = kString,
     .perKey = true,
     .doc = "Felt stiffness K_H: K_H·η^p at compression η, shared by the unisons (K_H/n each)."},
    {.name = "hammer.exponent",
     .min = 1,
     .max = 6,
     .defaultText = "2.312",
     .model = kString,
     .perKey = true,
     .doc = "Felt exponent p (measured 1.5 … 3.5, docs/instrument-data.md §2.3)."},
    {.name = "hammer.position",
     .min = 0.01,
     .max = 0.99,
     .defaultText = "0.12",
     .model = kString,
     .perKey = true,
     .doc = "Strike point as a fraction x0/L of the length."},
    {.name = "hammer.width_m",
     .unit = "m",
     .min = 0,
     .max = 0.1,
     .defaultText = "0.01",
     .model = kString,
     .doc = "Width of the felt's contact on the string, spread as the felt presses; under "
            "2 min(x0, L - x0) at every key, so that the felt lies on the string."},
    {.name = "hammer.velocity_min_m_s",
     .unit = "m/s",
     .min = 0,
     .max = 20,
     .defaultText = "0.5",
     .model = kString,
     .perKey = true,
     .doc = "Hammer speed at MIDI velocity 0."},
    {.name = "hammer.velocity_max_m_s",
     .unit = "m/s",
     .min = 0,
     .max = 20,
     .minOf = "hammer.velocity_min_m_s",
     .defaultText = "6",
     .model = kString,
     .perKey = true,
     .doc = "Hammer speed at MIDI velocity 127."},
    {.name = "hammer.velocity_curve",
     .min = 0.1,
     .max = 10,
     .defaultText = "1",
     .model = kString,
     .perKey = true,
     .doc = "speed = min + (max − min)·v^curve for v = velocity/127."},

    {.name = "plate.young_Pa",
     .unit = "Pa",
     .min = 1e9,
     .max = 1e12,
     .defaultText = "2e11",
     .model = kPlate,
     .doc = "Young's modulus E."},
    {.name = "plate.density_kg_m3",
     .unit = "kg/m^3",
     .min = 500,
     .max = 30000,
     .defaultText = "7850",
     .model = kPlate,
     .doc = "Density ρ."},
    {.name = "plate.poisson",
     .min = 0,
     .max = 0.49,
     .defaultText = "0.3",
     .model = kPlate,
     .doc = "Poisson's ratio ν."},
    {.name = "plate.thickness_m",
     .unit = "m",
     .min = 1e-4,
     .max = 0.05,
     .defaultText = "2e-3",
     .model = kPlate,
     .doc = "Thickness ξ: a thinner plate needs a finer grid (h ∝ sqrt(ξ)) and costs more."},
    {.name = "plate.lx_m",
     .unit = "m",
     .min = 0.01,
     .max = 5,
     .defaultText = "0.5",
     .model = kPlate,
     .doc = "Side along x at reference_note. The cost grows as the cube of the sides."},
    {.name = "plate.ly_m",
     .unit = "m",
     .min = 0.01,
     .max = 5,
     .defaultText = "0.5",
     .model = kPlate,
     .doc = "Side along y at reference_note."},
    {.name = "plate.reference_note",
     .type = note,
     .min = 0,
     .max = 127,
     .defaultText = "lowest_note",
     .defaultKind = kDerived,
     .model = kPlate,
     .doc = "The note at which the plate is lx × ly; a semitone up shrinks both sides by "
            "2^(−1/24), which raises every mode a semitone."},

    {.name = "strike.position_x",
     .min = 0.01,
     .max = 0.99,
     .defaultText = "0.37",
     .model = kPlate,
     .doc = "Strike point as a fraction of lx."},
    {.name = "strike.position_y",
     .min = 0.01,
     .max = 0.99,
     .defaultText = "0.41",
     .model = kPlate,
     .doc = "Strike point as a fraction of ly."},
    {.name = "strike.note_moves_strike",
     .type = boolean,
     .defaultText = "false",
     .model = kPlate,
     .doc = "true: the plate keeps its size at every note, and the notes move the strike from "
            "position_x/y (lowest note) to position_x/y_high (highest)."},
    {.name = "strike.position_x_high",
     .min = 0.01,
     .max = 0.99,
     .defaultText = "0.5",
     .model = kPlate,
     .doc = "With note_moves_strike: the highest note's strike point, fraction of lx."},
    {.name = "strike.position_y_high",
     .min = 0.01,
     .max = 0.99,
     .defaultText = "0.5",
     .model = kPlate,
     .doc = "With note_moves_strike: the highest note's strike point, fraction of ly."},
    {.name = "strike.width_m",
     .unit = "m",
     .min = 0,
     .max = 0.5,
     .defaultText = "0.02",
     .model = kPlate,
     .doc = "Diameter of the mallet's contact; 0 strikes the nearest grid point."},
    {.name = "strike.force_max_N",
     .unit = "N",
     .min = 0.01,
     .max = 1e5,
     .defaultText = "300",
     .model = kPlate,
     .doc = "Peak of the raised-cosine force pulse at velocity 127."},
    {.name = "strike.duration_min_s",
     .unit = "s",
     .min = 1e-5,
     .max = 0.05,
     .defaultText = "0.5e-3",
     .model = kPlate,
     .doc = "Length of the pulse at velocity 127: a harder strike is shorter and brighter."},
    {.name = "strike.duration_max_s",
     .unit = "s",
     .min = 1e-5,
     .max = 0.05,
     .minOf = "strike.duration_min_s",
     .defaultText = "3e-3",
     .model = kPlate,
     .doc = "Length of the pulse at velocity 0."},
    {.name = "strike.velocity_curve",
     .min = 0.1,
     .max = 10,
     .defaultText = "1.5",
     .model = kPlate,
     .doc = "force = force_max_N · v^curve for v = velocity/127."},

    {.name = "loss.t60_low_s",
     .unit = "s",
     .min = 0.01,
     .max = kInf,
     .defaultText = "20",
     .model = kString,
     .perKey = true,
     .doc = "Decay time (−60 dB) at 0 Hz; inf: no loss. Loss σ0 + σ1ξ fits both T60s."},
    {.name = "loss.t60_high_s",
     .unit = "s",
     .min = 0.01,
     .max = kInf,
     .maxOf = "loss.t60_low_s",
     .defaultText = "4",
     .model = kString,
     .perKey = true,
     .doc = "Decay time at t60_high_Hz; at most t60_low_s."},
    {.name = "loss.t60_high_Hz",
     .unit = "Hz",
     .min = 20,
     .max = 20000,
     .defaultText = "2000",
     .model = kString,
     .doc = "Frequency at which t60_high_s holds."},
    {.name = "loss.longitudinal_t60_low_s",
     .unit = "s",
     .min = 0.01,
     .max = kInf,
     .defaultText = "shared",
     .defaultKind = kDerived,
     .model = kString,
     .doc = "The longitudinal wave's own decay time at 0 Hz; unset, it shares the transverse law "
            "by wavenumber (BDZ (49)), which leaves its modes nearly lossless. Set, its law is "
            "fitted by frequency (σ0 + σ1 ω²ρ/E); the transverse σ0 is shared, so v decays at "
            "least as fast as t60_low_s says. Set alone, longitudinal_t60_high_s takes its "
            "value."},
    {.name = "loss.longitudinal_t60_high_s",
     .unit = "s",
     .min = 0.01,
     .max = kInf,
     .maxOf = "loss.longitudinal_t60_low_s",
     .defaultText = "shared",
     .defaultKind = kDerived,
     .model = kString,
     .doc = "The longitudinal wave's decay time at t60_high_Hz; at most longitudinal_t60_low_s. "
            "Set alone, longitudinal_t60_low_s takes its value."},
    {.name = "loss.damper_t60_s",
     .unit = "s",
     .min = 0.01,
     .max = 1000,
     .defaultText = "0.25",
     .model = kString,
     .perKey = true,
     .doc = "The fundamental's decay time that the damper adds once the key is released (1000: "
            "no damper); with damper.model = felt, other partials by their shape under it."},
    {.name = "damper.model",
     .type = choice,
     .choices = "uniform|felt",
     .defaultText = "uniform",
     .model = kString,
     .doc = "uniform: the damper adds one decay rate to every partial; felt: dashpots under the "
            "felt (damper.position, damper.width_m), each partial damped by its shape there."},
    {.name = "damper.position",
     .min = 0.01,
     .max = 0.99,
     .defaultText = "0.135",
     .model = kString,
     .perKey = true,
     .doc = "Where the damper's felt begins, as a fraction of the length from the agraffe (the "
            "hammer's end, x = 0)."},
    {.name = "damper.width_m",
     .unit = "m",
     .min = 0,
     .max = 0.1,
     .defaultText = "0.02",
     .model = kString,
     .perKey = true,
     .doc = "The felt's length along the string: it damps on every node of the string's grid "
            "under it (at most 8, spread evenly, both ends included)."},
    {.name = "loss.t60_low_s",
     .unit = "s",
     .min = 0.01,
     .max = kInf,
     .defaultText = "8",
     .model = kPlate,
     .doc = "Decay time (−60 dB) at 0 Hz; inf: no loss. Loss σ0 + σ1ξ fits both T60s."},
    {.name = "loss.t60_high_s",
     .unit = "s",
     .min = 0.01,
     .max = kInf,
     .maxOf = "loss.t60_low_s",
     .defaultText = "2",
     .model = kPlate,
     .doc = "Decay time at t60_high_Hz; at most t60_low_s."},
    {.name = "loss.t60_high_Hz",
     .unit = "Hz",
     .min = 20,
     .max = 20000,
     .defaultText = "4000",
     .model = kPlate,
     .doc = "Frequency at which t60_high_s holds."},
    {.name = "loss.damper_t60_s",
     .unit = "s",
     .min = 0.01,
     .max = 1000,
     .defaultText = "1",
     .model = kPlate,
     .doc = "Decay time once the key is released (1000: no damper)."},

    {.name = "pickups.signal",
     .type = choice,
     .choices = "velocity|displacement",
     .defaultText = "velocity",
     .doc = "What the pickups hear; a plate's displacement is DC-blocked at 5 Hz."},
    {.name = "pickups.gain",
     .min = -1e6,
     .max = 1e6,
     .defaultText = "0.25",
     .model = kString,
     .perKey = true,
     .doc = "Output units per m/s of the string (per m for displacement); per key, it levels the "
            "registers (linear between anchors)."},
    {.name = "pickups.gain",
     .min = -1e6,
     .max = 1e6,
     .defaultText = "0.5",
     .model = kPlate,
     .doc = "Output units per m/s of the plate (per m for displacement)."},
    {.name = "pickups.channels",
     .type = integer,
     .min = 1,
     .max = 2,
     .defaultText = "2",
     .model = kString,
     .doc = "1: mono, from left_position; 2: one pickup per channel."},
    {.name = "pickups.left_position",
     .min = 0.01,
     .max = 0.99,
     .defaultText = "0.31",
     .model = kString,
     .doc = "Left pickup as a fraction of the length."},
    {.name = "pickups.right_position",
     .min = 0.01,
     .max = 0.99,
     .defaultText = "0.73",
     .model = kString,
     .doc = "Right pickup as a fraction of the length."},
    {.name = "pickups.left_x",
     .min = 0.01,
     .max = 0.99,
     .defaultText = "0.23",
     .model = kPlate,
     .doc = "Left pickup, fraction of lx."},
    {.name = "pickups.left_y",
     .min = 0.01,
     .max = 0.99,
     .defaultText = "0.31",
     .model = kPlate,
     .doc = "Left pickup, fraction of ly."},
    {.name = "pickups.right_x",
     .min = 0.01,
     .max = 0.99,
     .defaultText = "0.71",
     .model = kPlate,
     .doc = "Right pickup, fraction of lx."},
    {.name = "pickups.right_y",
     .min = 0.01,
     .max = 0.99,
     .defaultText = "0.62",
     .model = kPlate,
     .doc = "Right pickup, fraction of ly."},

    {.name = "scheme.oversampling",
     .type = integer,
     .min = 1,
     .max = 64,
     .choices = "1|2|4|8|16|32|64",
     .defaultText = "1",
     .doc = "Scheme steps per output sample: a finer time step and grid, at that times the cost "
            "or more. 32 and 64 are for converged string references (a short treble string on "
            "the longitudinal grid at 16 has too few segments); a plate takes at most 16."},
    {.name = "scheme.grid_factor",
     .min = 1,
     .max = 100,
     .defaultText = "1",
     .doc = "Grid spacing as a multiple of the finest stable one: above 1 is cheaper and duller. "
            "The transverse grid keeps at least 1.02 of its bound (the bend range's sqrt of its "
            "tension range, 1.12 at 2 semitones, is more): on the bound its top mode rings at the "
            "Nyquist frequency."},
    {.name = "scheme.grid_rule",
     .type = choice,
     .choices = "two-grid|transverse|longitudinal",
     .defaultText = "two-grid",
     .model = kString,
     .doc = "two-grid (to play): u on the finest grid (44) allows at tension_margin·T0, v on a "
            "coarse nested grid with h_v >= 1.05 sqrt(E/ρ)k — geometrically exact at audio rate "
            "(pitch glide, phantom partials) at about 3/4 of the cost of transverse. longitudinal "
            "(the converged reference): h >= sqrt(E/ρ)k, as in the paper's runs; converged at "
            "oversampling 8–16, at a cost growing as its square. transverse (for comparison): u "
            "and v on u's grid; v cannot follow u at audio rate, so a loud note does not glide."},
    {.name = "scheme.tension_margin",
     .min = 1,
     .max = 4,
     .defaultText = "1.5",
     .model = kString,
     .doc = "two-grid: u's grid is sized for this multiple of T0. Stability needs only T0; a "
            "struck string's tension rises above it, and a grid at the T0 bound then glides at "
            "half the rate. A larger margin is coarser and cheaper (fewer high partials)."},
    {.name = "scheme.linear_below",
     .min = 0,
     .max = 1e-3,
     .defaultText = "5e-5",
     .model = kString,
     .doc = "The linear tail: once the hammer is back and the bound from the string's energy H on "
            "its tension modulation's mean over a period (<ΔT>/βT0 <= EA H / (2 β²T0² L), half "
            "of H potential on average, β the bend's tension scale) is under this, the string is "
            "stepped linear — V' dropped for its quadratic part, the "
            "longitudinal wave kept at its speed — in its sine modes, the highest dropped as they "
            "fall under −100 dB of its energy (−80 dB under the player's live tail; a felt damper "
            "on it takes it back to its nodes), at 0.09–0.19 of the cost; a strike makes it "
            "geometric again. The pitch is then off by at most 866 × this cents (5e-5: 0.043 "
            "cents; measured 0.032). 0: never (the research configuration). two-grid "
            "and longitudinal only: on the transverse grid the linear v would not be stable, and "
            "the string stays geometric."},
    {.name = "scheme.epsilon_J",
     .unit = "J",
     .min = 0,
     .max = 1e9,
     .defaultText = "by grid",
     .defaultKind = kDerived,
     .model = kString,
     .doc = "Gauge shift ε of the scalar auxiliary variable (BDZ §2.5). two-grid and "
            "longitudinal: 0.1 × the hardest strike's energy ½ M_H v_max² (any ε > 0 gives the "
            "converged glide; ε = 0 does not, from a displaced start); any value is accepted. "
            "transverse, and two-grid on a string shorter than c_L k (A#6 up at 48 kHz: one "
            "coarse cell that still does not resolve the longitudinal wave): 0, and at most 0.01 "
            "× that energy — a larger ε lets ψ drift and the output turns into noise."},
    {.name = "scheme.guard_energy_multiple",
     .min = 1.01,
     .max = 1e6,
     .defaultText = "4",
     .doc = "A voice whose energy exceeds this multiple of what its strikes put in is silenced."},

    {.name = "key.note",
     .type = note,
     .min = 0,
     .max = 127,
     .defaultKind = kRequired,
     .model = kString,
     .doc = "Opens each [[key]] anchor table: the key at which the per-key parameters that "
            "follow hold, e.g. [[key]] note = \"C3\" string.tension_N = 759 hammer.mass_kg = "
            "9.45e-3. At most 128 anchors, one per note, within lowest … highest."},
};

std::string_view modelText(ParameterModel m) {
  return m == ParameterModel::string ? "string" : m == ParameterModel::plate ? "plate" : "both";
}

std::string_view typeText(ParameterType t) {
  switch (t) {
    case real:
      return "real";
    case integer:
      return "integer";
    case choice:
      return "choice";
    case boolean:
      return "boolean";
    case note:
      return "note";
    case text:
      return "text";
  }
  return "";
}

std::string bound(double value, std::string_view of) {
  if (!of.empty()) return std::string(of.substr(of.find('.') + 1));
  return compactNumber(value);
}

std::string rangeText(const Parameter& p) {
  if (!p.choices.empty()) return std::string(p.choices);
  switch (p.type) {
    case boolean:
      return "true|false";
    case text:
      return "";
    default:
      return bound(p.min, p.minOf) + " … " + bound(p.max, p.maxOf);
  }
}

// Columns as display characters: '…', 'π' and the like are one column, several bytes.
size_t columns(std::string_view s) {
  return static_cast<size_t>(std::count_if(
      s.begin(), s.end(), [](char c) { return (static_cast<unsigned char>(c) & 0xC0) != 0x80; }));
}

// Appends a cell and pads the line to column `at` + `width`, where the cell should end; `at` moves
// on to there. A cell that leaves no space before that column ends its line: the row's next cells
// go on a line of their own, each under its heading.
void cell(std::string& out, std::string_view s, size_t width, size_t& at) {
  const size_t used = columns(out.substr(out.rfind('\n') + 1)) + columns(s);
  at += width;
  out += s;
  if (at > used) {
    out.append(at - used, ' ');
  } else {
    out += '\n';
    out.append(at, ' ');
  }
}

// Appends `words` wrapped to 100 columns, each line indented by `indent` spaces.
void wrap(std::string& out, std::string_view words, size_t indent) {
  size_t used = 0;
  while (!words.empty()) {
    const size_t end = words.find(' ');
    const std::string_view word = words.substr(0, end);
    if (used > 0 && used + 1 + columns(word) > 100) {
      out += '\n';
      used = 0;
    }
    if (used == 0) {
      out.append(indent, ' ');
      used = indent;
    } else {
      out += ' ';
      ++used;
    }
    out += word;
    used += columns(word);
    words = end == std::string_view::npos ? std::string_view() : words.substr(end + 1);
  }
  out += '\n';
}

}  // namespace

std::span<const Parameter> parameters() { return kTable; }

std::string_view sectionOf(std::string_view name) {
  const size_t dot = name.find('.');
  return dot == std::string_view::npos ? std::string_view() : name.substr(0, dot);
}

bool appliesTo(const Parameter& p, InstrumentModel model) {
  return p.model == ParameterModel::both ||
         (p.model == ParameterModel::string) == (model == InstrumentModel::string);
}

const Parameter* findParameter(std::string_view name, InstrumentModel model) {
  for (const Parameter& p : kTable)
    if (p.name == name && appliesTo(p, model)) return &p;
  return nullptr;
}

const Parameter* findParameter(std::string_view name) {
  for (const Parameter& p : kTable)
    if (p.name == name) return &p;
  return nullptr;
}

double defaultNumber(const Parameter& p) {
  if (p.defaultKind != DefaultKind::value || p.type == choice || p.type == text)
    throw std::logic_error(std::string(p.name) + " has no numeric default");
  if (p.type == boolean) return p.defaultText == "true" ? 1.0 : 0.0;
  if (p.defaultText == "inf") return kInf;
  double value = 0.0;
  const char* end = p.defaultText.data() + p.defaultText.size();
  if (std::from_chars(p.defaultText.data(), end, value).ptr != end)
    throw std::logic_error(std::string(p.name) + ": default is not a number");
  return value;
}

std::string compactNumber(double x) {
  const std::string text = formatNumber(x);
  const size_t e = text.find('e');
  if (e == std::string::npos) return text;
  size_t digits = e + 1;
  const bool negative = text[digits] == '-';
  if (text[digits] == '-' || text[digits] == '+') ++digits;
  while (digits + 1 < text.size() && text[digits] == '0') ++digits;
  return text.substr(0, e + 1) + (negative ? "-" : "") + text.substr(digits);
}

std::string parameterTable() {
  constexpr size_t kName = 29, kType = 8, kUnit = 10, kRange = 22, kDefault = 13;
  std::string out;
  wrap(out,
       "Preset parameters (TOML). Keys with a dot belong to a [section]: string.tension_N is "
       "tension_N in [string]. Per-key parameters of a string instrument may also be set in "
       "[[key]] anchor tables, each with note = \"C3\" (or a MIDI number); between anchors a "
       "key's value is interpolated geometrically in the note number (linearly when the range "
       "includes 0; an integer holds from its anchor up), and beyond the outer anchors the "
       "nearest one's value holds. Notes are MIDI numbers or names: \"A0\" = 21, \"C4\" = 60, "
       "\"C#4\" = \"Db4\" = 61.",
       0);
  std::string_view section = "-";
  for (const Parameter& p : kTable) {
    if (sectionOf(p.name) != section) {
      section = sectionOf(p.name);
      out += section.empty()    ? "\n[top level]\n"
             : section == "key" ? "\n[[key]] anchor tables\n"
                                : "\n[" + std::string(section) + "]\n";
      size_t at = 0;
      cell(out, "  name", kName + 2, at);
      cell(out, "type", kType, at);
      cell(out, "unit", kUnit, at);
      cell(out, "range", kRange, at);
      cell(out, "default", kDefault, at);
      out += "model\n";
    }
    const std::string defaultText =
        p.defaultKind == DefaultKind::required ? "required" : std::string(p.defaultText);
    out += "  ";
    size_t at = 2;
    cell(out, p.name, kName, at);
    cell(out, typeText(p.type), kType, at);
    cell(out, p.unit.empty() ? "-" : p.unit, kUnit, at);
    cell(out, rangeText(p), kRange, at);
    cell(out, defaultText, kDefault, at);
    out += modelText(p.model);
    if (p.perKey) out += ", per key";
    out += '\n';
    wrap(out, p.doc, 6);
  }
  return out;
}

std::optional<int> parseNoteName(std::string_view name) {
  static constexpr int kPitch[] = {9, 11, 0, 2, 4, 5, 7};  // A B C D E F G
  if (name.size() < 2 || name.size() > 4) return std::nullopt;
  const char letter = static_cast<char>(name[0] | 0x20);  // lower case
  if (letter < 'a' || letter > 'g') return std::nullopt;
  int pitch = kPitch[letter - 'a'];
  size_t i = 1;
  if (name[i] == '#' || name[i] == 'b') pitch += name[i++] == '#' ? 1 : -1;
  int octave = 0;
  const char* end = name.data() + name.size();
  const auto [ptr, error] = std::from_chars(name.data() + i, end, octave);
  if (error != std::errc() || ptr != end || octave < -1 || octave > 9) return std::nullopt;
  const int midi = 12 * (octave + 1) + pitch;
  if (midi < 0 || midi > 127) return std::nullopt;
  return midi;
}

std::string noteName(int midiNote) {
  static constexpr const char* kNames[] = {"C",  "C#", "D",  "D#", "E",  "F",
                                           "F#", "G",  "G#", "A",  "A#", "B"};
  const int pitch = ((midiNote % 12) + 12) % 12;
  return kNames[pitch] + std::to_string((midiNote - pitch) / 12 - 1);
}

}  // namespace hamiltone
