// Renders a performance — MIDI messages at times in seconds — through the synthesizer into a
// WAV file, block by block, with events at their exact samples.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "midi/midi_message.h"
#include "synth/synth.h"
#include "wav_writer.h"

namespace hamiltone::cli {

struct RenderStats {
  double seconds = 0.0;       // of audio written
  double wallSeconds = 0.0;   // taken
  int guardEvents = 0;        // voices the guard silenced
  long nonFinite = 0;         // samples the master replaced
  float peak = 0.0f;          // largest |sample| written
  long steals = 0;            // keys the voice limit took (Synth::steals)
  double loudestSteal = 0.0;  // the loudest of them under its own peak (Synth::loudestSteal)
  // The master's limiter (Synth::limiter): frames it reduced, frames over its ceiling, its
  // deepest gain reduction, and the largest |sample| that entered it.
  long limitedFrames = 0, overFrames = 0;
  double limiterDeepestDb = 0.0, peakBeforeLimiter = 0.0;
};

// What an unstable render did and why it is refused: per instrument (by its preset file), the
// notes whose voices the guard silenced, the guard's bound and the scheme's parameters that set
// the step and grid — the ones to change — and the non-finite samples the master zeroed.
std::string instabilityReport(const Synth& synth, const RenderStats& stats);

// Renders `seconds` of audio: messages (sorted by time) applied at round(t · rate), in blocks of
// `block` frames. `progress` is called after each block with the seconds rendered so far.
RenderStats renderPerformance(Synth& synth, const std::vector<TimedMessage>& messages,
                              double seconds, int block, double sampleRate, WavWriter& out,
                              const std::function<void(double)>& progress);

}  // namespace hamiltone::cli
