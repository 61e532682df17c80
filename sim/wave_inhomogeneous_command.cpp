// Parses wave-inhomogeneous, runs [M §4.3.2] and writes x, u numerical, u exact at the end.
#include "wave_inhomogeneous_command.h"

#include <CLI/Validators.hpp>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "atomic_file.h"
#include "csv_run.h"
#include "number_arguments.h"
#include "problems/inhomogeneous_wave.h"
#include "schemes/asynchronous_marazzato.h"
#include "schemes/marazzato.h"
#include "usage_error.h"
#include "util/format_number.h"

namespace hamiltone::cli {

CLI::App* addWaveInhomogeneousCommand(CLI::App& app, WaveInhomogeneousArguments& a) {
  CLI::App* wave = app.add_subcommand(
      "wave-inhomogeneous",
      "Inhomogeneous linear wave of [M §4.3.2]: u_tt = (c² u_x)_x on (0, 1), c = 10 for "
      "x <= 0.5 and 1 beyond, fixed ends, finite differences (28); fast nodes x < 0.5, the mixed "
      "node x = 0.5, slow x > 0.5. Asynchronous scheme [M (21)–(25)] with h_S = Δx, h_F = Δx/K.");
  auto number = [&](const char* flag, std::string& value, const char* type, const char* what) {
    addNumberOption(wave, flag, value, type, what);
  };
  number("--dx", a.dx, "METRES",
         "grid step Δx, 1/Δx an even integer from 4 to 1e7 (the interface is a node)");
  number("--ratio", a.ratio, "INT",
         "K = h_S/h_F (>= 10: the CFL bound (16) of the fast part is h_F <= Δx/10)");
  number("--duration", a.duration, "SECONDS",
         "simulated time (0 < T <= 0.5: the exact solution ignores the wall at x = 1)");
  wave->add_option("--quadrature", a.quadrature,
                   "force quadrature; every rule is exact for these linear forces")
      ->check(CLI::IsMember({"midpoint", "gl2", "gl3", "gl5", "lobatto3", "lobatto5"}))
      ->capture_default_str();
  wave->add_option("--start", a.start,
                   "paper: v⁰ as printed, = −u⁰' (the pulse splits 55 % right, 45 % left); "
                   "right-going: v⁰ = −10 u⁰', the case of the paper's exact formula")
      ->check(CLI::IsMember({"paper", "right-going"}))
      ->capture_default_str();
  wave->add_flag("--sync", a.sync, "the synchronous scheme [M (6)] at h_F instead");
  wave->add_flag("--allow-long-run", a.allowLongRun,
                 "start a run estimated to take more than an hour (refused otherwise; the estimate "
                 "is printed)");
  addOutputOption(wave, a.out);
  wave->footer(
      "CSV: x,u,exact at the final time, one row per node including the walls.\n"
      "Summary (name: value lines): time, max displacement error (L∞ at the end), force\n"
      "  evaluations (one spring at one new quadrature node, [M §4.3.1]'s unit), pseudo-energy\n"
      "  drift (max |H̃^n − H̃^0| / H̃^0 over the coarse nodes, (26) or (13) with --sync).\n"
      "Steps: floor(duration / h_S) coarse steps, K steps of h_F each; at most 1e10 steps of h_F\n"
      "  and 1e12 particle steps. A state that becomes non-finite ends the run there, with a\n"
      "  warning; the file then holds that state.\n"
      "Exit codes: 0 done, 1 an I/O error (no file is left), 2 bad input.");
  return wave;
}

namespace {

struct WaveResult {
  double drift = 0.0;
  long evaluations = 0;
  Vector q;
  double time = 0.0;
  bool diverged = false;  // a non-finite state ended the run early
};

// Steps `steps` times, recording the pseudo-energy drift every `every` steps (the coarse nodes),
// and stops at the first non-finite state (q or the pseudo-energy), which is then the result.
template <class Scheme>
WaveResult run(Scheme& scheme, long steps, long every) {
  WaveResult r;
  const double h0 = scheme.energy().total();
  for (long n = 1; n <= steps; ++n) {
    scheme.step();
    if (!scheme.q().allFinite()) {
      r.diverged = true;
      break;
    }
    if (n % every == 0) {
      const double h = scheme.energy().total();
      if (!std::isfinite(h)) {
        r.diverged = true;
        break;
      }
      r.drift = std::max(r.drift, std::abs(h - h0) / std::abs(h0));
    }
  }
  r.evaluations = scheme.forceEvaluations();
  r.q = scheme.q();
  r.time = scheme.time();
  return r;
}

// The most intervals N = 1/Δx: the scheme keeps about a dozen vectors of N doubles (1e7: about
// 1 GB), and the CSV has N + 1 rows of 3 numbers.
constexpr double kMaxIntervals = 1e7;

}  // namespace

int runWaveInhomogeneousCommand(const WaveInhomogeneousArguments& a) {
  const double dx = parseReal("--dx", a.dx, Range::positive, "m");
  const long ratio = parseInteger("--ratio", a.ratio, 1, 1'000'000);
  const double duration = parseReal("--duration", a.duration, Range::positive, "seconds");
  if (duration > 0.5)
    throw UsageError("--duration = " + a.duration +
                     ": expected <= 0.5 s; later the transmitted wave meets the wall at x = 1, "
                     "which the exact solution of [M §4.3.2] leaves out");
  // Output and memory before the model is built: N + 1 rows of 3 numbers, N − 1 particles.
  const double intervals = std::round(1.0 / dx);
  if (!(intervals <= kMaxIntervals))
    throw UsageError("--dx = " + a.dx + ": 1/dx = " + formatApprox(1.0 / dx) +
                     " intervals, expected at most 1e7 (memory and CSV size); use --dx >= 1e-7");
  checkOutputSize(static_cast<long>(intervals), 1, 3, "raise --dx");
  const InhomogeneousWave wave = building([&] {
    try {
      return InhomogeneousWave(dx);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("--" + std::string(e.what()));  // "dx = …" names the flag
    }
  });
  const double hs = dx, hf = dx / static_cast<double>(ratio);
  if (hf > wave.fastStepBound() * (1.0 + 1e-12))
    throw UsageError("--ratio = " + a.ratio + ": h_F = Δx/K = " + formatNumber(hf) +
                     " s breaks the CFL bound (16) of the fast part, h_F <= Δx/c₁ = " +
                     formatNumber(wave.fastStepBound()) + " s; use --ratio >= 10");
  const long coarseSteps = stepCount(duration, hs, "--duration", "--dx (h_S = Δx)");
  const double fineSteps = static_cast<double>(coarseSteps) * static_cast<double>(ratio);
  if (fineSteps > kMaxSteps)
    throw UsageError("--duration / --dx × --ratio = " + formatNumber(fineSteps) +
                     " steps of h_F: expected at most 1e10; coarsen --dx, lower --ratio or "
                     "shorten --duration");
  if (fineSteps * static_cast<double>(wave.size()) > 1e12)
    throw UsageError("--dx = " + a.dx + ", --ratio = " + a.ratio +
                     ": over 1e12 particle steps; coarsen --dx or shorten --duration");
  const WaveStart start = a.start == "paper" ? WaveStart::paper : WaveStart::rightGoing;
  const InitialState initial = waveInitialState(wave, start);
  const QuadratureRule rule = *parseQuadratureRule(a.quadrature);
  // Counted as if every particle took every step of h_F, which the synchronous scheme does and the
  // asynchronous one's slow part does not. Measured (one core, a 2-core Zen 5, midpoint, 1e4 and
  // 1e5 particles): about 2.5e8 such particle-steps a second, sync, and a third more async.
  checkWork(fineSteps * static_cast<double>(wave.size()), "particle-steps of h_F",
            2.5e8 / static_cast<double>(nodesPerInterval(quadrature(rule))), a.allowLongRun,
            "coarsen --dx, lower --ratio or shorten --duration");

  AtomicFile file(a.out, "--out");
  WaveResult r;
  if (a.sync) {
    Marazzato scheme(WholeSystem{wave}, StepParameters{.k = hf}, initial, rule);
    r = run(scheme, coarseSteps * ratio, ratio);
  } else {
    AsynchronousMarazzato scheme(wave, hf, ratio, initial, rule);
    r = run(scheme, coarseSteps, 1);
  }
  std::FILE* out = file.stream();
  std::fprintf(out, "x,u,exact\n");
  double error = 0.0;
  for (Eigen::Index i = 0; i <= wave.intervals(); ++i) {
    const double x = static_cast<double>(i) * dx;
    const double u = (i == 0 || i == wave.intervals()) ? 0.0 : r.q[i - 1];
    const double exact =
        (i == 0 || i == wave.intervals()) ? 0.0 : waveExactDisplacement(x, r.time, start);
    error = std::max(error, std::abs(u - exact));
    std::fprintf(out, "%.17g,%.17g,%.17g\n", x, u, exact);
  }
  file.commit();

  std::printf("wave-inhomogeneous: %s, dx = %s m, h_S = %s s, h_F = %s s, K = %ld, %s; wrote %s\n",
              a.sync ? "synchronous" : "asynchronous", a.dx.c_str(), formatNumber(hs).c_str(),
              formatNumber(hf).c_str(), ratio, a.quadrature.c_str(), a.out.c_str());
  std::printf("time: %.17g\n", r.time);
  std::printf("max displacement error: %.6e\n", error);
  std::printf("force evaluations: %ld\n", r.evaluations);
  std::printf("pseudo-energy drift: %.3e\n", r.drift);
  if (r.diverged)
    std::fprintf(stderr,
                 "hamiltone-sim wave-inhomogeneous: warning: the state became non-finite at "
                 "t = %.17g; the run stopped there, and the file holds that state (see the "
                 "README on the asynchronous scheme's instability; --sync is stable)\n",
                 r.time);
  else if (!std::isfinite(error) || error > 0.1)
    std::fprintf(stderr,
                 "hamiltone-sim wave-inhomogeneous: warning: the error exceeds the pulse's size; "
                 "the asynchronous scheme is unstable here (a resonance of its slow particles' "
                 "2h_S-periodic mode with fast frequencies π/h_S; see the README)\n");
  return 0;
}

}  // namespace hamiltone::cli
