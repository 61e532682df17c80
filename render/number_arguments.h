// Command-line numbers, parsed strictly: the whole text, finite, in range, else UsageError.
#pragma once

#include <string>

namespace hamiltone::cli {

enum class Range { any, positive, nonNegative };

// `flag` = "--k" names the argument in the message; `unit` is appended to what is valid.
double parseReal(const std::string& flag, const std::string& text, Range range,
                 const std::string& unit = "");
// A whole number in [minimum, maximum].
long parseInteger(const std::string& flag, const std::string& text, long minimum,
                  long maximum = 1'000'000'000);

}  // namespace hamiltone::cli
