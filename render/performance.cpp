// The render loop: the block's events with their sample offsets, the synthesizer, interleaving,
// the WAV writer, and the tallies the summary reports.
#include "performance.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "presets/parameters.h"
#include "util/format_number.h"

namespace hamiltone::cli {

std::string instabilityReport(const Synth& synth, const RenderStats& stats) {
  std::string report = "the preset is unstable for the notes played: the guard silenced " +
                       std::to_string(stats.guardEvents) + " voice(s) and " +
                       std::to_string(stats.nonFinite) +
                       " non-finite sample(s) were zeroed; no file written";
  const std::vector<Instrument>& instruments = synth.instruments();
  for (int program = 0; program < static_cast<int>(instruments.size()); ++program) {
    const Instrument& instrument = instruments[program];
    std::string notes;
    int first = -1;
    for (int note = instrument.lowestNote; note <= instrument.highestNote; ++note) {
      const KeyVoice* voice = synth.voice(program, note);
      if (!voice || voice->guardEvents() == 0) continue;
      if (!notes.empty()) notes += ' ';
      notes += noteName(note);
      if (first < 0) first = note;
    }
    if (first < 0) continue;
    // The scheme's settings of the first of those notes (a [[key]] table may vary them).
    std::string scheme;
    double guard = 0.0;
    if (instrument.model == InstrumentModel::string) {
      const StringPatch patch = unisonPatch(instrument, first, 0);
      guard = patch.guardEnergyMultiple;
      scheme = "scheme.oversampling = " + std::to_string(patch.oversampling) +
               ", scheme.grid_factor = " + formatNumber(patch.gridFactor) +
               ", scheme.grid_rule = " + gridRuleName(patch.grid) + ", scheme.epsilon_J = " +
               (patch.epsilon ? formatNumber(*patch.epsilon) : "its default for the grid");
    } else {
      guard = instrument.plate.guardEnergyMultiple;
      scheme = "scheme.oversampling = " + std::to_string(instrument.plate.oversampling) +
               ", scheme.grid_factor = " + formatNumber(instrument.plate.gridFactor);
    }
    report += "\n  ";
    report += instrument.source;
    report += " (program " + std::to_string(program) + "): " + notes;
    report += ": energy beyond scheme.guard_energy_multiple = " + formatNumber(guard);
    report += " times what the strikes put in, with " + scheme;
  }
  return report;
}

RenderStats renderPerformance(Synth& synth, const std::vector<TimedMessage>& messages,
                              double seconds, int block, double sampleRate, WavWriter& out,
                              const std::function<void(double)>& progress) {
  const auto start = std::chrono::steady_clock::now();
  const long frames = std::lround(seconds * sampleRate);
  std::vector<float> left(block), right(block), interleaved(2 * static_cast<size_t>(block));
  std::vector<SynthEvent> events;
  RenderStats stats;
  size_t next = 0;
  for (long done = 0; done < frames; done += block) {
    const long n = std::min<long>(block, frames - done);
    events.clear();
    while (next < messages.size()) {
      const long at = std::lround(messages[next].seconds * sampleRate);
      if (at >= done + n) break;
      events.push_back({static_cast<int>(std::max(at - done, 0L)), messages[next].message});
      ++next;
    }
    synth.process(std::span(left).first(n), std::span(right).first(n), events);
    for (long i = 0; i < n; ++i) {
      interleaved[2 * i] = left[i];
      interleaved[2 * i + 1] = right[i];
      stats.peak = std::max({stats.peak, std::abs(left[i]), std::abs(right[i])});
    }
    out.write(interleaved.data(), static_cast<size_t>(n));
    progress(static_cast<double>(done + n) / sampleRate);
  }
  stats.seconds = static_cast<double>(frames) / sampleRate;
  stats.wallSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  stats.guardEvents = synth.guardEvents();
  stats.nonFinite = synth.nonFiniteSamples();
  stats.steals = synth.steals();
  stats.loudestSteal = synth.loudestSteal();
  stats.limitedFrames = synth.limiter().limitedFrames();
  stats.overFrames = synth.limiter().overFrames();
  stats.limiterDeepestDb = synth.limiter().deepestReductionDb();
  stats.peakBeforeLimiter = synth.limiter().peakIn();
  return stats;
}

}  // namespace hamiltone::cli
