// Cost of the piano's body at 48 kHz: the modal soundboard alone and with the 88 keys'
// sympathetic strings (PianoBody), every bridge point driven, against the highest board mode.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <span>
#include <vector>

#include "instruments/piano_body.h"

namespace hamiltone {
namespace {

constexpr double kSampleRate = 48000.0;
const BoardPoint kPickups[2] = {{0.45, 0.35}, {1.2, 0.9}};

// "cpu/audio_s" is the CPU time per second of audio: 0.05 (shown "50ms") is 5 % of one core.
benchmark::Counter perAudioSecond(double steps) {
  return benchmark::Counter(steps / kSampleRate,
                            benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// A force on every point, different each step, as 88 sounding keys would give: 256 steps of them
// made beforehand, so that the sines are not timed.
class Forces {
 public:
  Forces() : f_(256 * 88) {
    for (int n = 0; n < 256; ++n)
      for (int k = 0; k < 88; ++k) f_[n * 88 + k] = std::sin(0.05 * n * (k + 1));
  }
  std::span<const double> at(long n) const { return {f_.data() + (n & 255) * 88, 88}; }

 private:
  std::vector<double> f_;
};

void boardStep(benchmark::State& state) {
  SoundboardPhysics p;
  p.maxModeHz = static_cast<double>(state.range(0));
  Soundboard board;
  board.prepare(p, kSampleRate, bridgeLine(21, 108, p), kPickups);
  const Forces forces;
  long n = 0;
  for (auto _ : state) {
    board.addForces(forces.at(n++));
    board.step();
    double l, r;
    board.pickups(l, r);
    benchmark::DoNotOptimize(l + r);
  }
  state.counters["modes"] = board.modes();
  state.counters["cpu/audio_s"] = perAudioSecond(static_cast<double>(state.iterations()));
}
// On a shared machine the least-disturbed repetition is the one to read:
// --benchmark_repetitions=10 --benchmark_report_aggregates_only=true reports it as "_min".
double fastest(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }

BENCHMARK(boardStep)
    ->ArgName("maxModeHz")
    ->Arg(800)
    ->Arg(1000)
    ->Arg(1500)
    ->Arg(2000)
    ->Arg(3000)
    ->Arg(4000)
    ->ComputeStatistics("min", fastest);

void bodyStep(benchmark::State& state) {
  PianoBodySpec spec;
  spec.board.maxModeHz = static_cast<double>(state.range(0));
  spec.sympatheticMaxPartials = static_cast<int>(state.range(1));
  PianoBody body;
  body.prepare(spec, bridgeLine(21, 108, spec.board), grandSympatheticKeys());
  for (int k = 0; k < body.keys(); ++k) body.setDamper(k, 0.0);  // the sustain pedal down
  const Forces forces;
  long n = 0;
  for (auto _ : state) {
    body.step(forces.at(n++));
    double l, r;
    body.output(l, r);
    benchmark::DoNotOptimize(l + r);
  }
  int partials = 0;
  for (int k = 0; k < body.keys(); ++k) partials += body.strings().partials(k);
  state.counters["modes"] = body.board().modes();
  state.counters["partials"] = partials;
  state.counters["cpu/audio_s"] = perAudioSecond(static_cast<double>(state.iterations()));
}
BENCHMARK(bodyStep)
    ->ArgNames({"maxModeHz", "partials"})
    ->ArgsProduct({{800, 1000, 1500, 2000, 3000}, {8, 16}})
    ->ComputeStatistics("min", fastest);

// The sustain pedal up: dampers down, ten keys played by voices (their strings excluded, their
// points driven), the damped keys asleep below a quiet floor of floor_per_mille thousandths of the
// body's energy: the 20 keys without dampers (F6 … C8) and the damped keys the board moves past the
// floor stay in use (the played keys are driven, not read); "points" says how many do.
void bodyStepPedalUp(benchmark::State& state) {
  PianoBodySpec spec;
  spec.board.maxModeHz = static_cast<double>(state.range(0));
  PianoBody body;
  body.prepare(spec, bridgeLine(21, 108, spec.board), grandSympatheticKeys());
  const int played[] = {15, 27, 31, 34, 39, 43, 46, 51, 55, 58};
  for (int k = 0; k < body.keys(); ++k) body.setDamper(k, 1.0);
  for (int k : played) body.setExcluded(k, true);
  body.setQuietFloor(1e-12, static_cast<double>(state.range(1)) * 1e-3);
  std::vector<double> f(88, 0.0);
  const Forces forces;
  const auto drive = [&](long n) {
    const auto all = forces.at(n);
    for (int k : played) f[k] = all[k];
    body.step(f);
  };
  long n = 0;
  for (; n < 4096; ++n) drive(n);  // past the strikes' 50 ms awake and the looks after it
  for (auto _ : state) {
    drive(n++);
    double l, r;
    body.output(l, r);
    benchmark::DoNotOptimize(l + r);
  }
  state.counters["modes"] = body.board().modes();
  state.counters["points"] = body.pointsInUse();
  state.counters["cpu/audio_s"] = perAudioSecond(static_cast<double>(state.iterations()));
}
BENCHMARK(bodyStepPedalUp)
    ->ArgNames({"maxModeHz", "floor_per_mille"})
    ->ArgsProduct({{1000, 2000, 4000}, {1, 30}})
    ->ComputeStatistics("min", fastest);

}  // namespace
}  // namespace hamiltone

BENCHMARK_MAIN();
