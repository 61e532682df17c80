// A bad command line: the message names the argument, its value and what is valid; exit code 2.
#pragma once

#include <stdexcept>
#include <string>

namespace hamiltone::cli {

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

constexpr int kExitUsage = 2;

}  // namespace hamiltone::cli
