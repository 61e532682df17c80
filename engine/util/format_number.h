// Numbers in error messages: a value as given, or a bound it is compared with — the shortest text
// that reads back as the same double — and a value computed from others, to the digits worth
// reading.
#pragma once

#include <charconv>
#include <cmath>
#include <cstdio>
#include <string>

namespace hamiltone {

inline std::string formatNumber(double x) {
  char buffer[32];
  const auto end = std::to_chars(buffer, buffer + sizeof buffer, x).ptr;
  return std::string(buffer, end);
}

// A derived quantity (a grid spacing, a step count, an energy): `digits` significant digits,
// where the 17 of formatNumber would be noise and std::to_string's fixed notation can run to 300
// digits; a NaN is "NaN", not the "-nan" of printf.
inline std::string formatApprox(double x, int digits = 4) {
  if (std::isnan(x)) return "NaN";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.*g", digits, x);
  return buffer;
}

}  // namespace hamiltone
