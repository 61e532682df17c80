// Parses the wave subcommand, runs Marazzato's scheme on the [M §3.3] string and writes the
// energies and the midpoint's motion as CSV, and on request the string's shape at given times.
#include "wave_command.h"

#include <CLI/Validators.hpp>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <vector>

#include "atomic_file.h"
#include "csv_run.h"
#include "number_arguments.h"
#include "problems/nonlinear_wave.h"
#include "schemes/variable_step_marazzato.h"
#include "snapshots.h"
#include "usage_error.h"
#include "util/format_number.h"

namespace hamiltone::cli {

namespace {

// Grow the step back after this many accepted steps in a row with gap <= eps_fly H̃ / 4.
constexpr int kGrowAfter = 4;
constexpr double kMinStepFraction = 1.0 / 1024.0;  // default --min-step: k / 2¹⁰

using Scheme = VariableStepMarazzato<NonlinearWave>;

// "0.1,0.5,1" → sorted times in [0, duration].
std::vector<double> parseSnapshotTimes(const std::string& text, double duration) {
  std::vector<double> times;
  size_t begin = 0;
  for (;;) {
    const size_t comma = text.find(',', begin);
    const std::string item = text.substr(begin, comma - begin);
    const double t = parseReal("--snapshots", item, Range::nonNegative, "seconds");
    if (t > duration)
      throw UsageError("--snapshots = " + item + ": after --duration; expected times from 0 to " +
                       formatNumber(duration) + " s");
    times.push_back(t);
    if (comma == std::string::npos) break;
    begin = comma + 1;
  }
  std::sort(times.begin(), times.end());
  times.erase(std::unique(times.begin(), times.end()), times.end());
  return times;
}

// One row per node, the ends included: t,x,u1,u2.
void writeShape(const Scheme& s, std::FILE* f) {
  const NonlinearWave& wave = s.system();
  const int n = wave.nodes();
  for (int j = 0; j <= n + 1; ++j) {
    const bool interior = j >= 1 && j <= n;
    std::fprintf(f, "%.17g", s.time());
    writeNumber(f, j * wave.dx());
    writeNumber(f, interior ? s.q()[j - 1] : 0.0);
    writeNumber(f, interior ? s.q()[n + j - 1] : 0.0);
    std::fputc('\n', f);
  }
}

void writeRow(const Scheme& s, std::FILE* f) {
  const double pseudo = s.pseudoEnergy(), energy = s.discreteEnergy();
  std::fprintf(f, "%.17g", s.time());
  writeNumber(f, s.lastStep());
  writeNumber(f, pseudo);
  writeNumber(f, energy);
  writeNumber(f, energy - pseudo);
  writeNumber(f, s.system().displacement(s.q(), 0, 0.5));
  writeNumber(f, s.system().displacement(s.q(), 1, 0.5));
  std::fputc('\n', f);
}

}  // namespace

CLI::App* addWaveCommand(CLI::App& app, WaveArguments& a) {
  CLI::App* wave = app.add_subcommand(
      "wave",
      "Nonlinear wave equation of Marazzato et al. §3.3: an R²-valued string on [0, 1], fixed "
      "ends, V(u1,u2) = (u1²+u2²)/2 − α(sqrt((1+u1)²+u2²) − (1+u1)), P1 elements with the "
      "consistent mass matrix Δx tridiag(1/6, 2/3, 1/6), on Marazzato's scheme (6). Start "
      "u(x,0) = u0 (sin πx, sin πx), ∂t u(x,0) = 0.");
  wave->add_option("--quadrature", a.quadrature,
                   "force quadrature of the scheme (6), (9); gl2, gl3, gl5 are Gauss–Legendre "
                   "with 2, 3, 5 points (the paper's GL5 is gl3, its GL9 gl5), lobatto3, "
                   "lobatto5 Gauss–Lobatto")
      ->capture_default_str()
      ->check(CLI::IsMember({"midpoint", "gl2", "gl3", "gl5", "lobatto3", "lobatto5"}));
  auto number = [&](const char* flag, std::string& value, const char* type, const char* what) {
    addNumberOption(wave, flag, value, type, what);
  };
  number("--alpha", a.alpha, "NUMBER", "nonlinearity α (0 <= α < 1; 0 is the linear string)");
  number("--amplitude", a.amplitude, "NUMBER", "u0, the amplitude of the start (> 0)");
  number("--dx", a.dx, "NUMBER", "element width; 1/dx must be a whole number from 2 to 1e6");
  number("--k", a.k, "SECONDS",
         "time step (> 0); with --adaptive the first and largest step. Must be below the "
         "linear stability bound dx/√3");
  number("--duration", a.duration, "SECONDS", "simulated time (> 0)");
  number("--every", a.every, "INT", "write every N-th step (>= 1); n = 0 is always written");
  wave->add_flag("--allow-long-run", a.allowLongRun,
                 "start a run estimated to take more than an hour (refused otherwise; the estimate "
                 "is printed)");
  wave->add_flag("--adaptive", a.adaptive,
                 "adapt the step to keep ⅛[p]ᵀM⁻¹[p] <= eps_fly H̃ ([M Remark 8]; see below)");
  number("--eps-fly", a.epsFly, "NUMBER",
         "with --adaptive (only): its bound (> 0; the paper's 0.03 %)");
  number("--min-step", a.minStep, "SECONDS",
         "with --adaptive (only): the run fails rather than use a smaller step (> 0, <= k; default "
         "k/1024)");
  wave->add_option("--snapshots", a.snapshots,
                   "comma-separated times (0 to --duration) at which to write the shape")
      ->type_name("T1,T2,...");
  wave->add_option("--snapshot-out", a.snapshotOut,
                   "CSV file for --snapshots (needed with it): t,x,u1,u2, one row per node")
      ->type_name("PATH");
  addOutputOption(wave, a.out);
  // Whether --eps-fly and --min-step were typed at all (an empty value included), for the check
  // that they come with --adaptive.
  wave->parse_complete_callback([wave, &a] {
    a.epsFlyGiven = wave->count("--eps-fly") > 0;
    a.minStepGiven = wave->count("--min-step") > 0;
  });
  wave->footer(
      "CSV: a header, then one row per written step n: t,h,pseudo_energy,energy,gap,u1_mid,"
      "u2_mid.\n"
      "  t = t^n; h = t^n − t^{n−1}, the step that reached t^n (0 at n = 0); pseudo_energy is\n"
      "  H̃^n of (13) = V(q^n) + ½ p^{n−½}·M⁻¹p^{n+½}; energy is H^n of (17); gap = H^n − H̃^n\n"
      "  = ⅛[p]ᵀM⁻¹[p] >= 0 (18); u1_mid, u2_mid = u(0.5, t^n).\n"
      "Snapshots: t,x,u1,u2 at every node (ends included) at the first step at or after each\n"
      "  requested time (the last step for a time past it).\n"
      "--adaptive [M Remark 8]: a step whose jump [p] = p^{n+3/2} − p^{n+½} breaks\n"
      "  ⅛[p]ᵀM⁻¹[p] <= eps_fly H̃^{n+1} is discarded and redone from the same state with half\n"
      "  the step (H̃ is conserved for any step sequence, Theorem 1, so nothing is lost). After\n"
      "  4 accepted steps in a row with the gap <= eps_fly H̃ / 4 the step doubles, at most to\n"
      "  --k. A step below --min-step ends the run with exit code 2 (the parameters cannot run)\n"
      "  and no file. The run stops at the last step at or before --duration.\n"
      "Summary: 'name: value' lines: steps, rejected steps, force evaluations, the start's\n"
      "  pseudo-energy, its max relative and absolute drift, the min and max step, and with\n"
      "  --adaptive the max of gap / (eps_fly H̃).\n" +
      std::string(kRunFooter));
  return wave;
}

int runWaveCommand(const WaveArguments& a) {
  const double alpha = parseReal("--alpha", a.alpha, Range::nonNegative);
  if (alpha >= 1.0)
    throw UsageError("--alpha = " + a.alpha + ": out of range; expected 0 <= alpha < 1");
  const double amplitude = parseReal("--amplitude", a.amplitude, Range::positive);
  const double dx = parseReal("--dx", a.dx, Range::positive);
  const double elements = std::round(1.0 / dx);
  if (!(elements >= 2.0 && elements <= 1e6) || std::abs(elements * dx - 1.0) > 1e-9)
    throw UsageError("--dx = " + a.dx +
                     ": 1/dx must be a whole number from 2 to 1000000 (e.g. 0.01, 0.005)");
  const double k = parseReal("--k", a.k, Range::positive, "seconds");
  // The stability bound of the scheme (6) on this string. Linearised with stiffness matrix K and
  // an exact quadrature (any rule integrates a linear force exactly), (6) is the recurrence
  // (z + 1)(z² + (k²ω² − 2) z + 1) = 0 per mode ω² of M⁻¹K: the leapfrog's roots and the
  // parasitic −1, bounded iff k ω < 2. V's Hessian has the eigenvalues 1 (along (1 + u1, u2))
  // and 1 − α/|(1 + u1, u2)| (1 − α at rest), so no wave is faster than c = 1 and the largest ω
  // is that of the c = 1 string: with P1 elements and the consistent mass Δx tridiag(1/6, 2/3,
  // 1/6), ω² = 4s / (Δx² (1 − 2s/3)), s = sin²(θ/2) → 1 at the top mode, ω_max → √12/Δx, so
  // k < Δx/√3. That is necessary near rest, where u1 waves travel at exactly c = 1 (the finite
  // grid's top mode has s = cos²(πΔx/2), which moves the exact bound up by a relative 1.5
  // (πΔx/2)², 4e-4 at Δx = 0.01: measured stable at 0.005774, diverging at 0.005776, for α = 0).
  // It is not sufficient far from rest: the paper's largest working step at α = 0.99 was found
  // empirically (0.0055 at Δx = 0.01), and such runs are the divergence warning's business. The
  // adaptive run starts at --k, so the bound holds there too.
  const double stableBelow = dx / std::sqrt(3.0);
  if (!(k < stableBelow))
    throw UsageError("--k = " + a.k +
                     ": at or above the stability bound --dx/√3 = " + formatNumber(stableBelow) +
                     " s for --dx = " + a.dx + "; expected a smaller step (or a larger --dx)");
  const double duration = parseReal("--duration", a.duration, Range::positive, "seconds");
  const long every = parseInteger("--every", a.every, 1);
  const long steps = stepCount(duration, k);  // the fixed step's count; bounds the adaptive run
  checkOutputSize(steps, every, 7);
  // Each step evaluates every element's force at each quadrature node; an adaptive run takes at
  // least the fixed run's steps (its step never exceeds --k). Measured: about 3e7 element-steps a
  // second at one node (midpoint, 1000 elements).
  const double nodes =
      static_cast<double>(nodesPerInterval(quadrature(*parseQuadratureRule(a.quadrature))));
  checkWork(static_cast<double>(steps) * elements, "element-steps", 3e7 / nodes, a.allowLongRun,
            "shorten --duration, raise --k or --dx");
  AdaptiveStep adaptive{.enabled = a.adaptive, .growAfter = kGrowAfter};
  if (!a.adaptive) {
    if (a.epsFlyGiven)
      throw UsageError("--eps-fly = '" + a.epsFly +
                       "': needs --adaptive (it bounds the adaptive step); give both or neither");
    if (a.minStepGiven)
      throw UsageError("--min-step = '" + a.minStep +
                       "': needs --adaptive (the smallest adaptive step); give both or neither");
  } else {
    // An empty value, given, is refused as not a number rather than taken as the default.
    adaptive.epsilonFly = parseReal("--eps-fly", a.epsFly, Range::positive);
    adaptive.minStep = a.minStepGiven
                           ? parseReal("--min-step", a.minStep, Range::positive, "seconds")
                           : k * kMinStepFraction;
    if (adaptive.minStep > k)
      throw UsageError("--min-step = " + a.minStep +
                       ": out of range; expected at most --k = " + a.k + " s");
  }
  checkSnapshotFlags(a.snapshots, a.snapshotOut, a.out);
  std::vector<double> snapshots;
  if (!a.snapshots.empty()) snapshots = parseSnapshotTimes(a.snapshots, duration);

  const NonlinearWave wave =
      building([&] { return NonlinearWave(alpha, static_cast<int>(elements)); });
  Scheme scheme = building([&] {
    return Scheme(wave, k, nonlinearWaveInitialState(wave, amplitude),
                  *parseQuadratureRule(a.quadrature), adaptive);
  });
  const double start = scheme.pseudoEnergy();
  if (!std::isfinite(start))
    throw UsageError("the start's pseudo-energy is " + formatApprox(start) +
                     ": --amplitude is too large for double precision");
  // H̃⁰ = V(q⁰) >= 0. At 0 or below the normal doubles (a tiny --amplitude) there is no energy
  // to measure drift against; the adaptive bound gap <= eps_fly H̃ cannot hold there at all.
  const bool hasEnergy = std::isnormal(start);
  if (a.adaptive && !hasEnergy)
    throw UsageError("--amplitude = " + a.amplitude + ": the start's pseudo-energy is " +
                     formatNumber(start) +
                     ", too small for --adaptive's bound gap <= eps_fly H̃; expected a larger "
                     "--amplitude");

  AtomicFile file(a.out, "--out");
  std::unique_ptr<AtomicFile> shapes;
  if (!snapshots.empty()) {
    shapes = std::make_unique<AtomicFile>(a.snapshotOut, "--snapshot-out");
    std::fprintf(shapes->stream(), "t,x,u1,u2\n");
  }
  std::fprintf(file.stream(), "t,h,pseudo_energy,energy,gap,u1_mid,u2_mid\n");

  size_t nextSnapshot = 0;
  long rows = 0;
  double maxDrift = 0.0, maxGap = 0.0;
  bool diverged = false;
  // Times are sums of steps: a requested time is reached when within rounding of t^n.
  const double slack = 1e-9 * k;
  for (;;) {
    const double t = scheme.time();
    const double pseudo = scheme.pseudoEnergy();
    diverged = !std::isfinite(pseudo) || !scheme.q().allFinite();
    if (scheme.stepIndex() % every == 0 || diverged) {
      writeRow(scheme, file.stream());
      if (++rows % 4096 == 0 && std::ferror(file.stream()))
        throw std::runtime_error("writing the output failed: " + std::string(std::strerror(errno)));
    }
    if (diverged) break;
    maxDrift = std::max(maxDrift, std::abs(pseudo - start));
    if (hasEnergy) maxGap = std::max(maxGap, (scheme.discreteEnergy() - pseudo) / pseudo);
    for (; nextSnapshot < snapshots.size() && snapshots[nextSnapshot] <= t + slack; ++nextSnapshot)
      writeShape(scheme, shapes->stream());
    const bool done =
        a.adaptive ? t + scheme.nextStep() > duration + slack : scheme.stepIndex() == steps;
    if (done) break;
    if (!scheme.step())
      throw UsageError("--adaptive: at t = " + formatNumber(t) +
                       " s the bound ⅛[p]ᵀM⁻¹[p] <= eps_fly H̃ " +
                       "needs a step below --min-step = " + formatNumber(adaptive.minStep) +
                       " s; no file written. Raise --eps-fly or lower --min-step");
  }
  if (shapes)
    for (; nextSnapshot < snapshots.size(); ++nextSnapshot) writeShape(scheme, shapes->stream());
  commitTogether({&file, shapes.get()});  // both files or neither

  std::printf(
      "wave: marazzato (6), %s, alpha = %s, amplitude = %s, dx = %s (%d nodes per "
      "direction), k = %s s%s; wrote %s (%ld rows)\n",
      a.quadrature.c_str(), a.alpha.c_str(), a.amplitude.c_str(), a.dx.c_str(), wave.nodes(),
      a.k.c_str(), a.adaptive ? ", adaptive" : "", a.out.c_str(), rows);
  std::printf("steps: %ld\n", scheme.stepIndex());
  std::printf("rejected steps: %ld\n", scheme.rejectedSteps());
  std::printf("force evaluations: %ld\n", scheme.forceEvaluations());
  std::printf("pseudo-energy at t = 0: %.17g\n", start);
  if (hasEnergy)
    std::printf("max relative pseudo-energy drift: %.6g\n", maxDrift / std::abs(start));
  else
    std::printf("max relative pseudo-energy drift: no energy to drift\n");
  std::printf("max absolute pseudo-energy drift: %.6g\n", maxDrift);
  if (hasEnergy)
    std::printf("max gap / pseudo-energy: %.6g\n", maxGap);
  else
    std::printf("max gap / pseudo-energy: no energy to drift\n");
  if (scheme.stepIndex() > 0) {
    std::printf("min step: %.17g\n", scheme.minStepUsed());
    std::printf("max step: %.17g\n", scheme.maxStepUsed());
  }
  if (a.adaptive) std::printf("max gap / (eps_fly pseudo-energy): %.6g\n", scheme.worstGapRatio());
  if (shapes)
    std::printf("snapshots: wrote %s (%zu times)\n", a.snapshotOut.c_str(), snapshots.size());
  if (diverged)
    std::fprintf(stderr,
                 "hamiltone-sim wave: warning: the state became non-finite at t = %.17g; the run "
                 "stopped there, and the file ends with that row\n",
                 scheme.time());
  return 0;
}

}  // namespace hamiltone::cli
