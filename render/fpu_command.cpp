// Parses the fpu subcommand, builds the chosen scheme over the FPU chain and writes its CSV.
#include "fpu_command.h"

#include <CLI/Validators.hpp>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "atomic_file.h"
#include "csv_run.h"
#include "models/fpu.h"
#include "number_arguments.h"
#include "schemes/marazzato.h"
#include "schemes/sav.h"
#include "schemes/stormer_verlet.h"
#include "usage_error.h"

namespace hamiltone::cli {

CLI::App* addFpuCommand(CLI::App& app, FpuArguments& a) {
  CLI::App* fpu = app.add_subcommand(
      "fpu",
      "Fermi–Pasta–Ulam chain (BDZ (52), split (53)): 2M unit masses, alternating linear springs "
      "(ω²/2) and quartic springs, fixed ends. Start q(0) = α e₄, p(0) = 0.");
  fpu->add_option("--scheme", a.scheme,
                  "sv: Störmer–Verlet (20); sav: explicit SAV (27); sav-split: split-potential "
                  "SAV (38), needs k <= 2/ω (54); marazzato: Marazzato et al. (22)")
      ->required()
      ->check(CLI::IsMember({"sv", "sav", "sav-split", "marazzato"}));
  fpu->add_option("--quadrature", a.quadrature,
                  "force quadrature of marazzato (default midpoint); gl2, gl3, gl5 are "
                  "Gauss–Legendre, lobatto3, lobatto5 Gauss–Lobatto")
      ->check(CLI::IsMember({"midpoint", "gl2", "gl3", "gl5", "lobatto3", "lobatto5"}));
  // Numbers are taken as text and parsed strictly by runFpuCommand, whose messages say what
  // is valid.
  auto number = [&](const char* flag, std::string& value, const char* type, const char* what) {
    addNumberOption(fpu, flag, value, type, what);
  };
  number("--k", a.k, "SECONDS", "time step (> 0)");
  number("--duration", a.duration, "SECONDS", "simulated time (> 0)");
  number("--alpha", a.alpha, "NUMBER", "initial displacement of coordinate 4");
  number("--omega", a.omega, "RAD/S", "linear spring frequency ω (> 0)");
  number("--pairs", a.pairs, "INT", "number of pairs M (>= 2; N = 2M masses)");
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
      "  With loss, energy + dissipated energy is what stays constant (50).\n" +
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

template <class Scheme>
RunSummary simulate(Scheme scheme, const FpuRun& run, std::FILE* out) {
  std::fprintf(out, "t");
  for (Eigen::Index i = 1; i <= run.chain.size(); ++i)
    std::fprintf(out, ",q%ld", static_cast<long>(i));
  std::fprintf(out, ",energy,kinetic,potential\n");
  return runToCsv(
      scheme, run.steps, run.every, out,
      [](const Scheme& s, const Energy& e, std::FILE* f) {
        for (double x : s.q()) writeNumber(f, x);
        writeNumber(f, e.total());
        writeNumber(f, e.kinetic);
        writeNumber(f, e.potential);
      },
      "--alpha, --omega or --epsilon is");
}

}  // namespace

int runFpuCommand(const FpuArguments& a) {
  const double k = parseReal("--k", a.k, Range::positive, "seconds");
  const double duration = parseReal("--duration", a.duration, Range::positive, "seconds");
  const double alpha = parseReal("--alpha", a.alpha, Range::any);
  const double omega = parseReal("--omega", a.omega, Range::positive, "rad/s");
  const long pairs = parseInteger("--pairs", a.pairs, 2, 1'000'000);
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
