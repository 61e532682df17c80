// The render loop: the block's events with their sample offsets, the synthesizer, interleaving,
// the WAV writer, and the tallies the summary reports.
#include "performance.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace hamiltone::cli {

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
  return stats;
}

}  // namespace hamiltone::cli
