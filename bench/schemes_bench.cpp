// Time per step of SV (20), SAV (27)/(38) and Marazzato (22) on the FPU chain; ratios to SV.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "problems/fpu.h"
#include "recording_reporter.h"
#include "schemes/marazzato.h"
#include "schemes/sav.h"
#include "schemes/stormer_verlet.h"

namespace hamiltone {
namespace {

constexpr double kOmega = 50.0;  // BDZ §4.1.1
constexpr double kStep = 1e-3;
// A run may take tens of millions of steps, so every scheme must stay bounded for good.
// α = 1 gives H ≈ ω²/4, so no quartic spring stretches past H^¼ ≈ 5, and the stiffest
// linearised frequency, ≈ sqrt(ω² + 24·5²) ≈ 56, keeps kω far under SV's bound 2 (and (44)).
// Lossless, so the state never decays into denormals, which would time the CPU's slow path.
constexpr double kAlpha = 1.0;
constexpr int kChainPairs[] = {3, 1000};

constexpr const char* kSv = "StormerVerlet_20";
constexpr const char* kNonSplit = "NonSplitSav_27";
constexpr const char* kSplit = "SplitSav_38";
constexpr const char* kMidpoint = "Marazzato_22_midpoint";
constexpr const char* kGl2 = "Marazzato_22_gl2";

std::string benchmarkName(const char* scheme, int pairs) {
  return std::string(scheme) + "/pairs:" + std::to_string(pairs);
}

// One iteration is one step. Each run steps its own copy of the scheme built at registration,
// taken before the timing starts.
template <class Scheme>
void stepScheme(benchmark::State& state, Scheme scheme) {
  for (auto _ : state) {
    scheme.step();
    benchmark::DoNotOptimize(scheme.q().data());
  }
  if (!scheme.q().allFinite()) state.SkipWithError("the state went non-finite");
  const double unknowns = static_cast<double>(scheme.system().size());
  state.SetItemsProcessed(state.iterations());
  // An inverted rate is time per item: here per unknown per step, shown as e.g. "1.2ns".
  state.counters["time/unknown"] =
      benchmark::Counter(unknowns * static_cast<double>(state.iterations()),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

template <class Scheme>
void add(const char* scheme, int pairs, const Scheme& prototype) {
  // Real time, so the counter and the ratios printed after the table measure the same thing.
  benchmark::RegisterBenchmark(benchmarkName(scheme, pairs).c_str(), &stepScheme<Scheme>, prototype)
      ->UseRealTime();
}

void registerBenchmarks() {
  using Fpu = FermiPastaUlam;
  for (int pairs : kChainPairs) {
    const Fpu chain(pairs, kOmega);
    const InitialState start = fpuInitialState(chain, kAlpha);
    const StepParameters params{.k = kStep};
    add(kSv, pairs, StormerVerlet<Fpu>(chain, params, start));
    add(kNonSplit, pairs, NonSplitSav<Fpu>(chain, params, start));
    add(kSplit, pairs, SplitSav<Fpu>(chain, params, start));
    add(kMidpoint, pairs, Marazzato<Fpu>(chain, params, start, QuadratureRule::midpoint));
    add(kGl2, pairs, Marazzato<Fpu>(chain, params, start, QuadratureRule::gaussLegendre2));
  }
}

// The cost of `scheme` relative to Störmer–Verlet on the same chain, from the recorded runs.
void printRatio(const RecordingReporter& runs, const char* scheme, int pairs) {
  const auto* num = runs.find(benchmarkName(scheme, pairs));
  const auto* den = runs.find(benchmarkName(kSv, pairs));
  if (!num || !den) return;  // filtered out or failed
  std::printf("%-22s / %s  pairs %4d: %.3f\n", scheme, kSv, pairs, num->seconds / den->seconds);
}

}  // namespace
}  // namespace hamiltone

int main(int argc, char** argv) {
  using namespace hamiltone;
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  registerBenchmarks();
  RecordingReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();

  std::printf("\nCost relative to Stormer-Verlet (20), real time per step:\n");
  for (int pairs : kChainPairs)
    for (const char* scheme : {kSplit, kNonSplit, kMidpoint}) printRatio(reporter, scheme, pairs);
  return 0;
}
