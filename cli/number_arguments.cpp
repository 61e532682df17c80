// Strict number parsing for the command-line programs: "1e-3" yes; "1e-3x", "", "nan", "inf" no.
#include "number_arguments.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>

#include "usage_error.h"

namespace hamiltone::cli {

namespace {

std::string expected(Range range, const std::string& unit) {
  std::string what = "a finite number";
  if (range == Range::positive) what += " > 0";
  if (range == Range::nonNegative) what += " >= 0";
  return unit.empty() ? what : what + " (" + unit + ")";
}

}  // namespace

double parseReal(const std::string& flag, const std::string& text, Range range,
                 const std::string& unit) {
  const std::string valid = "expected " + expected(range, unit);
  char* end = nullptr;
  errno = 0;
  const double x = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size())
    throw UsageError(flag + " = '" + text + "': not a number; " + valid);
  if (errno == ERANGE && std::abs(x) < 1.0)
    throw UsageError(flag + " = " + text + ": too small for double precision; " + valid);
  if (!std::isfinite(x) || errno == ERANGE)
    throw UsageError(flag + " = " + text + ": not finite; " + valid);
  if ((range == Range::positive && !(x > 0.0)) || (range == Range::nonNegative && x < 0.0))
    throw UsageError(flag + " = " + text + ": out of range; " + valid);
  return x;
}

long parseInteger(const std::string& flag, const std::string& text, long minimum, long maximum) {
  const std::string valid =
      "expected a whole number from " + std::to_string(minimum) + " to " + std::to_string(maximum);
  char* end = nullptr;
  errno = 0;
  const long x = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || end != text.c_str() + text.size())
    throw UsageError(flag + " = '" + text + "': not a whole number; " + valid);
  if (errno == ERANGE || x < minimum || x > maximum)  // ERANGE: a whole number past long's range
    throw UsageError(flag + " = " + text + ": out of range; " + valid);
  return x;
}

}  // namespace hamiltone::cli
