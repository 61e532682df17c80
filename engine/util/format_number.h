// Numbers in error messages, printed so the user sees the value exactly as it was taken.
#pragma once

#include <sstream>
#include <string>

namespace hamiltone {

inline std::string formatNumber(double x) {
  std::ostringstream s;
  s.precision(17);
  s << x;
  return s.str();
}

}  // namespace hamiltone
