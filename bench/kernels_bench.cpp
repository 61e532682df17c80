// The string's nonlinear kernels per fine segment, on each instruction set this CPU runs. The
// single grid needs one square root and two divisions per segment, and is timed beside a loop that
// does only that arithmetic over as many values: the floor it cannot go under. The two grids need
// the same per coarse cell, and per fine segment a difference, a square and the force's products
// (docs/string-grids.md, "The strain of a cell"). The summary gives both kernels' cost on A0.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "kernels/kernels.h"
#include "recording_reporter.h"

namespace hamiltone {
namespace {

// A0 of grand-piano at 48 kHz: two grids 43 cells of 8 fine segments, one grid 318 segments.
constexpr long kCells = 43;
constexpr int kRatio = 8;
constexpr long kFine = kCells * kRatio;
constexpr long kSingle = 318;

// Values of a given scale that vary from one index to the next without a pattern the timing
// could depend on.
std::vector<double> wiggle(long n, double scale, double step) {
  std::vector<double> a(n);
  for (long i = 0; i < n; ++i) a[i] = scale * std::sin(step * static_cast<double>(i * i % 97));
  return a;
}

benchmark::Counter perSegment(double segments) {
  return benchmark::Counter(
      segments, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

// The padded displacement of a struck string (mm over a grid of cm): strains of ~1e-3.
std::vector<double> paddedU(long m) {
  std::vector<double> up = wiggle(m + kMaxLanes, 1e-5, 0.7);
  up.front() = 0.0;
  for (long l = m; l < m + kMaxLanes; ++l) up[l] = 0.0;
  return up;
}

void twoGrids(benchmark::State& state, Isa isa) {
  const Kernels& k = kernelsFor(isa);
  const std::vector<double> u = wiggle(kFine - 1, 1e-5, 0.7), v = wiggle(kCells - 1, 1e-6, 1.3);
  std::vector<double> work(twoGridWork(kFine, kCells)), gu(kFine - 1), gv(kCells - 1);
  for (auto _ : state) {
    benchmark::DoNotOptimize(k.twoGridForces(u.data(), v.data(), kCells, kRatio, 100.0, 10.0, 7.0,
                                             600.0, work.data(), gu.data(), gv.data()));
    benchmark::ClobberMemory();
  }
  state.counters["t/segment"] = perSegment(kFine);
}

void singleGrid(benchmark::State& state, Isa isa) {
  const Kernels& k = kernelsFor(isa);
  const std::vector<double> up = paddedU(kSingle), vp = wiggle(kSingle + 1, 1e-6, 1.9);
  std::vector<double> wz(kSingle), we(kSingle), gu(kSingle), gv(kSingle);
  for (auto _ : state) {
    benchmark::DoNotOptimize(k.singleGridForces(up.data(), vp.data(), kSingle, 100.0, 7.0,
                                                wz.data(), we.data(), gu.data(), gv.data()));
    benchmark::ClobberMemory();
  }
  state.counters["t/segment"] = perSegment(kSingle);
}

// The single grid's floor, compiled like the AVX2 kernels (x86-64-v3): what the hardware's divider
// does alone.
#if defined(__x86_64__)
#define FLOOR_TARGET __attribute__((target("arch=x86-64-v3")))
#else
#define FLOOR_TARGET
#endif

FLOOR_TARGET void sqrtAndDivisions(const double* x, double* y, long n) {
#pragma omp simd
  for (long l = 0; l < n; ++l) {
    const double s = __builtin_sqrt(x[l]);
    y[l] = x[l] / (s + 1.0) + 1.0 / s;
  }
}

void floorLoop(benchmark::State& state, long n) {
  std::vector<double> x(n), y(n);
  for (long l = 0; l < n; ++l) x[l] = 1.0 + 1e-3 * static_cast<double>(l % 7);
  for (auto _ : state) {
    sqrtAndDivisions(x.data(), y.data(), n);
    benchmark::DoNotOptimize(y.data());
    benchmark::ClobberMemory();
  }
  state.counters["t/segment"] = perSegment(static_cast<double>(n));
}

std::string name(const char* what, Isa isa) {
  return std::string("Kernel/") + what + "/" + kernelsFor(isa).name;
}

void registerAll() {
  for (Isa isa : {Isa::portable, Isa::avx2, Isa::avx512}) {
    if (!cpuRuns(isa)) continue;
    benchmark::RegisterBenchmark(name("twoGrids", isa).c_str(), &twoGrids, isa);
    benchmark::RegisterBenchmark(name("singleGrid", isa).c_str(), &singleGrid, isa);
  }
#if defined(__x86_64__)
  if (cpuRuns(Isa::avx2))
    benchmark::RegisterBenchmark("Floor/sqrtTwoDivisions/avx2", &floorLoop, kSingle);
#endif
}

void printSummary(const RecordingReporter& reporter) {
  auto nsPerSegment = [&](const std::string& n) {
    const auto* r = reporter.find(n);
    return r == nullptr ? -1.0 : r->counters.at("t/segment").value * 1e9;
  };
  const double floor = nsPerSegment("Floor/sqrtTwoDivisions/avx2");
  const double two = nsPerSegment(name("twoGrids", Isa::avx2));
  const double one = nsPerSegment(name("singleGrid", Isa::avx2));
  if (floor <= 0.0 || two <= 0.0 || one <= 0.0) return;
  std::printf(
      "\nAVX2, ns per fine segment: two grids %.2f (a square root and two divisions per coarse "
      "cell), one grid %.2f (floor: sqrt + 2 divisions per segment %.2f, %.2fx)\n",
      two, one, floor, one / floor);
  std::printf(
      "A0: the two grids' nonlinear step costs %.0f ns over %ld segments, the single grid's %.0f "
      "over %ld\n",
      two * kFine, kFine, one * kSingle, kSingle);
}

}  // namespace
}  // namespace hamiltone

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  hamiltone::registerAll();
  hamiltone::RecordingReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  hamiltone::printSummary(reporter);
  benchmark::Shutdown();
  return 0;
}
