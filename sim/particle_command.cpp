// Parses the particle subcommand, runs Marazzato's scheme on the [M §3.1] particle and writes
// its CSV beside the exact solution.
#include "particle_command.h"

#include <CLI/Validators.hpp>
#include <cmath>
#include <cstdio>

#include "atomic_file.h"
#include "csv_run.h"
#include "number_arguments.h"
#include "problems/particle.h"
#include "schemes/marazzato.h"

namespace hamiltone::cli {

CLI::App* addParticleCommand(CLI::App& app, ParticleArguments& a) {
  CLI::App* particle = app.add_subcommand(
      "particle",
      "Single particle of Marazzato et al. §3.1: unit mass, V(q) = 8((q−1)² − (q−1)^{3/2}) (the "
      "paper's sign flipped), exact solution q(t) = sin⁴t + 1. Start at t0 = π/2: q = 2, p = 0.");
  particle
      ->add_option("--quadrature", a.quadrature,
                   "force quadrature of Marazzato's scheme (22); gl2, gl3, gl5 are "
                   "Gauss–Legendre, lobatto3, lobatto5 Gauss–Lobatto")
      ->capture_default_str()
      ->check(CLI::IsMember({"midpoint", "gl2", "gl3", "gl5", "lobatto3", "lobatto5"}));
  auto number = [&](const char* flag, std::string& value, const char* type, const char* what) {
    addNumberOption(particle, flag, value, type, what);
  };
  number("--k", a.k, "SECONDS", "time step (> 0)");
  number("--duration", a.duration, "SECONDS", "simulated time after t0 (> 0)");
  number("--every", a.every, "INT", "write every N-th step (>= 1); n = 0 is always written");
  addOutputOption(particle, a.out);
  particle->footer(
      "CSV: a header, then one row per written step n: t,q,p,q_exact,error,energy,kinetic,"
      "potential.\n"
      "  t = n k is the time since t0 = π/2; q = q^n, p = ½(p^{n−½} + p^{n+½}),\n"
      "  q_exact = sin⁴(t0 + t) + 1, error = q − q_exact. energy is the pseudo-energy (13):\n"
      "  kinetic = ½ p^{n−½} p^{n+½}, potential = V(q^n); the exact energy is 0.\n"
      "  The error is second order in k up to a duration of π/2 (t0 + t = π), where the orbit\n"
      "  touches q = 1 and the force ∝ (q−1)^{1/2} is not Lipschitz; runs past it converge\n"
      "  like k^{1/3} only.\n" +
      std::string(kRunFooter));
  return particle;
}

int runParticleCommand(const ParticleArguments& a) {
  const double k = parseReal("--k", a.k, Range::positive, "seconds");
  const double duration = parseReal("--duration", a.duration, Range::positive, "seconds");
  const long every = parseInteger("--every", a.every, 1);
  const long steps = stepCount(duration, k);
  checkOutputSize(steps, every, 8);

  Marazzato scheme(Particle(), {.k = k}, particleInitialState(),
                   *parseQuadratureRule(a.quadrature));
  AtomicFile file(a.out, "--out");
  std::fprintf(file.stream(), "t,q,p,q_exact,error,energy,kinetic,potential\n");
  const RunSummary summary = runToCsv(
      scheme, steps, every, file.stream(),
      [](const Marazzato<Particle>& s, const Energy& e, std::FILE* f) {
        const double exact = Particle::exactPosition(Particle::startTime + s.time());
        writeNumber(f, s.q()[0]);
        writeNumber(f, 0.5 * (s.pPrevious()[0] + s.p()[0]));
        writeNumber(f, exact);
        writeNumber(f, s.q()[0] - exact);
        writeNumber(f, e.total());
        writeNumber(f, e.kinetic);
        writeNumber(f, e.potential);
      },
      "the fixed start (q = 2, p = 0) is");
  file.commit();

  printSummary("particle", "marazzato, " + a.quadrature + ", k = " + a.k + " s", a.out, summary);
  return 0;
}

}  // namespace hamiltone::cli
