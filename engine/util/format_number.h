// Numbers in error messages: the shortest text that reads back as the same double.
#pragma once

#include <charconv>
#include <cstdio>
#include <string>

namespace hamiltone {

inline std::string formatNumber(double x) {
  char buffer[32];
  const auto end = std::to_chars(buffer, buffer + sizeof buffer, x).ptr;
  return std::string(buffer, end);
}

// A computed value, rounded for reading: `digits` significant digits ("%g").
inline std::string formatSignificant(double x, int digits) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.*g", digits, x);
  return buffer;
}

}  // namespace hamiltone
