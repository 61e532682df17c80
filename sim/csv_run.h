// Steps a scheme and writes its rows as CSV: `t, <state columns>, energy, kinetic, potential`.
#pragma once

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "schemes/hamiltonian.h"
#include "usage_error.h"
#include "util/format_number.h"

namespace hamiltone::cli {

// What a run reports beside its CSV.
struct RunSummary {
  long steps = 0;
  long rows = 0;
  double initialEnergy = 0.0;       // energy at n = 0
  double maxRelativeDeviation = 0;  // (51) over the written and unwritten steps alike
  double dissipated = 0.0;          // energy taken by loss
  bool diverged = false;            // a non-finite state ended the run early
  double divergedAt = 0.0;          // t of that state
};

// Full double precision: 17 significant digits round-trip.
inline void writeNumber(std::FILE* out, double x) { std::fprintf(out, ",%.17g", x); }

// Writes rows n = 0, every, 2·every, … <= steps: the time, then `columns(scheme, energy, out)`,
// which writes the rest of the row with writeNumber. The balance energy + dissipated is what
// (50) keeps constant, so its drift is the deviation reported, lossy or not. Stops at the first
// non-finite state, after writing it. A start whose energy is not finite is a usage error, with
// `tooLarge` naming the arguments that can cause it; a failed write (a full disk) throws
// std::runtime_error within a few thousand rows.
template <class Scheme, class Columns>
RunSummary runToCsv(Scheme& scheme, long steps, long every, std::FILE* out, Columns columns,
                    const std::string& tooLarge) {
  RunSummary summary;
  summary.steps = steps;
  summary.initialEnergy = scheme.energy().total();
  if (!std::isfinite(summary.initialEnergy))
    throw UsageError("the start's energy is " + formatApprox(summary.initialEnergy) + ": " +
                     tooLarge + " too large for double precision");
  for (long n = 0;; ++n) {
    const Energy e = scheme.energy();
    const double balance = e.total() + scheme.dissipated();
    const bool finite = std::isfinite(balance) && scheme.q().allFinite();
    if (n % every == 0 || !finite) {
      std::fprintf(out, "%.17g", scheme.time());
      columns(scheme, e, out);
      std::fputc('\n', out);
      if (++summary.rows % 4096 == 0 && std::ferror(out))
        throw std::runtime_error("writing the output failed: " + std::string(std::strerror(errno)));
    }
    if (!finite) {
      summary.diverged = true;
      summary.divergedAt = scheme.time();
      summary.steps = n;
      break;
    }
    const double deviation =
        std::abs(balance - summary.initialEnergy) / std::abs(summary.initialEnergy);
    summary.maxRelativeDeviation = std::max(summary.maxRelativeDeviation, deviation);
    if (n == steps) break;
    scheme.step();
  }
  summary.dissipated = scheme.dissipated();
  return summary;
}

// Engine errors about parameters are usage errors of the flags that set them.
template <class Make>
auto building(Make make) {
  try {
    return make();
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
}

// The most steps a run may take (of its finest step, where it has several).
inline constexpr double kMaxSteps = 1e10;

// floor(duration / k) steps, refused outside 1 … 1e10 naming the flag at fault: the step, when
// it is longer than the duration; both, when there would be too many.
long stepCount(double duration, double k, const std::string& durationFlag = "--duration",
               const std::string& stepFlag = "--k");

// Refuses a CSV of more than 2e8 numbers (a few GB); `remedy` says which flags to change.
void checkOutputSize(long steps, long every, long columns,
                     const std::string& remedy = "raise --every or shorten --duration");

// The longest run, in estimated seconds, hamiltone-sim starts without --allow-long-run.
inline constexpr double kMaxRunSeconds = 3600.0;

// Refuses (UsageError) a run whose estimated time exceeds kMaxRunSeconds, unless `allowed`
// (--allow-long-run): `units` of work — steps × unknowns × quadrature nodes, named `unitName` —
// at `unitsPerSecond`, a rate measured on one core of a 2-core CI machine (a faster machine
// takes less; the estimate is for deciding, not a promise). The message prints the estimate and
// `remedy`.
void checkWork(double units, const std::string& unitName, double unitsPerSecond, bool allowed,
               const std::string& remedy);

// The lines a run prints on stdout (and its divergence warning on stderr).
void printSummary(const std::string& command, const std::string& what, const std::string& path,
                  const RunSummary& summary);

}  // namespace hamiltone::cli
