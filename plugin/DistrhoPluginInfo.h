// What DPF builds: an instrument with MIDI in and stereo out, no UI (hosts show the parameters),
// real-time safe, no latency, with state (the preset file and the overrides, plugin_parameters.h).
// DPF reads this file by this name.
#pragma once

#define DISTRHO_PLUGIN_NAME "Hamiltone"
#define DISTRHO_PLUGIN_URI "urn:hamiltone:hamiltone"
#define DISTRHO_PLUGIN_CLAP_ID "hamiltone.synth"

#define DISTRHO_PLUGIN_NUM_INPUTS 0
#define DISTRHO_PLUGIN_NUM_OUTPUTS 2
#define DISTRHO_PLUGIN_HAS_UI 0
#define DISTRHO_PLUGIN_IS_RT_SAFE 1
#define DISTRHO_PLUGIN_IS_SYNTH 1
#define DISTRHO_PLUGIN_WANT_LATENCY 0
#define DISTRHO_PLUGIN_WANT_STATE 1
#define DISTRHO_PLUGIN_WANT_FULL_STATE 1

#define DISTRHO_PLUGIN_LV2_CATEGORY "lv2:InstrumentPlugin"
#define DISTRHO_PLUGIN_VST3_CATEGORIES "Instrument|Synth|Stereo"
#define DISTRHO_PLUGIN_CLAP_FEATURES "instrument", "synthesizer", "stereo"
