// Cost of the von Kármán plate at 48 kHz: (38) and SV per step, the exact Airy solve against a
// sparse LDLᵀ, and the largest steel plate whose (38) step keeps up with real time on one core.
#include <benchmark/benchmark.h>

#include <Eigen/SparseCholesky>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "instruments/plate.h"
#include "recording_reporter.h"
#include "schemes/sav.h"
#include "schemes/stormer_verlet.h"

namespace hamiltone {
namespace {

constexpr double kSampleRate = 48000.0;
constexpr double kStep = 1.0 / kSampleRate;
constexpr double kRealTimeMicros = 1e6 / kSampleRate;  // one step per sample on one core
constexpr double kGoalCoreFraction = 0.5;              // the paper's plate within half a core
// (85) with α = 1: q is one thickness at the centre. Small enough that SV stays stable on the
// (84) grid, large enough that V' is no rounding error; lossless, so nothing decays into
// denormals (which would time the CPU's slow path).
constexpr double kFirstModeAlpha = 1.0;

constexpr const char* kSv = "StormerVerlet_20";
constexpr const char* kSplit = "SplitSav_38";
constexpr const char* kDst = "dense_DST";
constexpr const char* kLdlt = "sparse_LDLT";

struct PlateCase {
  const char* name;
  PlatePhysics physics;
};

PlatePhysics largePlate() {
  PlatePhysics p;
  p.lx = 1.0;
  p.ly = 0.8;
  p.thickness = 1e-3;
  return p;
}

// (a) BDZ §4.3.3's plate, PlatePhysics{}; (b) a larger, thinner one, with four times its grid.
const PlateCase kPlates[] = {{"paper_0.5x0.5m_2mm", PlatePhysics{}},
                             {"large_1.0x0.8m_1mm", largePlate()}};
// Sides of the 2 mm steel square for the real-time sweep, m.
constexpr double kSides[] = {0.2, 0.25, 0.3, 0.32, 0.35, 0.4, 0.45, 0.5, 0.6, 0.8};

// The plate on the grid of the bound (84) at k = 1/48000 s, as tight as it allows.
VonKarmanPlate boundGridPlate(const PlatePhysics& p) {
  return VonKarmanPlate(p, plateSegments(p, p.lx, kStep, 1.0), plateSegments(p, p.ly, kStep, 1.0));
}

PlatePhysics squarePlate(double side) {
  PlatePhysics p;
  p.lx = p.ly = side;
  return p;
}

std::string schemeName(const char* plate, const char* scheme) {
  return std::string("Plate/") + plate + "/" + scheme;
}
std::string airyName(const char* plate, const char* solver) {
  return std::string("Airy/") + plate + "/" + solver;
}
std::string sideLabel(double side) {
  char label[32];
  std::snprintf(label, sizeof label, "side:%.2fm", side);
  return label;
}
std::string sweepName(double side) {
  return std::string("RealTime/") + sideLabel(side) + "/" + kSplit;
}

// An inverted rate is a time per item, shown as e.g. "1.2ns".
benchmark::Counter timePer(double items) {
  return benchmark::Counter(items, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void gridCounters(benchmark::State& state, const VonKarmanPlate& plate) {
  state.counters["nx"] = plate.nx();
  state.counters["ny"] = plate.ny();
  state.counters["unknowns"] = static_cast<double>(plate.size());
}

// One iteration is one step at k = 1/48000 s; each run steps its own copy of the scheme built at
// registration. cpu/audio_s is the CPU time per second of audio ("12ms" is 1.2 % of one core).
template <class Scheme>
void stepScheme(benchmark::State& state, Scheme scheme) {
  for (auto _ : state) {
    scheme.step();
    benchmark::DoNotOptimize(scheme.q().data());
  }
  if (!scheme.q().allFinite()) state.SkipWithError("the state went non-finite");
  const double steps = static_cast<double>(state.iterations());
  gridCounters(state, scheme.system());
  state.counters["t/unknown"] = timePer(steps * static_cast<double>(scheme.system().size()));
  state.counters["cpu/audio_s"] = timePer(steps / kSampleRate);
}

template <class Scheme>
void addScheme(const std::string& name, const Scheme& prototype) {
  benchmark::RegisterBenchmark(name.c_str(), &stepScheme<Scheme>, prototype)
      ->UseRealTime()
      ->Unit(benchmark::kMicrosecond);
}

// A right-hand side of the size of the plate's grid, the same on every run.
Vector randomRhs(Eigen::Index n) {
  std::mt19937_64 rng(20240611);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Vector r(n);
  for (double& x : r) x = u(rng);
  return r;
}

// One iteration is one DΔΔ F = r solve by the plate's dense 2-D DST-I.
void solveDst(benchmark::State& state, VonKarmanPlate plate) {
  const Vector rhs = randomRhs(plate.size());
  Vector f = Vector::Zero(plate.size());
  for (auto _ : state) {
    plate.solveBiharmonic(rhs, f);
    benchmark::DoNotOptimize(f.data());
    benchmark::ClobberMemory();
  }
  gridCounters(state, plate);
}

// DΔΔ as a sparse matrix, column j = DΔ DΔ e_j from the plate's own stencil (13 entries at most).
Eigen::SparseMatrix<double> sparseBiharmonic(const VonKarmanPlate& plate) {
  const Eigen::Index n = plate.size();
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<std::size_t>(13 * n));
  Vector unit = Vector::Zero(n), lap(n), bilap(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    unit[j] = 1.0;
    plate.laplacian(unit, lap);
    plate.laplacian(lap, bilap);
    unit[j] = 0.0;
    for (Eigen::Index i = 0; i < n; ++i)
      if (bilap[i] != 0.0) entries.emplace_back(i, j, bilap[i]);
  }
  Eigen::SparseMatrix<double> a(n, n);
  a.setFromTriplets(entries.begin(), entries.end());
  return a;
}

// The same solve by Eigen's SimplicialLDLT (AMD ordering), factorised once before the timing.
// rel_diff: max |F_ldlt − F_dst| / max |F_dst|, to show both solve the same system.
void solveLdlt(benchmark::State& state, VonKarmanPlate plate) {
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(sparseBiharmonic(plate));
  if (ldlt.info() != Eigen::Success) {
    state.SkipWithError("the sparse LDLT factorisation failed");
    return;
  }
  const Vector rhs = randomRhs(plate.size());
  Vector f = Vector::Zero(plate.size());
  for (auto _ : state) {
    f = ldlt.solve(rhs);
    benchmark::DoNotOptimize(f.data());
    benchmark::ClobberMemory();
  }
  Vector exact = Vector::Zero(plate.size());
  plate.solveBiharmonic(rhs, exact);
  gridCounters(state, plate);
  state.counters["rel_diff"] = (f - exact).cwiseAbs().maxCoeff() / exact.cwiseAbs().maxCoeff();
  state.counters["factor_nnz"] = static_cast<double>(ldlt.matrixL().nestedExpression().nonZeros());
}

void addSolver(const std::string& name, void (*solve)(benchmark::State&, VonKarmanPlate),
               const VonKarmanPlate& plate) {
  benchmark::RegisterBenchmark(name.c_str(), solve, plate)
      ->UseRealTime()
      ->Unit(benchmark::kMicrosecond);
}

void registerBenchmarks() {
  using Split = SplitSav<VonKarmanPlate>;
  using Sv = StormerVerlet<VonKarmanPlate>;
  for (const PlateCase& c : kPlates) {
    const VonKarmanPlate plate = boundGridPlate(c.physics);
    const InitialState start{plateFirstMode(plate, kFirstModeAlpha), Vector::Zero(plate.size())};
    const StepParameters params{.k = kStep};
    addScheme(schemeName(c.name, kSplit), Split(plate, params, start));
    addScheme(schemeName(c.name, kSv), Sv(plate, params, start));
    addSolver(airyName(c.name, kDst), &solveDst, plate);
    addSolver(airyName(c.name, kLdlt), &solveLdlt, plate);
  }
  for (double side : kSides) {
    const VonKarmanPlate plate = boundGridPlate(squarePlate(side));
    const InitialState start{plateFirstMode(plate, kFirstModeAlpha), Vector::Zero(plate.size())};
    addScheme(sweepName(side), Split(plate, {.k = kStep}, start));
  }
}

const char* verdict(bool met) { return met ? "met" : "NOT met"; }

// Nothing in the summary is timed anew: every figure is the median the table above shows.
void printSchemes(const RecordingReporter& reporter) {
  std::printf(
      "\nPlates at k = 1/%.0f s on the (84) grid, first mode (85) alpha = %.0f, real time"
      " (median with repetitions):\n",
      kSampleRate, kFirstModeAlpha);
  std::printf("%-20s %-17s %9s %9s %9s %12s %16s\n", "plate", "scheme", "grid", "unknowns",
              "us/step", "core @48k", "ns/unknown/step");
  for (const PlateCase& c : kPlates)
    for (const char* scheme : {kSplit, kSv}) {
      const auto* r = reporter.find(schemeName(c.name, scheme));
      if (r == nullptr) continue;  // filtered out or failed
      const double micros = r->seconds * 1e6, unknowns = r->counters.at("unknowns").value;
      const std::string grid = std::to_string(static_cast<int>(r->counters.at("nx").value)) + "x" +
                               std::to_string(static_cast<int>(r->counters.at("ny").value));
      std::printf("%-20s %-17s %9s %9.0f %9.2f %11.1f%% %16.2f\n", c.name, scheme, grid.c_str(),
                  unknowns, micros, 100.0 * micros * kSampleRate / 1e6, micros * 1e3 / unknowns);
    }
  for (const PlateCase& c : kPlates) {
    const auto* split = reporter.find(schemeName(c.name, kSplit));
    const auto* sv = reporter.find(schemeName(c.name, kSv));
    if (split != nullptr && sv != nullptr)
      std::printf("%s / %s per step, same grid, %s: %.3f\n", kSplit, kSv, c.name,
                  split->seconds / sv->seconds);
  }
}

void printAiry(const RecordingReporter& reporter) {
  std::printf("\nAiry solve DDD F = r alone (random r), real time:\n");
  std::printf("%-20s %13s %15s %10s %14s %15s\n", "plate", "dense DST us", "sparse LDLT us",
              "LDLT/DST", "DST % of (38)", "LDLT rel. diff");
  for (const PlateCase& c : kPlates) {
    const auto* dst = reporter.find(airyName(c.name, kDst));
    const auto* ldlt = reporter.find(airyName(c.name, kLdlt));
    const auto* split = reporter.find(schemeName(c.name, kSplit));
    if (dst == nullptr || ldlt == nullptr) continue;
    std::printf("%-20s %13.2f %15.2f %10.3f", c.name, dst->seconds * 1e6, ldlt->seconds * 1e6,
                ldlt->seconds / dst->seconds);
    if (split != nullptr)
      std::printf(" %13.1f%%", 100.0 * dst->seconds / split->seconds);
    else
      std::printf(" %14s", "-");
    std::printf(" %15.1e\n", ldlt->counters.at("rel_diff").value);
  }
}

void printRealTime(const RecordingReporter& reporter) {
  std::printf(
      "\n%s on 2 mm steel squares at k = 1/%.0f s, (84) grid; real time is <= %.2f us"
      " per step:\n",
      kSplit, kSampleRate, kRealTimeMicros);
  std::printf("%-8s %9s %9s %9s %12s\n", "side m", "grid", "unknowns", "us/step", "core @48k");
  double largest = 0.0;
  for (double side : kSides) {
    const auto* r = reporter.find(sweepName(side));
    if (r == nullptr) continue;
    const double micros = r->seconds * 1e6;
    const int nx = static_cast<int>(r->counters.at("nx").value);
    const std::string grid = std::to_string(nx) + "x" + std::to_string(nx);
    std::printf("%-8.2f %9s %9.0f %9.2f %11.1f%%\n", side, grid.c_str(),
                r->counters.at("unknowns").value, micros, 100.0 * micros * kSampleRate / 1e6);
    if (micros <= kRealTimeMicros && side > largest) largest = side;
  }
  if (largest > 0.0)
    std::printf("Largest measured side in real time on one core: %.2f m\n", largest);
  else
    std::printf("No measured side runs in real time on one core\n");

  if (const auto* r = reporter.find(schemeName(kPlates[0].name, kSplit))) {
    const double fraction = r->seconds * kSampleRate;
    std::printf(
        "Goal: the paper's plate on (38) at %.0f Hz in <= %.0f %% of one core: %.1f %%, %s\n",
        kSampleRate, 100.0 * kGoalCoreFraction, 100.0 * fraction,
        verdict(fraction <= kGoalCoreFraction));
  }
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

  printSchemes(reporter);
  printAiry(reporter);
  printRealTime(reporter);
  return 0;
}
