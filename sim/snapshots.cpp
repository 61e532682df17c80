// The snapshot times and the snapshot writer of the string and plate subcommands.
#include "snapshots.h"

#include <algorithm>
#include <cmath>

#include "atomic_file.h"
#include "number_arguments.h"
#include "usage_error.h"
#include "util/format_number.h"

namespace hamiltone::cli {

void checkSnapshotFlags(const std::string& times, const std::string& file, const std::string& out) {
  if (times.empty() != file.empty())
    throw UsageError(times.empty()
                         ? "--snapshot-out = " + file + ": needs --snapshots (the times)"
                         : "--snapshots = " + times + ": needs --snapshot-out (the file)");
  if (!file.empty() && !out.empty() && sameFile(file, out))
    throw UsageError("--snapshot-out = " + file + ": the same file as --out = " + out +
                     "; expected a different path");
}

std::vector<long> snapshotSteps(const std::string& times, double k, long steps) {
  std::vector<long> result;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = times.find(',', start);
    std::string item = times.substr(start, comma == std::string::npos ? comma : comma - start);
    item.erase(0, item.find_first_not_of(' '));
    item.erase(item.find_last_not_of(' ') + 1);
    if (item.empty())
      throw UsageError("--snapshots = '" + times +
                       "': an empty time; expected comma-separated times in seconds");
    const double t = parseReal("--snapshots", item, Range::nonNegative, "seconds");
    const long n = static_cast<long>(std::ceil(t / k * (1.0 - 1e-12)));
    if (n > steps)
      throw UsageError("--snapshots = " + item + ": after the last step (t = " +
                       formatApprox(static_cast<double>(steps) * k) +
                       " s); expected times <= --duration");
    result.push_back(n);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  std::sort(result.begin(), result.end());
  result.erase(std::unique(result.begin(), result.end()), result.end());
  return result;
}

Snapshots::Snapshots(std::vector<long> steps, const char* header, Field field, std::FILE* out)
    : steps_(std::move(steps)), field_(std::move(field)), out_(out) {
  std::fprintf(out_, "%s\n", header);
}

void Snapshots::visit(long n, double t, const Vector& q) {
  if (next_ >= steps_.size() || n < steps_[next_]) return;
  while (next_ < steps_.size() && steps_[next_] <= n) ++next_;  // one field per step
  field_(out_, t, q);
}

}  // namespace hamiltone::cli
