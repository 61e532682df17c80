// BDZ Fig. 7 and Fig. 10: compute time per simulated second against k for Störmer–Verlet, the
// split scheme (38) and the implicit references — (67) on the string, (83) on the plate.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <iterator>
#include <numbers>
#include <string>

#include "instruments/plate.h"
#include "instruments/string.h"
#include "recording_reporter.h"
#include "schemes/reference/discrete_gradient_string.h"
#include "schemes/reference/linearly_implicit_plate.h"
#include "schemes/sav.h"
#include "schemes/stormer_verlet.h"

namespace hamiltone {
namespace {

// A simulated second at the finest k takes hours with the implicit schemes, so every benchmark
// steps a fixed count and reports time per simulated second = time per step / k (the counter
// s_per_sim_s; the figures plot that against k). CPU time, not wall time: every scheme runs on
// one thread, and on a shared machine the wall time mostly measures the neighbours. The counts keep
// the whole program near a minute on a loaded two-core machine.
constexpr long kExplicitSteps = 10000;
constexpr long kStringImplicitSteps = 500;
constexpr long kPlateImplicitSteps = 30;

// The stored text of BDZ does not give the figures' axes. The string's k span the paper's own
// runs (2.6e-7 s, Figs. 4–6; the reference 1.04e-7, Fig. 5) up to a grid of 23 segments, where
// Fig. 7's cost levels off; the plate's, its k = 1e-5 (Fig. 11), 5e-6 (Fig. 8) and the 2.5e-6
// reference (Fig. 9), one halving below and 2e-5, 4e-5 above (SV at α = 10 fails past 2e-5,
// §4.3.3; at α = 1 it is stable on the grid (84)).
constexpr double kStringSteps[] = {1e-5, 4e-6, 1.6e-6, 6.4e-7, 2.56e-7, 1.024e-7};
constexpr double kPlateSteps[] = {4e-5, 2e-5, 1e-5, 5e-6, 2.5e-6, 1.25e-6};
constexpr double kStringAlpha = 300.0;  // (70): the amplitude of Figs. 5–6
constexpr double kPlateAlpha = 1.0;     // (85): one thickness, nonlinear, SV stable
constexpr double kGridFactor = 1.05;    // h = 1.05 sqrt(E/ρ) k, BDZ §4.2.3

constexpr const char* kSv = "SV";
constexpr const char* kSplit = "SAV_38";
constexpr const char* kStringImplicit = "implicit_67";
constexpr const char* kPlateImplicit = "implicit_83";

std::string label(double k) {
  char text[32];
  std::snprintf(text, sizeof text, "k:%g", k);
  return text;
}
std::string benchName(const char* problem, double k, const char* scheme) {
  return std::string(problem) + "/" + label(k) + "/" + scheme;
}

// An inverted rate is a time per item: here seconds of computation per simulated second.
benchmark::Counter timePer(double items) {
  return benchmark::Counter(items, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// One iteration is one step of a scheme built before the timing by `make` — in place, since the
// implicit ones cannot be copied or moved (nor can their factorisations).
template <class Make>
void add(const std::string& name, double k, long steps, Make make) {
  benchmark::RegisterBenchmark(name.c_str(),
                               [make, k](benchmark::State& state) {
                                 auto scheme = make();
                                 for (auto _ : state) {
                                   scheme.step();
                                   benchmark::DoNotOptimize(scheme.q().data());
                                 }
                                 if (!scheme.qNext().allFinite())
                                   state.SkipWithError("the state went non-finite");
                                 const double n = static_cast<double>(state.iterations());
                                 state.counters["k"] = k;
                                 state.counters["unknowns"] =
                                     static_cast<double>(scheme.system().size());
                                 state.counters["s_per_sim_s"] = timePer(n * k);
                                 // The CSV reporter needs every counter in every run: 0 where there
                                 // is no Newton.
                                 double newton = 0.0;
                                 if constexpr (requires { scheme.totalIterations(); })
                                   newton = static_cast<double>(scheme.totalIterations()) / n;
                                 state.counters["newton_per_step"] = newton;
                               })
      ->Iterations(steps)
      ->Unit(benchmark::kMicrosecond);
}

void registerString(double k) {
  const StringPhysics physics;  // BDZ §4.2.3's C3 string, as hamiltone-sim string's defaults
  const NonlinearString string(physics,
                               gridSegments(physics, GridRule::longitudinal, k, 0.0, kGridFactor));
  InitialState start{Vector::Zero(string.size()), Vector::Zero(string.size())};
  for (int j = 1; j < string.segments(); ++j)  // (70)
    start.q[j - 1] =
        kStringAlpha * std::sqrt(physics.area) * std::sin(std::numbers::pi * j / string.segments());
  const StepParameters params{.k = k};
  add(benchName("String", k, kSv), k, kExplicitSteps,
      [=] { return StormerVerlet<NonlinearString>(string, params, start); });
  add(benchName("String", k, kSplit), k, kExplicitSteps,
      [=] { return SplitSav<NonlinearString>(string, params, start); });
  add(benchName("String", k, kStringImplicit), k, kStringImplicitSteps,
      [=] { return DiscreteGradientString(string, k, start); });
}

void registerPlate(double k) {
  const PlatePhysics physics;  // BDZ §4.3.3's steel plate
  const VonKarmanPlate plate(physics, plateSegments(physics, physics.lx, k, 1.0),
                             plateSegments(physics, physics.ly, k, 1.0));  // (84)
  const InitialState start{plateFirstMode(plate, kPlateAlpha), Vector::Zero(plate.size())};
  const StepParameters params{.k = k};
  add(benchName("Plate", k, kSv), k, kExplicitSteps,
      [=] { return StormerVerlet<VonKarmanPlate>(plate, params, start); });
  add(benchName("Plate", k, kSplit), k, kExplicitSteps,
      [=] { return SplitSav<VonKarmanPlate>(plate, params, start); });
  add(benchName("Plate", k, kPlateImplicit), k, kPlateImplicitSteps,
      [=] { return LinearlyImplicitPlate(plate, params, start); });
}

// Nothing is timed anew: every figure is from the runs in the table above.
void printSummary(const RecordingReporter& reporter, const char* problem, const char* implicit,
                  const double* steps, int count) {
  std::printf("\n%s: CPU seconds per simulated second (CPU time per step / k)\n", problem);
  std::printf("%-10s %9s %12s %12s %12s %10s %14s\n", "k", "unknowns", kSv, kSplit, implicit,
              "(38)/SV", "implicit/(38)");
  for (int i = 0; i < count; ++i) {
    const double k = steps[i];
    const auto* sv = reporter.find(benchName(problem, k, kSv));
    const auto* split = reporter.find(benchName(problem, k, kSplit));
    const auto* imp = reporter.find(benchName(problem, k, implicit));
    if (sv == nullptr && split == nullptr && imp == nullptr) continue;  // filtered out
    auto cost = [](const RecordingReporter::Record* r) {
      return r ? r->counters.at("s_per_sim_s").value : NAN;
    };
    const auto* any = sv ? sv : split ? split : imp;
    std::printf("%-10g %9.0f %12.4g %12.4g %12.4g %10.3f %14.1f\n", k,
                any->counters.at("unknowns").value, cost(sv), cost(split), cost(imp),
                cost(split) / cost(sv), cost(imp) / cost(split));
  }
}

}  // namespace
}  // namespace hamiltone

int main(int argc, char** argv) {
  using namespace hamiltone;
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  for (double k : kStringSteps) registerString(k);
  for (double k : kPlateSteps) registerPlate(k);
  RecordingReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  printSummary(reporter, "String", kStringImplicit, kStringSteps, std::size(kStringSteps));
  printSummary(reporter, "Plate", kPlateImplicit, kPlateSteps, std::size(kPlateSteps));
  return 0;
}
