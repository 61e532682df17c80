// Parses the string subcommand, builds the string (and hammer) on the chosen grid and writes CSV.
#include "string_command.h"

#include <CLI/Validators.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>
#include <type_traits>
#include <vector>

#include "atomic_file.h"
#include "csv_run.h"
#include "instruments/hammer.h"
#include "instruments/string.h"
#include "number_arguments.h"
#include "schemes/reference/discrete_gradient_string.h"
#include "schemes/sav.h"
#include "schemes/stormer_verlet.h"
#include "snapshots.h"

namespace hamiltone::cli {

CLI::App* addStringCommand(CLI::App& app, StringArguments& a) {
  CLI::App* cmd = app.add_subcommand(
      "string",
      "Geometrically exact string (BDZ (56), split (65)), transverse u and longitudinal v, fixed "
      "ends. Start (70): u = α sqrt(A) sin(πx/L), v = 0, at rest; or --alpha 0 "
      "--hammer-velocity V: struck by a felt hammer (C3 law) at 0.12 L.");
  cmd->add_option("--scheme", a.scheme,
                  "sv: Störmer–Verlet (66); sav-split: split scheme (38); implicit: the "
                  "discrete-gradient scheme (67)–(68) with Newton–Raphson (tolerance 1e-13, at "
                  "most 20 iterations), lossless, no hammer")
      ->check(CLI::IsMember({"sv", "sav-split", "implicit"}))
      ->capture_default_str();
  cmd->add_option("--grid", a.grid,
                  "longitudinal: h >= sqrt(E/ρ) k (the paper's); transverse: the finest grid the "
                  "stiff-string bound (44) allows; two-grid: u on the transverse grid sized for "
                  "--tension-margin·T0, v on a coarse grid nested in it with h_v >= 1.05 "
                  "sqrt(E/ρ) k (SCHEMES §3b, the voices' default)")
      ->check(CLI::IsMember({"longitudinal", "transverse", "two-grid"}))
      ->capture_default_str();
  cmd->add_option("--stiffness", a.stiffness, "bending stiffness EI, I = πr⁴/4 of the section")
      ->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str();
  // Numbers are taken as text and parsed strictly by runStringCommand.
  auto number = [&](const char* flag, std::string& value, const char* type, const char* what) {
    addNumberOption(cmd, flag, value, type, what);
  };
  number("--k", a.k, "SECONDS", "time step (> 0)");
  number("--grid-factor", a.gridFactor, "NUMBER", "multiplies the rule's minimal h (>= 1)");
  number("--tension-margin", a.tensionMargin, "NUMBER",
         "two-grid: u's grid sized for this multiple of T0 (1 … 4)");
  cmd->add_option("--segments", a.segments,
                  "number of grid segments M, instead of the grid rule (a fixed grid for "
                  "convergence in k)")
      ->type_name("INT");
  number("--alpha", a.alpha, "NUMBER", "amplitude of the first-mode start (70)");
  number("--hammer-velocity", a.hammerVelocity, "M/S", "hammer speed at impact; needs --alpha 0");
  number("--epsilon", a.epsilon, "JOULES", "gauge shift ε of sav-split, §2.5 (>= 0)");
  number("--duration", a.duration, "SECONDS", "simulated time (> 0)");
  number("--probe", a.probe, "FRACTION", "where u, v are written, as a fraction of L (0..1)");
  number("--every", a.every, "INT", "write every N-th step (>= 1); n = 0 is always written");
  number("--rho", a.density, "KG/M3", "density ρ (> 0)");
  number("--area", a.area, "M2", "cross-section A (> 0)");
  number("--length", a.length, "M", "length L (> 0)");
  number("--young", a.young, "PA", "Young's modulus E (> 0; E A > T0)");
  number("--tension", a.tension, "N", "tension T0 (> 0)");
  number("--sigma0", a.sigma0, "1/S", "frequency-independent loss σ0 (>= 0)");
  number("--sigma1", a.sigma1, "M2/S", "frequency-dependent loss σ1 (>= 0)");
  cmd->add_option("--snapshots", a.snapshots,
                  "times at which the whole string is written to --snapshot-out, comma-separated "
                  "(>= 0, <= --duration); each at the first step at or after it")
      ->type_name("T1,T2,...");
  cmd->add_option("--snapshot-out", a.snapshotOut,
                  "CSV of the snapshots: t,x,u,v, one row per grid node (the fixed ends "
                  "included) per snapshot; written whole or not at all")
      ->type_name("PATH");
  addOutputOption(cmd, a.out);
  cmd->footer(
      "CSV: a comment line '# segments=M h=... k=...', a header, then one row per written step\n"
      "  n: t,u,v,energy,psi. t = n k; u, v = u^n, v^n at the grid point nearest probe·L;\n"
      "  energy = H^{n+1/2} of (41) (sv: (41) with ψ = 0 plus V'(u^n, v^n); implicit: the\n"
      "  energy (67)–(68) conserve), with the gauge shift ε excluded; psi = ψ^{n+1/2} of the\n"
      "  string's potential (0 for sv and implicit; a hammer strike has a second ψ, the felt's,\n"
      "  which is not written). With loss, energy + dissipated is what stays constant.\n"
      "Snapshots: a header, then for each time of --snapshots (at the first step n with\n"
      "  n k >= it) one row per grid node x = j h, j = 0..M: t,x,u,v (u = v = 0 at the ends).\n" +
      std::string(kRunFooter));
  cmd->add_flag("--allow-long-run", a.allowLongRun,
                "start a run estimated to take more than an hour (refused otherwise; the estimate "
                "is printed)");
  return cmd;
}

namespace {

// u at the grid point nearest the probe; v there too on a single grid, and on two grids v linear in
// the coarse cell holding the probe's x (v = 0 at the ends), as the snapshots take it.
struct Probe {
  Eigen::Index u = 0;
  Eigen::Index vLow = -1, vHigh = -1;  // indices into q, −1 at a fixed end
  double weight = 0.0;                 // of vHigh
  double v(const Vector& q) const {
    return (vLow >= 0 ? (1.0 - weight) * q[vLow] : 0.0) + (vHigh >= 0 ? weight * q[vHigh] : 0.0);
  }
};

template <class Scheme>
RunSummary simulate(Scheme& scheme, Probe probe, long steps, long every, std::FILE* out,
                    Snapshots* snapshots) {
  Snapshotting<Scheme> watched(scheme, snapshots);
  std::fprintf(out, "t,u,v,energy,psi\n");
  return runToCsv(
      watched, steps, every, out,
      [&](const Snapshotting<Scheme>& w, const Energy& e, std::FILE* f) {
        const Scheme& s = w.scheme();
        writeNumber(f, s.q()[probe.u]);
        writeNumber(f, probe.v(s.q()));
        writeNumber(f, e.total());
        if constexpr (requires { s.psi(); })
          writeNumber(f, s.psi());
        else
          writeNumber(f, 0.0);
      },
      "--alpha, --hammer-velocity or --epsilon is");
}

template <class System>
RunSummary run(const std::string& scheme, const System& system, const InitialState& start,
               const StepParameters& params, Probe probe, long steps, long every, std::FILE* out,
               Snapshots* snapshots) {
  if (scheme == "sv") {
    auto sv = building([&] { return StormerVerlet<System>(system, params, start); });
    return simulate(sv, probe, steps, every, out, snapshots);
  }
  if constexpr (std::is_same_v<System, NonlinearString>) {
    if (scheme == "implicit") {
      auto implicit = building([&] { return DiscreteGradientString(system, params.k, start); });
      return simulate(implicit, probe, steps, every, out, snapshots);
    }
  }
  auto split = building([&] { return SplitSav<System>(system, params, start); });
  return simulate(split, probe, steps, every, out, snapshots);
}

}  // namespace

int runStringCommand(const StringArguments& a) {
  StringPhysics physics;
  physics.density = parseReal("--rho", a.density, Range::positive, "kg/m^3");
  physics.area = parseReal("--area", a.area, Range::positive, "m^2");
  physics.length = parseReal("--length", a.length, Range::positive, "m");
  physics.young = parseReal("--young", a.young, Range::positive, "Pa");
  physics.tension = parseReal("--tension", a.tension, Range::positive, "N");
  if (a.stiffness == "on") physics.inertia = physics.area * physics.area / (4.0 * std::numbers::pi);
  const double k = parseReal("--k", a.k, Range::positive, "seconds");
  const double factor = parseReal("--grid-factor", a.gridFactor, Range::positive);
  if (factor < 1.0)
    throw UsageError("--grid-factor = " + a.gridFactor + ": out of range; expected >= 1");
  const double alpha = parseReal("--alpha", a.alpha, Range::any);
  const double hammerVelocity =
      parseReal("--hammer-velocity", a.hammerVelocity, Range::nonNegative, "m/s");
  const double epsilon = parseReal("--epsilon", a.epsilon, Range::nonNegative, "J");
  const double duration = parseReal("--duration", a.duration, Range::positive, "seconds");
  const double probe = parseReal("--probe", a.probe, Range::positive);
  if (probe >= 1.0) throw UsageError("--probe = " + a.probe + ": out of range; expected in (0, 1)");
  const long every = parseInteger("--every", a.every, 1);
  const double sigma0 = parseReal("--sigma0", a.sigma0, Range::nonNegative, "1/s");
  const double sigma1 = parseReal("--sigma1", a.sigma1, Range::nonNegative, "m^2/s");
  if (hammerVelocity > 0.0 && alpha != 0.0)
    throw UsageError("--hammer-velocity = " + a.hammerVelocity +
                     ": a strike starts from rest; give --alpha 0 with it");
  if (epsilon != 0.0 && a.scheme != "sav-split")
    throw UsageError("--epsilon = " + a.epsilon + ": the gauge shift applies to sav-split only");
  if (a.scheme == "implicit" && (hammerVelocity > 0.0 || sigma0 > 0.0 || sigma1 > 0.0))
    throw UsageError(
        "--scheme implicit: the reference (67) is lossless and unstruck; give it "
        "no --hammer-velocity, --sigma0 or --sigma1");
  const long steps = stepCount(duration, k);
  checkOutputSize(steps, every, 5);
  checkSnapshotFlags(a.snapshots, a.snapshotOut, a.out);
  const std::vector<long> wanted =
      a.snapshots.empty() ? std::vector<long>{} : snapshotSteps(a.snapshots, k, steps);

  const GridRule rule = a.grid == "transverse" ? GridRule::transverse
                        : a.grid == "two-grid" ? GridRule::twoGrid
                                               : GridRule::longitudinal;
  const double margin = parseReal("--tension-margin", a.tensionMargin, Range::positive);
  if (margin < 1.0 || margin > 4.0)
    throw UsageError("--tension-margin = " + a.tensionMargin + ": out of range; expected 1 … 4");
  if (!a.segments.empty() && rule == GridRule::twoGrid)
    throw UsageError("--segments = " + a.segments +
                     ": fixes one grid for u and v; --grid two-grid sizes its two from k");
  const StringGrid grid =
      a.segments.empty()
          ? building([&] { return stringGrid(physics, rule, k, sigma1, factor, margin); })
          : StringGrid{static_cast<int>(parseInteger("--segments", a.segments, 2, 1'000'000)), 0};
  const int segments = grid.transverse;
  // Measured (one core, a 2-core Zen 5): sav-split and sv about 3e8 unknown-steps a second (two
  // grids, 3e4 unknowns); the implicit reference's Newton solves grow as the square of the
  // unknowns: about 4e8 unknown²-steps a second (200 to 2000 unknowns).
  const double unknowns =
      static_cast<double>(segments - 1) +
      static_cast<double>((grid.longitudinal ? grid.longitudinal : segments) - 1);
  if (a.scheme == "implicit")
    checkWork(static_cast<double>(steps) * unknowns * unknowns, "unknown²-steps", 4e8,
              a.allowLongRun, "shorten --duration, raise --k or lower --segments");
  else
    checkWork(static_cast<double>(steps) * unknowns, "unknown-steps", 3e8, a.allowLongRun,
              "shorten --duration, raise --k or --grid-factor, or lower --segments");
  const NonlinearString string = building([&] {
    return NonlinearString(physics,
                           StringGrid{segments, grid.longitudinal ? grid.longitudinal : segments});
  });
  const int cells = string.grid().longitudinal;
  Probe probeIndex;
  probeIndex.u = std::clamp<Eigen::Index>(std::lround(probe * segments) - 1, 0, segments - 2);
  if (cells == segments) {
    probeIndex.vLow = probeIndex.u + string.transverseSize();
  } else {  // coarse points J and J + 1 around x = probe L, point J at q[offset + J − 1]
    const double at = probe * cells;
    const Eigen::Index cell = std::min<Eigen::Index>(static_cast<Eigen::Index>(at), cells - 1);
    const Eigen::Index offset = string.transverseSize() - 1;
    probeIndex.weight = at - static_cast<double>(cell);
    probeIndex.vLow = cell == 0 ? -1 : offset + cell;
    probeIndex.vHigh = cell + 1 == cells ? -1 : offset + cell + 1;
  }
  const StepParameters params{.k = k, .sigma0 = sigma0, .sigma1 = sigma1, .epsilon = epsilon};

  if (!wanted.empty())
    checkOutputSize(static_cast<long>(wanted.size()) - 1, 1, 4L * (segments + 1));
  AtomicFile file(a.out, "--out");
  std::optional<AtomicFile> snapshotFile;
  std::optional<Snapshots> snapshots;
  if (!wanted.empty()) {
    snapshotFile.emplace(a.snapshotOut, "--snapshot-out");
    // t,x,u,v at x = j h, j = 0..M, zero at the fixed ends; q holds u then v (then the hammer).
    // On two grids v is linear in each coarse cell of r fine segments (its strain is the cell's).
    const Eigen::Index interior = segments - 1;
    const int r = segments / cells;
    const double h = string.spacing();
    snapshots.emplace(
        wanted, "t,x,u,v",
        [segments, interior, r, h](std::FILE* f, double t, const Vector& q) {
          auto v = [&](int coarse) {  // v at coarse point J, 0 at the ends
            return coarse == 0 || coarse * r == segments ? 0.0 : q[interior + coarse - 1];
          };
          for (int j = 0; j <= segments; ++j) {
            const bool end = j == 0 || j == segments;
            const int cell = std::min(j / r, segments / r - 1);
            const double frac = static_cast<double>(j - cell * r) / r;
            std::fprintf(f, "%.17g", t);
            writeNumber(f, j * h);
            writeNumber(f, end ? 0.0 : q[j - 1]);
            writeNumber(f, (1.0 - frac) * v(cell) + frac * v(cell + 1));
            std::fputc('\n', f);
          }
        },
        snapshotFile->stream());
  }
  Snapshots* watcher = snapshots ? &*snapshots : nullptr;
  std::fprintf(file.stream(), "# segments=%d h=%.17g k=%.17g longitudinal_segments=%d h_v=%.17g\n",
               segments, string.spacing(), k, cells, string.longitudinalSpacing());
  RunSummary summary;
  const Eigen::Index n = string.size();
  if (hammerVelocity > 0.0) {
    const HammerFelt felt;
    const HammeredString system = building([&] { return HammeredString(string, felt); });
    InitialState start{Vector::Zero(n + 1), Vector::Zero(n + 1)};
    start.q[n] = -1e-4;  // 0.1 mm below the string
    start.p[n] = felt.mass * hammerVelocity;
    summary =
        run(a.scheme, system, start, params, probeIndex, steps, every, file.stream(), watcher);
  } else {
    InitialState start{Vector::Zero(n), Vector::Zero(n)};
    for (int j = 0; j < segments - 1; ++j)  // (70)
      start.q[j] = alpha * std::sqrt(physics.area) *
                   std::sin(std::numbers::pi * (j + 1) / static_cast<double>(segments));
    summary =
        run(a.scheme, string, start, params, probeIndex, steps, every, file.stream(), watcher);
  }
  commitTogether({&file, snapshotFile ? &*snapshotFile : nullptr});  // both files or neither
  printSummary("string",
               a.scheme + ", " + std::to_string(segments) + " segments, k = " + a.k + " s", a.out,
               summary);
  return 0;
}

}  // namespace hamiltone::cli
