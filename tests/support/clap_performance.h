// A performance for a CLAP instance (tests/support/clap_host.h): MIDI and parameter changes at
// times, played in blocks of given sizes, and what came out.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <span>
#include <thread>
#include <vector>

#include "support/clap_host.h"

namespace hamiltone::testing {

// The host's process call, as play() makes it unless told otherwise.
struct ClapProcessCall {
  void operator()(ClapInstance& plugin, std::span<float> left, std::span<float> right,
                  std::span<const ClapEvent> events) const {
    plugin.process(left, right, events);
  }
};

// A message or parameter change at a time of the performance.
struct Cue {
  double seconds;
  ClapEvent event;
};
inline Cue noteOn(double seconds, int key, int velocity = 100) {
  return {seconds, ClapEvent::midiAt(0, 0x90, uint8_t(key), uint8_t(velocity))};
}
inline Cue noteOff(double seconds, int key) {
  return {seconds, ClapEvent::midiAt(0, 0x80, uint8_t(key), 0)};
}
inline Cue param(double seconds, clap_id id, double value) {
  return {seconds, ClapEvent::paramAt(0, id, value)};
}

struct Take {
  double rate = 0.0;
  std::vector<float> left, right;

  std::vector<double> mono(double from, double to) const {
    std::vector<double> x;
    for (long n = std::lround(from * rate); n < std::min<long>(std::lround(to * rate), left.size());
         ++n)
      x.push_back(0.5 * (left[n] + right[n]));
    return x;
  }
  double peak(double from, double to) const {
    double p = 0.0;
    for (double v : mono(from, to)) p = std::max(p, std::abs(v));
    return p;
  }
};

// Plays `seconds` with the cues at their frames, in blocks cycling through `blocks` (after the
// first 0.1 s in single frames when `singleFramesFirst`); each block goes through
// process(plugin, left, right, events), by default ClapInstance::process itself.
template <class Process = ClapProcessCall>
Take play(ClapInstance& plugin, double rate, double seconds, const std::vector<Cue>& cues,
          const std::vector<uint32_t>& blocks, bool singleFramesFirst = false,
          Process process = {}) {
  Take take{rate, std::vector<float>(std::lround(seconds * rate)),
            std::vector<float>(std::lround(seconds * rate))};
  const long frames = static_cast<long>(take.left.size());
  std::vector<ClapEvent> events;
  size_t next = 0, call = 0;
  for (long done = 0; done < frames;) {
    long n =
        singleFramesFirst && done < std::lround(0.1 * rate) ? 1 : blocks[call++ % blocks.size()];
    n = std::min(n, frames - done);
    events.clear();
    for (; next < cues.size() && std::lround(cues[next].seconds * rate) < done + n; ++next) {
      events.push_back(cues[next].event);
      events.back().header.time =
          static_cast<uint32_t>(std::max(0L, std::lround(cues[next].seconds * rate) - done));
    }
    process(plugin, std::span(take.left).subspan(done, n), std::span(take.right).subspan(done, n),
            std::span<const ClapEvent>(events));
    done += n;
  }
  return take;
}

// Silent blocks of 64 frames while the parameter `status` reads `loading` (a plugin building
// something away from the audio thread; at most 30 s), then one more, in which the plugin takes
// what was built. The status then.
template <class Process = ClapProcessCall>
double settle(ClapInstance& plugin, clap_id status, double loading, Process process = {}) {
  std::vector<float> left(64), right(64);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (plugin.param(status) == loading && std::chrono::steady_clock::now() < deadline) {
    process(plugin, std::span(left), std::span(right), std::span<const ClapEvent>());
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  process(plugin, std::span(left), std::span(right), std::span<const ClapEvent>());
  return plugin.param(status);
}

}  // namespace hamiltone::testing
