// What each bundled preset costs: keys spread over its range struck together at velocity 90 and
// held (struck again every half second, so none decays), on one thread at 48 kHz. The time per
// key per sample of audio gives the keys one core sustains in real time — the README's table.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "held_keys.h"
#include "presets/preset_loader.h"
#include "synth/synth.h"

namespace hamiltone {
namespace {

constexpr double kRestrikeS = 0.5;

struct Bundled {
  const char* name;
  int everyNth;  // keys measured: lowest, lowest + n, … up to the highest
};
const Bundled kPresets[] = {
    {"grand-piano", 6}, {"grand-piano-strings", 6}, {"paper-c3-string", 3}, {"steel-plate", 3},
    {"gong", 3},        {"thunder-sheet", 2},       {"small-cymbal", 3}};

void presetCost(benchmark::State& state) {
  const Bundled& preset = kPresets[state.range(0)];
  const Instrument instrument =
      loadPreset(std::string(HAMILTONE_SOURCE_DIR "/presets/") + preset.name + ".toml");
  playHeldKeys(state, instrument, everyNthKey(instrument, preset.everyNth), 256, kRestrikeS);
  state.SetLabel(preset.name);
  state.counters["polyphony"] = instrument.polyphony;
}

// The console table, then one line per preset: its keys per core in real time.
class CostReporter : public benchmark::ConsoleReporter {
 public:
  CostReporter() : ConsoleReporter(OO_Tabular) {}
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& run : runs)
      if (const auto cost = keyCostOf(run))
        lines[run.report_label] = {*cost, run.counters.at("polyphony").value};
  }
  struct Line {
    double secondsPerKeySample, polyphony;
  };
  std::map<std::string, Line> lines;
};

}  // namespace
}  // namespace hamiltone

BENCHMARK(hamiltone::presetCost)
    ->ArgName("preset")
    ->DenseRange(0, std::size(hamiltone::kPresets) - 1)
    ->Unit(benchmark::kMillisecond);

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  hamiltone::CostReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  std::printf("\n%-16s %16s %14s %10s\n", "preset", "% of a core/key", "keys per core",
              "polyphony");
  for (const auto& [name, line] : reporter.lines) {
    const double coreFraction = line.secondsPerKeySample * hamiltone::kHeldKeysSampleRate;
    std::printf("%-16s %16.1f %14.1f %10.0f\n", name.c_str(), 100.0 * coreFraction,
                1.0 / coreFraction, line.polyphony);
  }
  benchmark::Shutdown();
}
