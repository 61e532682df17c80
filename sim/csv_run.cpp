// The step count and the summary every hamiltone-sim subcommand prints.
#include "csv_run.h"

#include <cmath>

namespace hamiltone::cli {

long stepCount(double duration, double k, const std::string& durationFlag,
               const std::string& stepFlag) {
  const double steps = std::floor(duration / k * (1.0 + 1e-12));
  if (!(steps >= 1.0))
    throw UsageError(stepFlag + " = " + formatNumber(k) + " s: longer than " + durationFlag +
                     " = " + formatNumber(duration) + " s; expected a step at most " +
                     durationFlag);
  if (steps > kMaxSteps)
    throw UsageError(durationFlag + " / " + stepFlag + " = " + formatApprox(duration / k) +
                     " steps (" + durationFlag + " = " + formatNumber(duration) + " s, " +
                     stepFlag + " = " + formatNumber(k) + " s): expected at most 1e10; shorten " +
                     durationFlag + " or raise " + stepFlag);
  return static_cast<long>(steps);
}

void checkOutputSize(long steps, long every, long columns, const std::string& remedy) {
  const double numbers = (static_cast<double>(steps / every) + 1.0) * static_cast<double>(columns);
  if (numbers > 2e8)
    throw UsageError("the CSV would hold " + std::to_string(static_cast<long long>(numbers)) +
                     " numbers (" + std::to_string(static_cast<long long>(numbers * 2.4e-8)) +
                     " GB): expected at most 2e8; " + remedy);
}

namespace {

// A time in the unit that reads best: "40 s", "7.5 h", "3.2 years".
std::string readableSeconds(double s) {
  if (!std::isfinite(s)) return formatApprox(s) + " s";
  const struct {
    double seconds;
    const char* unit;
  } units[] = {{365.25 * 86400.0, "years"}, {86400.0, "days"}, {3600.0, "h"}, {60.0, "min"}};
  for (const auto& u : units)
    if (s >= u.seconds) return formatApprox(s / u.seconds) + " " + u.unit;
  return formatApprox(s) + " s";
}

}  // namespace

void checkWork(double units, const std::string& unitName, double unitsPerSecond, bool allowed,
               const std::string& remedy) {
  const double seconds = units / unitsPerSecond;
  if (allowed || seconds <= kMaxRunSeconds) return;
  throw UsageError("the run would take about " + readableSeconds(seconds) + " (" +
                   formatApprox(units) + " " + unitName + " at about " +
                   formatApprox(unitsPerSecond) + " per second): more than the " +
                   readableSeconds(kMaxRunSeconds) + " started without --allow-long-run; " +
                   remedy + ", or give --allow-long-run");
}

void printSummary(const std::string& command, const std::string& what, const std::string& path,
                  const RunSummary& summary) {
  std::printf("%s: %s, %ld steps; wrote %s (%ld rows)\n", command.c_str(), what.c_str(),
              summary.steps, path.c_str(), summary.rows);
  std::printf("energy at t = 0: %.17g J; ", summary.initialEnergy);
  if (summary.initialEnergy != 0.0)
    std::printf("max relative energy drift (51): %.3g", summary.maxRelativeDeviation);
  else
    std::printf("no energy to drift");
  if (summary.dissipated > 0.0)
    std::printf(" of energy + dissipated; dissipated %.6g J", summary.dissipated);
  std::printf("\n");
  if (summary.diverged)
    std::fprintf(stderr,
                 "hamiltone-sim %s: warning: the state became non-finite at t = %.17g; the run "
                 "stopped there, and the file ends with that row\n",
                 command.c_str(), summary.divergedAt);
}

}  // namespace hamiltone::cli
