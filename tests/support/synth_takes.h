// Driving a Synth in the tests: MIDI messages at times in seconds rendered in blocks of any size,
// the take's two channels, and its peak.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "synth/synth.h"

namespace hamiltone::testing {

constexpr double kTakeRate = 48000.0;

inline MidiMessage on(int note, int velocity = 100) {
  return {0x90, uint8_t(note), uint8_t(velocity)};
}
inline MidiMessage off(int note) { return {0x80, uint8_t(note), 0}; }
inline MidiMessage cc(int controller, int value) {
  return {0xB0, uint8_t(controller), uint8_t(value)};
}

struct Take {
  std::vector<float> left, right;
};

// Renders `seconds` with the messages (sorted) at their times, in blocks of `block` frames; after
// each block, afterBlock(frames rendered so far) may look at the synth.
inline Take render(Synth& synth, const std::vector<TimedMessage>& messages, double seconds,
                   int block, const std::function<void(long)>& afterBlock = {}) {
  const long frames = std::lround(seconds * kTakeRate);
  Take take{std::vector<float>(frames), std::vector<float>(frames)};
  std::vector<SynthEvent> events;
  size_t next = 0;
  for (long start = 0; start < frames; start += block) {
    const long n = std::min<long>(block, frames - start);
    events.clear();
    while (next < messages.size() && std::lround(messages[next].seconds * kTakeRate) < start + n) {
      events.push_back(
          {int(std::lround(messages[next].seconds * kTakeRate) - start), messages[next].message});
      ++next;
    }
    synth.process(std::span(take.left).subspan(start, n), std::span(take.right).subspan(start, n),
                  events);
    if (afterBlock) afterBlock(start + n);
  }
  return take;
}

inline Synth prepared(std::vector<Instrument> instruments, int maxBlock = 256,
                      bool freeQuietVoices = true, int threads = 0) {
  Synth synth;
  synth.prepare(std::move(instruments), {.sampleRate = kTakeRate,
                                         .maxBlock = maxBlock,
                                         .notes = {},
                                         .threads = threads,
                                         .freeQuietVoices = freeQuietVoices});
  return synth;
}

inline float peak(const std::vector<float>& x, size_t from = 0, size_t to = SIZE_MAX) {
  float p = 0.0f;
  for (size_t i = from; i < std::min(to, x.size()); ++i) p = std::max(p, std::abs(x[i]));
  return p;
}

// The larger of the two channels' peaks over [from, to).
inline float peak(const Take& take, size_t from = 0, size_t to = SIZE_MAX) {
  return std::max(peak(take.left, from, to), peak(take.right, from, to));
}

}  // namespace hamiltone::testing
