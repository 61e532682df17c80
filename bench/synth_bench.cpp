// Cost of the synthesizer playing the grand-piano preset: chords of N held middle-register keys
// (every unison string of each key), as a real-time callback would ask for them. The counter
// "x_realtime" is seconds of audio per second of CPU: above 1 the chord plays in real time on one
// core (threads = 1: every key on the calling thread). The summary names the largest N that does.
// Beside it, the cost of one grand-piano key across the keyboard on each string grid rule, and the
// ratio of the two-grid to the transverse; and of single keys by register (key/…).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "held_keys.h"
#include "presets/preset_loader.h"
#include "synth/synth.h"

namespace hamiltone {
namespace {

constexpr int kLowestKey = 48;      // C3: keys C3, C#3, … upward, the middle register
constexpr double kRestrikeS = 2.0;  // keys are struck again every 2 s, well inside their T60s

void chord(benchmark::State& state) {
  const int voices = static_cast<int>(state.range(0));
  const int block = static_cast<int>(state.range(1));
  const Instrument piano = loadPreset(HAMILTONE_SOURCE_DIR "/presets/grand-piano.toml");
  std::vector<int> keys;
  for (int i = 0; i < voices; ++i) keys.push_back(kLowestKey + i);
  playHeldKeys(state, piano, keys, block, kRestrikeS);
  state.counters["x_realtime"] =
      benchmark::Counter(static_cast<double>(state.iterations()) * block / kHeldKeysSampleRate,
                         benchmark::Counter::kIsRate);
  state.counters["strings"] = 0;
  for (int key : keys) state.counters["strings"] += piano.keys[key - piano.lowestNote].unisons;
}

// Every 6th key from A0 to C8 (15 keys, all unison strings on their bridges) struck together and
// held: the time per block divided by the keys is the cost of an average grand-piano key (ns per
// sample of audio). The body is off: its cost is the board's and every key's sympathetic strings,
// shared by the keys and the same on both grid rules (hamiltone_bench_body measures it). tail:0
// turns the linear tail off (scheme.linear_below = 0), which only the two grids take: the rules
// compared geometric throughout.
constexpr const char* kGridRules[] = {"two-grid", "transverse"};

void keyboard(benchmark::State& state) {
  const char* rule = kGridRules[state.range(0)];
  const bool tail = state.range(1) != 0;
  PresetOptions options{.overrides = {{"scheme.grid_rule", rule}, {"body.enabled", "false"}}};
  if (!tail) options.overrides.push_back({"scheme.linear_below", "0"});
  const Instrument piano = loadPreset(HAMILTONE_SOURCE_DIR "/presets/grand-piano.toml", options);
  playHeldKeys(state, piano, everyNthKey(piano, 6), 256, kRestrikeS);
  state.SetLabel(std::string(rule) + (tail ? "" : ", no tail"));
}

// One key alone, all its unison strings on their bridge (body off), on each grid rule: A0, C3, C5,
// C6 and C7, where `keyboard` gives the mean of fifteen keys. The treble's short strings (C5: three
// coarse cells; C6, C7: one) spend most of a step on work that does not scale with the grid.
void key(benchmark::State& state) {
  const int note = static_cast<int>(state.range(0));
  const char* rule = kGridRules[state.range(1)];
  PresetOptions options{.overrides = {{"scheme.grid_rule", rule}, {"body.enabled", "false"}}};
  const Instrument piano = loadPreset(HAMILTONE_SOURCE_DIR "/presets/grand-piano.toml", options);
  playHeldKeys(state, piano, {note}, 256, kRestrikeS);
}

}  // namespace
}  // namespace hamiltone

BENCHMARK(hamiltone::key)
    ->ArgNames({"note", "rule"})
    ->ArgsProduct({{21, 48, 72, 84, 96}, {0, 1}})
    ->Unit(benchmark::kMicrosecond);

BENCHMARK(hamiltone::keyboard)
    ->ArgNames({"rule", "tail"})
    ->ArgsProduct({{0, 1}, {1, 0}})
    ->Unit(benchmark::kMillisecond);

BENCHMARK(hamiltone::chord)
    ->ArgNames({"voices", "block"})
    ->ArgsProduct({{1, 4, 8, 16, 24, 32}, {256}})
    ->Unit(benchmark::kMillisecond);

namespace {

// The console table, the largest chord (its "voices:N" argument) at or above real time, and the
// cost of a key on each grid rule.
class ChordReporter : public benchmark::ConsoleReporter {
 public:
  ChordReporter() : ConsoleReporter(OO_Tabular) {}
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& run : runs) {
      if (const auto cost = hamiltone::keyCostOf(run); cost && !run.report_label.empty())
        keyCost[run.report_label] = *cost;
      const auto speed = run.counters.find("x_realtime");
      if (run.error_occurred || speed == run.counters.end() || speed->second.value < 1.0) continue;
      const std::string& args = run.run_name.args;  // "voices:16/block:256"
      largest = std::max(largest, std::stoi(args.substr(args.find(':') + 1)));
    }
  }
  int largest = 0;
  std::map<std::string, double> keyCost;  // seconds per sample of audio, by grid rule
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  ChordReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  const int largest = reporter.largest;
  auto& cost = reporter.keyCost;
  for (const char* tail : {"", ", no tail"}) {
    const std::string two = std::string("two-grid") + tail, one = std::string("transverse") + tail;
    if (cost.count(two) && cost.count(one))
      std::printf(
          "\ngrand-piano key (no body), every 6th from A0%s: two-grid %.0f ns per sample, "
          "transverse %.0f (ratio %.2f; goal <= 0.7)\n",
          tail, 1e9 * cost[two], 1e9 * cost[one], cost[two] / cost[one]);
  }
  std::printf(
      "\nlargest grand-piano chord (keys from C3) rendered faster than real time on one "
      "core: %d keys (goal: 32)\n",
      largest);
  benchmark::Shutdown();
}
