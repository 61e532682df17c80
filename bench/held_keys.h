// Keys struck together at velocity 90 and held, on one thread: the loop of the synthesizer's
// benchmarks (chords, a key across the keyboard) and of the presets' costs.
#pragma once

#include <benchmark/benchmark.h>

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "synth/synth.h"

namespace hamiltone {

inline constexpr double kHeldKeysSampleRate = 48000.0;

// Every n-th key of the instrument's range, from its lowest.
inline std::vector<int> everyNthKey(const Instrument& instrument, int n) {
  std::vector<int> keys;
  for (int key = instrument.lowestNote; key <= instrument.highestNote; key += n)
    keys.push_back(key);
  return keys;
}

// `keys` struck at once and again every `restrikeS` (so none decays), in blocks of `block` at
// kHeldKeysSampleRate. Counters: "keys", and "t/key/sample", the CPU time per key per sample of
// audio. Skips with an error when a key stopped sounding.
inline void playHeldKeys(benchmark::State& state, const Instrument& instrument,
                         const std::vector<int>& keys, int block, double restrikeS) {
  std::vector<bool> notes(128, false);
  std::vector<SynthEvent> strike;
  for (int key : keys) {
    notes[key] = true;
    strike.push_back({0, {0x90, static_cast<std::uint8_t>(key), 90}});
  }
  const int count = static_cast<int>(keys.size());
  Synth synth;
  synth.prepare(
      {instrument},
      {.sampleRate = kHeldKeysSampleRate, .maxBlock = block, .notes = notes, .threads = 1});
  synth.setPolyphony(count);
  std::vector<float> left(block), right(block);
  const int restrike = static_cast<int>(restrikeS * kHeldKeysSampleRate / block);
  int blocks = 0;
  for (auto _ : state) {
    const bool now = blocks++ % restrike == 0;
    synth.process(left, right,
                  now ? std::span<const SynthEvent>(strike) : std::span<const SynthEvent>());
    benchmark::DoNotOptimize(left.data());
  }
  if (synth.activeVoices() != count) state.SkipWithError("not every key kept sounding");
  state.counters["keys"] = count;
  state.counters["t/key/sample"] =
      benchmark::Counter(static_cast<double>(state.iterations()) * block * count,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// A run's "t/key/sample": a single run's, or with repetitions their median; none for the other
// aggregates, a failed run or another benchmark.
inline std::optional<double> keyCostOf(const benchmark::BenchmarkReporter::Run& run) {
  using Run = benchmark::BenchmarkReporter::Run;
  const auto perKey = run.counters.find("t/key/sample");
  const bool median = run.run_type == Run::RT_Aggregate && run.aggregate_name == "median";
  if (run.error_occurred || perKey == run.counters.end() ||
      !(median || (run.run_type == Run::RT_Iteration && run.repetitions <= 1)))
    return std::nullopt;
  return perKey->second.value;
}

}  // namespace hamiltone
