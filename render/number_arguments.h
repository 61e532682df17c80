// Command-line numbers, parsed strictly: the whole text, finite, in range, else UsageError.
#pragma once

#include <CLI/App.hpp>
#include <string>

namespace hamiltone::cli {

enum class Range { any, positive, nonNegative };

// `flag` = "--k" names the argument in the message; `unit` is appended to what is valid.
double parseReal(const std::string& flag, const std::string& text, Range range,
                 const std::string& unit = "");
// Registers a numeric option taken as text (parsed later by parseReal/parseInteger, whose
// messages say what is valid), shown in --help with its unit as `type` and its default.
inline void addNumberOption(CLI::App* command, const char* flag, std::string& value,
                            const char* type, const char* what) {
  command->add_option(flag, value, what)->type_name(type)->capture_default_str();
}

// A whole number in [minimum, maximum].
long parseInteger(const std::string& flag, const std::string& text, long minimum,
                  long maximum = 1'000'000'000);

}  // namespace hamiltone::cli
