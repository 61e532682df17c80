// Parses the plate subcommand, builds the plate on the grid of the bound (84) and writes CSV.
#include "plate_command.h"

#include <CLI/Validators.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <utility>
#include <vector>

#include "atomic_file.h"
#include "csv_run.h"
#include "instruments/plate.h"
#include "number_arguments.h"
#include "schemes/reference/linearly_implicit_plate.h"
#include "schemes/sav.h"
#include "schemes/stormer_verlet.h"
#include "snapshots.h"

namespace hamiltone::cli {

CLI::App* addPlateCommand(CLI::App& app, PlateArguments& a) {
  CLI::App* cmd = app.add_subcommand(
      "plate",
      "Von Kármán plate (BDZ (71), split (81)), simply supported rectangle, started in its first "
      "mode (85): q = α ξ sin(πx/Lx) sin(πy/Ly), at rest. Defaults: the paper's steel plate.");
  cmd->add_option("--scheme", a.scheme,
                  "sv: Störmer–Verlet (82); sav-split: split scheme (38); implicit: the linearly "
                  "implicit reference (83), lossless, one sparse factorisation per step")
      ->check(CLI::IsMember({"sv", "sav-split", "implicit"}))
      ->capture_default_str();
  auto number = [&](const char* flag, std::string& value, const char* type, const char* what) {
    addNumberOption(cmd, flag, value, type, what);
  };
  number("--k", a.k, "SECONDS", "time step (> 0)");
  number("--alpha", a.alpha, "NUMBER", "amplitude of (85), in plate thicknesses");
  number("--grid-factor", a.gridFactor, "NUMBER", "multiplies the minimal h of (84) (>= 1)");
  number("--duration", a.duration, "SECONDS", "simulated time (> 0)");
  cmd->add_option("--probe", a.probe, "where q is written: x,y as fractions of Lx, Ly")
      ->type_name("X,Y")
      ->capture_default_str();
  number("--every", a.every, "INT", "write every N-th step (>= 1); n = 0 is always written");
  number("--young", a.young, "PA", "Young's modulus E (> 0)");
  number("--density", a.density, "KG/M3", "density ρ (> 0)");
  number("--poisson", a.poisson, "NUMBER", "Poisson's ratio ν (−1 … 0.5)");
  number("--thickness", a.thickness, "M", "thickness ξ (> 0)");
  number("--lx", a.lx, "M", "side along x (> 0)");
  number("--ly", a.ly, "M", "side along y (> 0)");
  number("--sigma0", a.sigma0, "1/S", "frequency-independent loss σ0 (>= 0)");
  number("--sigma1", a.sigma1, "M2/S", "frequency-dependent loss σ1 (>= 0)");
  cmd->add_option("--snapshots", a.snapshots,
                  "times at which the whole plate is written to --snapshot-out, comma-separated "
                  "(>= 0, <= --duration); each at the first step at or after it")
      ->type_name("T1,T2,...");
  cmd->add_option("--snapshot-out", a.snapshotOut,
                  "CSV of the snapshots: t,x,y,w, one row per grid node (the edges included) per "
                  "snapshot; written whole or not at all")
      ->type_name("PATH");
  addOutputOption(cmd, a.out);
  cmd->footer(
      "CSV: a comment line '# nx=.. ny=.. h=.. hy=.. k=..' (interior points; h along x), a\n"
      "  header, then one row per written step n: t,q,energy,psi. t = n k; q = q^n at the grid\n"
      "  point nearest the probe; energy = H^{n+1/2} of (41) (sv: (41) with ψ = 0 plus\n"
      "  V'(q^n); implicit: the energy (83) conserves, (41) with ½ψ² replaced by the mean of\n"
      "  the Airy energies of F^n and F^{n+1}); psi = ψ^{n+1/2} (0 for sv and implicit). With\n"
      "  loss, energy + dissipated is what stays constant.\n"
      "Snapshots: a header, then for each time of --snapshots (at the first step n with\n"
      "  n k >= it) one row per grid node x = l hx, y = m hy, l = 0..Mx, m = 0..My (x fastest):\n"
      "  t,x,y,w with w = q^n (0 on the edges).\n" +
      std::string(kRunFooter));
  cmd->add_flag("--allow-long-run", a.allowLongRun,
                "start a run estimated to take more than an hour (refused otherwise; the estimate "
                "is printed)");
  return cmd;
}

namespace {

template <class Scheme>
RunSummary simulate(Scheme& scheme, Eigen::Index probe, long steps, long every, std::FILE* out,
                    Snapshots* snapshots) {
  Snapshotting<Scheme> watched(scheme, snapshots);
  std::fprintf(out, "t,q,energy,psi\n");
  return runToCsv(
      watched, steps, every, out,
      [&](const Snapshotting<Scheme>& w, const Energy& e, std::FILE* f) {
        const Scheme& s = w.scheme();
        writeNumber(f, s.q()[probe]);
        writeNumber(f, e.total());
        if constexpr (requires { s.psi(); })
          writeNumber(f, s.psi());
        else
          writeNumber(f, 0.0);
      },
      "--alpha, --thickness or --young is");
}

// "0.3,0.4" → two fractions strictly inside (0, 1).
std::pair<double, double> parseProbe(const std::string& text) {
  const auto comma = text.find(',');
  if (comma == std::string::npos)
    throw UsageError("--probe = '" + text + "': expected two fractions x,y such as 0.3,0.4");
  const double x = parseReal("--probe", text.substr(0, comma), Range::positive);
  const double y = parseReal("--probe", text.substr(comma + 1), Range::positive);
  if (x >= 1.0 || y >= 1.0)
    throw UsageError("--probe = " + text + ": out of range; expected fractions in (0, 1)");
  return {x, y};
}

}  // namespace

int runPlateCommand(const PlateArguments& a) {
  PlatePhysics physics;
  physics.young = parseReal("--young", a.young, Range::positive, "Pa");
  physics.density = parseReal("--density", a.density, Range::positive, "kg/m^3");
  physics.poisson = parseReal("--poisson", a.poisson, Range::any);
  if (!(physics.poisson > -1.0 && physics.poisson < 0.5))
    throw UsageError("--poisson = " + a.poisson +
                     ": out of range; expected a ratio between -1 and 0.5 (an isotropic solid)");
  physics.thickness = parseReal("--thickness", a.thickness, Range::positive, "m");
  physics.lx = parseReal("--lx", a.lx, Range::positive, "m");
  physics.ly = parseReal("--ly", a.ly, Range::positive, "m");
  const double k = parseReal("--k", a.k, Range::positive, "seconds");
  const double alpha = parseReal("--alpha", a.alpha, Range::any);
  const double factor = parseReal("--grid-factor", a.gridFactor, Range::positive);
  if (factor < 1.0)
    throw UsageError("--grid-factor = " + a.gridFactor + ": out of range; expected >= 1");
  const double duration = parseReal("--duration", a.duration, Range::positive, "seconds");
  const auto [px, py] = parseProbe(a.probe);
  const long every = parseInteger("--every", a.every, 1);
  const double sigma0 = parseReal("--sigma0", a.sigma0, Range::nonNegative, "1/s");
  const double sigma1 = parseReal("--sigma1", a.sigma1, Range::nonNegative, "m^2/s");
  if (a.scheme == "implicit" && (sigma0 > 0.0 || sigma1 > 0.0))
    throw UsageError(
        "--scheme implicit: the reference (83) is lossless; give it no --sigma0 or --sigma1");
  const long steps = stepCount(duration, k);
  checkOutputSize(steps, every, 4);
  checkSnapshotFlags(a.snapshots, a.snapshotOut, a.out);
  const std::vector<long> wanted =
      a.snapshots.empty() ? std::vector<long>{} : snapshotSteps(a.snapshots, k, steps);

  const int mx = building([&] { return plateSegments(physics, physics.lx, k, factor, sigma1); });
  const int my = building([&] { return plateSegments(physics, physics.ly, k, factor, sigma1); });
  // Measured (one core, a 2-core Zen 5): sav-split and sv about 5e7 point-steps a second (142 ×
  // 142 points); the implicit reference's Newton solves grow as the square of the points: about
  // 5e8 point²-steps a second (30 × 30 to 142 × 142).
  const double points = static_cast<double>(mx - 1) * static_cast<double>(my - 1);
  if (a.scheme == "implicit")
    checkWork(static_cast<double>(steps) * points * points, "point²-steps", 5e8, a.allowLongRun,
              "shorten --duration, raise --k or --grid-factor");
  else
    checkWork(static_cast<double>(steps) * points, "point-steps", 5e7, a.allowLongRun,
              "shorten --duration, raise --k or --grid-factor");
  const VonKarmanPlate plate = building([&] { return VonKarmanPlate(physics, mx, my); });
  const long l = std::clamp(std::lround(px * mx) - 1, 0L, static_cast<long>(plate.nx() - 1));
  const long m = std::clamp(std::lround(py * my) - 1, 0L, static_cast<long>(plate.ny() - 1));
  const Eigen::Index probe = l + static_cast<Eigen::Index>(plate.nx()) * m;
  const StepParameters params{.k = k, .sigma0 = sigma0, .sigma1 = sigma1};
  const InitialState start{plateFirstMode(plate, alpha), Vector::Zero(plate.size())};

  if (!wanted.empty())
    checkOutputSize(static_cast<long>(wanted.size()) - 1, 1, 4L * (mx + 1) * (my + 1));
  AtomicFile file(a.out, "--out");
  std::optional<AtomicFile> snapshotFile;
  std::optional<Snapshots> snapshots;
  if (!wanted.empty()) {
    snapshotFile.emplace(a.snapshotOut, "--snapshot-out");
    // t,x,y,w at x = i hx, y = j hy over the whole grid (x fastest), zero on the edges.
    const int nx = plate.nx(), ny = plate.ny();
    const double hx = plate.hx(), hy = plate.hy();
    snapshots.emplace(
        wanted, "t,x,y,w",
        [nx, ny, hx, hy](std::FILE* f, double t, const Vector& q) {
          for (int j = 0; j <= ny + 1; ++j)
            for (int i = 0; i <= nx + 1; ++i) {
              const bool edge = i == 0 || j == 0 || i == nx + 1 || j == ny + 1;
              std::fprintf(f, "%.17g", t);
              writeNumber(f, i * hx);
              writeNumber(f, j * hy);
              writeNumber(f, edge ? 0.0 : q[(i - 1) + static_cast<Eigen::Index>(nx) * (j - 1)]);
              std::fputc('\n', f);
            }
        },
        snapshotFile->stream());
  }
  Snapshots* watcher = snapshots ? &*snapshots : nullptr;
  std::fprintf(file.stream(), "# nx=%d ny=%d h=%.17g hy=%.17g k=%.17g\n", plate.nx(), plate.ny(),
               plate.hx(), plate.hy(), k);
  const RunSummary summary = [&] {
    if (a.scheme == "sv") {
      auto scheme = building([&] { return StormerVerlet<VonKarmanPlate>(plate, params, start); });
      return simulate(scheme, probe, steps, every, file.stream(), watcher);
    }
    if (a.scheme == "implicit") {
      auto scheme = building([&] { return LinearlyImplicitPlate(plate, params, start); });
      return simulate(scheme, probe, steps, every, file.stream(), watcher);
    }
    auto scheme = building([&] { return SplitSav<VonKarmanPlate>(plate, params, start); });
    return simulate(scheme, probe, steps, every, file.stream(), watcher);
  }();
  commitTogether({&file, snapshotFile ? &*snapshotFile : nullptr});  // both files or neither
  printSummary("plate",
               a.scheme + ", " + std::to_string(plate.nx()) + "x" + std::to_string(plate.ny()) +
                   " points, k = " + a.k + " s",
               a.out, summary);
  return 0;
}

}  // namespace hamiltone::cli
