// Cost of the synthesizer playing the grand-piano preset: chords of N held middle-register keys
// (every unison string of each key), as a real-time callback would ask for them. The counter
// "x_realtime" is seconds of audio per second of CPU: above 1 the chord plays in real time on one
// core. The summary names the largest N that does.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "presets/preset_loader.h"
#include "synth/synth.h"

namespace hamiltone {
namespace {

constexpr double kSampleRate = 48000.0;
constexpr int kLowestKey = 48;  // C3: keys C3, C#3, … upward, the middle register
constexpr double kRestrikeS = 2.0;  // keys are struck again every 2 s, well inside their T60s

void chord(benchmark::State& state) {
  const int voices = static_cast<int>(state.range(0));
  const int block = static_cast<int>(state.range(1));
  Instrument piano = loadPreset(HAMILTONE_SOURCE_DIR "/presets/grand-piano.toml");
  std::vector<bool> notes(128, false);
  for (int i = 0; i < voices; ++i) notes[kLowestKey + i] = true;
  Synth synth;
  synth.prepare({piano}, {.sampleRate = kSampleRate, .maxBlock = block, .notes = notes});
  synth.setPolyphony(voices);
  std::vector<SynthEvent> strike;
  for (int i = 0; i < voices; ++i)
    strike.push_back({0, {0x90, static_cast<std::uint8_t>(kLowestKey + i), 90}});
  std::vector<float> left(block), right(block);
  const int restrike = static_cast<int>(kRestrikeS * kSampleRate / block);
  int blocks = 0;
  for (auto _ : state) {
    const bool now = blocks++ % restrike == 0;
    synth.process(left, right, now ? std::span<const SynthEvent>(strike) : std::span<const SynthEvent>());
    benchmark::DoNotOptimize(left.data());
  }
  if (synth.activeVoices() != voices) state.SkipWithError("not every key kept sounding");
  state.counters["x_realtime"] =
      benchmark::Counter(static_cast<double>(state.iterations()) * block / kSampleRate,
                         benchmark::Counter::kIsRate);
  state.counters["strings"] = 0;
  for (int i = 0; i < voices; ++i)
    state.counters["strings"] += piano.keys[kLowestKey + i - piano.lowestNote].unisons;
}

}  // namespace
}  // namespace hamiltone

BENCHMARK(hamiltone::chord)
    ->ArgNames({"voices", "block"})
    ->ArgsProduct({{1, 4, 8, 16, 24, 32}, {256}})
    ->Unit(benchmark::kMillisecond);

namespace {

// The console table, and the largest chord (its "voices:N" argument) at or above real time.
class ChordReporter : public benchmark::ConsoleReporter {
 public:
  ChordReporter() : ConsoleReporter(OO_Tabular) {}
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& run : runs) {
      const auto speed = run.counters.find("x_realtime");
      if (run.error_occurred || speed == run.counters.end() || speed->second.value < 1.0) continue;
      const std::string& args = run.run_name.args;  // "voices:16/block:256"
      largest = std::max(largest, std::stoi(args.substr(args.find(':') + 1)));
    }
  }
  int largest = 0;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  ChordReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  const int largest = reporter.largest;
  std::printf("\nlargest grand-piano chord (keys from C3) rendered faster than real time on one "
              "core: %d keys (goal: 32)\n", largest);
  benchmark::Shutdown();
}
