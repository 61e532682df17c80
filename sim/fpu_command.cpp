// Parses the fpu subcommand, builds the chosen scheme over the FPU chain and writes its CSV.
#include "fpu_command.h"

#include <CLI/Validators.hpp>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "atomic_file.h"
#include "csv_run.h"
#include "number_arguments.h"
#include "problems/fpu.h"
#include "problems/slow_fast_fpu.h"
#include "schemes/asynchronous_marazzato.h"
#include "schemes/marazzato.h"
#include "schemes/sav.h"
#include "schemes/stormer_verlet.h"
#include "usage_error.h"
#include "util/format_number.h"

namespace hamiltone::cli {

CLI::App* addFpuCommand(CLI::App& app, FpuArguments& a) {
  CLI::App* fpu = app.add_subcommand(
      "fpu",
      "Fermi–Pasta–Ulam chain (BDZ (52), split (53)): 2M unit masses, alternating linear springs "
      "(ω²/2) and quartic springs, fixed ends. Start q(0) = α e₄, p(0) = 0.");
  fpu->add_option("--scheme", a.scheme,
                  "sv: Störmer–Verlet (20); sav: explicit SAV (27); sav-split: split-potential "
                  "SAV (38), needs k <= 2/ω (54); marazzato: Marazzato et al. (22)")
      ->check(CLI::IsMember({"sv", "sav", "sav-split", "marazzato"}));
  a.command = fpu;
  fpu->add_flag("--slow-fast", a.slowFast,
                "the slow/fast chain of [M §4.3.1] (m linear springs, then m + 1 quartic ones) on "
                "the asynchronous scheme [M (21)–(25)], steps --hs and --hf; replaces --scheme");
  fpu->add_flag("--allow-long-run", a.allowLongRun,
                "start a run estimated to take more than an hour (refused otherwise; the estimate "
                "is printed)");
  fpu->add_flag("--sync", a.sync,
                "with --slow-fast: the synchronous scheme [M (6)] at h_F on the same chain");
  fpu->add_option("--quadrature", a.quadrature,
                  "force quadrature of marazzato (default midpoint) and --slow-fast (default "
                  "lobatto5); gl2, gl3, gl5 are Gauss–Legendre, lobatto3, lobatto5 Gauss–Lobatto")
      ->check(CLI::IsMember({"midpoint", "gl2", "gl3", "gl5", "lobatto3", "lobatto5"}));
  // Numbers are taken as text and parsed strictly by runFpuCommand, whose messages say what
  // is valid.
  auto number = [&](const char* flag, std::string& value, const char* type, const char* what) {
    addNumberOption(fpu, flag, value, type, what);
  };
  number("--k", a.k, "SECONDS", "time step (> 0)");
  number("--duration", a.duration, "SECONDS", "simulated time (> 0)");
  number("--alpha", a.alpha, "NUMBER", "initial displacement of coordinate 4");
  number("--omega", a.omega, "RAD/S",
         "linear spring frequency ω (> 0; default 50, with --slow-fast √10: ω² = 10)");
  number("--pairs", a.pairs, "INT",
         "number of pairs M (2 … 1e6; N = 2M masses, a CSV row of 2M + 4 numbers); with "
         "--slow-fast the paper's m (2 … 1e6)");
  number("--hs", a.hs, "SECONDS",
         "--slow-fast: coarse step h_S, an integer multiple K (1 … 1e9) of --hf");
  number("--hf", a.hf, "SECONDS", "--slow-fast: fine step h_F (> 0), within the CFL bound (16)");
  number("--epsilon", a.epsilon, "JOULES", "gauge shift ε of sav, sav-split, §2.5 (>= 0)");
  number("--sigma0", a.sigma0, "1/S",
         "mass-proportional loss σ0, force −2σ0 M q' (>= 0; sv, sav, sav-split)");
  number("--every", a.every, "INT", "write every N-th step (>= 1); n = 0 is always written");
  addOutputOption(fpu, a.out);
  fpu->footer(
      "CSV: a header, then one row per written step n: t,q1..qN,energy,kinetic,potential.\n"
      "  t = n k and q = q^n. For sv, sav, sav-split the energy is that of the interval\n"
      "  [t^n, t^{n+1}]: H^{n+1/2} of (41) [(36) for sav], kinetic = ½|q^{n+1}−q^n|²/k²,\n"
      "  potential = ½ q^{n+1}·K q^n + ½ψ² − ε (sv: ψ = 0 plus V'(q^n)). For marazzato it is\n"
      "  the pseudo-energy (13) at t^n: kinetic = ½ p^{n−½}·p^{n+½}, potential = V(q^n).\n"
      "  With loss, energy + dissipated energy is what stays constant (50).\n"
      "--slow-fast: rows at the coarse nodes t = n h_S (--sync: t = n h_F), energy = the\n"
      "  pseudo-energy (26) [(13) with --sync]; the start is q(0) = α e_{m+1}, p(0) = 0. The\n"
      "  summary adds the counted force evaluations (one spring at one new quadrature node)\n"
      "  and [M §4.3.1]'s N_s, N_a and η = N_a / N_s for the same run. At most 1e10 steps of\n"
      "  h_F (duration/h_S × K) and 1e12 particle steps (h_F steps of the m fast and mixed\n"
      "  particles, h_S steps of the m slow ones; all 2m at h_F with --sync).\n" +
      std::string(kRunFooter));
  return fpu;
}

namespace {

struct FpuRun {
  FermiPastaUlam chain;
  InitialState start;
  StepParameters params;
  long steps;
  long every;
};

// Writes the CSV of `steps` steps of a scheme over `size` coordinates; the scheme is stepped in
// place, so the caller may read its counters afterwards.
template <class Scheme>
RunSummary simulate(Scheme& scheme, Eigen::Index size, long steps, long every, std::FILE* out) {
  std::fprintf(out, "t");
  for (Eigen::Index i = 1; i <= size; ++i) std::fprintf(out, ",q%ld", static_cast<long>(i));
  std::fprintf(out, ",energy,kinetic,potential\n");
  return runToCsv(
      scheme, steps, every, out,
      [](const Scheme& s, const Energy& e, std::FILE* f) {
        for (double x : s.q()) writeNumber(f, x);
        writeNumber(f, e.total());
        writeNumber(f, e.kinetic);
        writeNumber(f, e.potential);
      },
      "--alpha, --omega or --epsilon is");
}

template <class Scheme>
RunSummary simulate(Scheme scheme, const FpuRun& run, std::FILE* out) {
  return simulate(scheme, run.chain.size(), run.steps, run.every, out);
}

// Whether `flag` was on the command line, whatever its text (an empty one included).
bool given(const FpuArguments& a, const char* flag) {
  return a.command != nullptr && a.command->count(flag) > 0;
}

// ω, or `fallback` when --omega is not given; refused where ω² is not a positive finite double
// (the springs' stiffness ω²/2 and every bound derived from it would be 0, inf or NaN).
double parseOmega(const FpuArguments& a, double fallback) {
  if (!given(a, "--omega")) return fallback;
  const double omega = parseReal("--omega", a.omega, Range::positive, "rad/s");
  const double square = omega * omega;
  if (!std::isfinite(square) || square == 0.0)
    throw UsageError("--omega = " + a.omega +
                     ": ω² must be a finite number > 0 in double precision; expected ω from "
                     "about 1e-154 to 1e154 rad/s");
  return omega;
}

// `fpu --slow-fast`: [M §4.3.1] on AsynchronousMarazzato, or Marazzato at h_F with --sync.
int runSlowFast(const FpuArguments& a) {
  if (!a.scheme.empty())
    throw UsageError("--scheme = " + a.scheme +
                     ": --slow-fast runs its own schemes; drop --scheme");
  if (given(a, "--k")) throw UsageError("--k = " + a.k + ": with --slow-fast use --hs and --hf");
  if (given(a, "--epsilon") || given(a, "--sigma0"))
    throw UsageError("--epsilon / --sigma0: not used by --slow-fast (lossless, no SAV)");
  const double hs = parseReal("--hs", a.hs, Range::positive, "seconds");
  const double hf = parseReal("--hf", a.hf, Range::positive, "seconds");
  const double duration = parseReal("--duration", a.duration, Range::positive, "seconds");
  const double alpha = parseReal("--alpha", a.alpha, Range::any);
  const double omega = parseOmega(a, std::sqrt(10.0));
  const long pairs = parseInteger("--pairs", a.pairs, 2, 1'000'000);
  const long every = parseInteger("--every", a.every, 1);
  const double quotient = hs / hf;
  if (!(quotient <= 1e9 + 0.5))
    throw UsageError("--hs / --hf = " + formatNumber(quotient) +
                     ": K = h_S / h_F must be at most 1e9");
  const double ratio = std::round(quotient);
  if (ratio < 1.0 || std::abs(quotient - ratio) > 1e-9 * ratio)
    throw UsageError("--hs / --hf = " + formatNumber(quotient) +
                     ": h_S must be an integer multiple K >= 1 of h_F");
  const long k = static_cast<long>(ratio);
  const QuadratureRule rule =
      a.quadrature.empty() ? QuadratureRule::lobatto5 : *parseQuadratureRule(a.quadrature);
  const SlowFastFermiPastaUlam chain =
      building([&] { return SlowFastFermiPastaUlam(static_cast<int>(pairs), omega); });
  const double bound = 2.0 / std::sqrt(chain.fastEigenvalueMax());
  if (hf >= bound)
    throw UsageError("--hf = " + a.hf + ": the CFL bound (16) of the linear springs is h_F < " +
                     formatNumber(bound) + " s");
  const long coarseSteps = stepCount(duration, hs, "--duration", "--hs");
  // Both schemes take K steps of h_F per coarse step: count them (and the particle steps) in
  // double, where they cannot overflow, before any is taken.
  const double fineSteps = static_cast<double>(coarseSteps) * ratio;
  if (fineSteps > kMaxSteps)
    throw UsageError("--duration / --hf = " + formatNumber(fineSteps) +
                     " steps of h_F (K = --hs / --hf = " + std::to_string(k) +
                     " per coarse step): expected at most 1e10; shorten --duration or raise --hf");
  const double m = static_cast<double>(pairs);
  const double particleSteps = a.sync ? fineSteps * 2.0 * m : fineSteps * m + coarseSteps * m;
  if (particleSteps > 1e12)
    throw UsageError("--pairs = " + a.pairs + ", --duration = " + a.duration +
                     ", --hs / --hf = " + std::to_string(k) + ": " + formatNumber(particleSteps) +
                     " particle steps, expected at most 1e12; lower --pairs, shorten --duration "
                     "or raise --hf");
  const long steps = a.sync ? coarseSteps * k : coarseSteps;
  checkOutputSize(steps, every, 2 * pairs + 4);
  const InitialState start = building([&] { return slowFastInitialState(chain, alpha); });

  AtomicFile file(a.out, "--out");
  RunSummary summary;
  long evaluations = 0;
  if (a.sync) {
    Marazzato scheme(WholeSystem{chain}, StepParameters{.k = hf}, start, rule);
    summary = simulate(scheme, chain.size(), steps, every, file.stream());
    evaluations = scheme.forceEvaluations();
  } else {
    AsynchronousMarazzato scheme(chain, hf, k, start, rule);
    summary = simulate(scheme, chain.size(), steps, every, file.stream());
    evaluations = scheme.forceEvaluations();
  }
  file.commit();

  printSummary("fpu",
               std::string(a.sync ? "synchronous" : "asynchronous") + " slow/fast, " +
                   std::to_string(pairs) + " pairs, h_S = " + a.hs + " s, h_F = " + a.hf +
                   " s, K = " + std::to_string(k),
               a.out, summary);
  // [M §4.3.1]: N_s = (n−1) T (2m+1)/h_F, N_a = (n−1) T ((m+1)/h_F + m/h_S), T = the run's.
  const double nodes = static_cast<double>(nodesPerInterval(quadrature(rule)));
  const double t = static_cast<double>(coarseSteps) * hs;
  const double ns = nodes * t * (2.0 * m + 1.0) / hf, na = nodes * t * ((m + 1.0) / hf + m / hs);
  std::printf("force evaluations: %ld\n", evaluations);
  std::printf("paper N_s: %.17g\npaper N_a: %.17g\n", ns, na);
  std::printf("paper eta: %.17g\n", (1.0 + m / ((m + 1.0) * ratio)) / (1.0 + m / (m + 1.0)));
  return 0;
}

}  // namespace

int runFpuCommand(const FpuArguments& a) {
  if (a.slowFast) return runSlowFast(a);
  if (a.sync) throw UsageError("--sync: applies to --slow-fast only");
  if (a.scheme.empty()) throw UsageError("--scheme is required (or --slow-fast)");
  const double k = parseReal("--k", a.k, Range::positive, "seconds");
  const double duration = parseReal("--duration", a.duration, Range::positive, "seconds");
  const double alpha = parseReal("--alpha", a.alpha, Range::any);
  const double omega = parseOmega(a, 50.0);
  const long pairs = parseInteger("--pairs", a.pairs, 2, 1'000'000);
  if (given(a, "--hs") || given(a, "--hf"))
    throw UsageError("--hs / --hf: apply to --slow-fast only; use --k");
  const double epsilon = parseReal("--epsilon", a.epsilon, Range::nonNegative, "J");
  const double sigma0 = parseReal("--sigma0", a.sigma0, Range::nonNegative, "1/s");
  const long every = parseInteger("--every", a.every, 1);
  if (!a.quadrature.empty() && a.scheme != "marazzato")
    throw UsageError("--quadrature = " + a.quadrature + ": applies to --scheme marazzato only");
  if (epsilon != 0.0 && (a.scheme == "sv" || a.scheme == "marazzato"))
    throw UsageError("--epsilon = " + a.epsilon +
                     ": the gauge shift applies to --scheme sav or sav-split only");
  if (sigma0 != 0.0 && a.scheme == "marazzato")
    throw UsageError("--sigma0 = " + a.sigma0 +
                     ": marazzato is lossless; use sv, sav or sav-split");
  const long steps = stepCount(duration, k);
  checkOutputSize(steps, every, 2 * pairs + 4);
  // A step moves 2M particles (a Marazzato step evaluates the forces at each quadrature node).
  // Measured: 3e8 particle-steps a second for sv, sav and sav-split at 2e4 particles.
  const double nodes = a.scheme != "marazzato"
                           ? 1.0
                           : static_cast<double>(nodesPerInterval(quadrature(
                                 a.quadrature.empty() ? QuadratureRule::midpoint
                                                      : *parseQuadratureRule(a.quadrature))));
  checkWork(static_cast<double>(steps) * 2.0 * static_cast<double>(pairs), "particle-steps",
            3e8 / nodes, a.allowLongRun, "shorten --duration, raise --k or lower --pairs");

  FpuRun run{building([&] { return FermiPastaUlam(static_cast<int>(pairs), omega); }),
             {},
             {.k = k, .sigma0 = sigma0, .epsilon = epsilon},
             steps,
             every};
  run.start = building([&] { return fpuInitialState(run.chain, alpha); });

  AtomicFile file(a.out, "--out");
  RunSummary summary;
  if (a.scheme == "sv") {
    summary = simulate(building([&] { return StormerVerlet(run.chain, run.params, run.start); }),
                       run, file.stream());
  } else if (a.scheme == "sav") {
    summary = simulate(
        building([&] { return NonSplitSav<FermiPastaUlam>(run.chain, run.params, run.start); }),
        run, file.stream());
  } else if (a.scheme == "sav-split") {
    summary = simulate(
        building([&] { return SplitSav<FermiPastaUlam>(run.chain, run.params, run.start); }), run,
        file.stream());
  } else {
    const QuadratureRule rule =
        a.quadrature.empty() ? QuadratureRule::midpoint : *parseQuadratureRule(a.quadrature);
    summary = simulate(building([&] { return Marazzato(run.chain, run.params, run.start, rule); }),
                       run, file.stream());
  }
  file.commit();

  printSummary("fpu", a.scheme + ", " + std::to_string(pairs) + " pairs, k = " + a.k + " s", a.out,
               summary);
  return 0;
}

}  // namespace hamiltone::cli
