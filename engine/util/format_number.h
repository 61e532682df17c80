// Numbers in error messages: the shortest text that reads back as the same double.
#pragma once

#include <charconv>
#include <string>

namespace hamiltone {

inline std::string formatNumber(double x) {
  char buffer[32];
  const auto end = std::to_chars(buffer, buffer + sizeof buffer, x).ptr;
  return std::string(buffer, end);
}

}  // namespace hamiltone
