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

// Registers the required --out option every subcommand writes its CSV to.
inline void addOutputOption(CLI::App* command, std::string& path) {
  command
      ->add_option("--out", path, "CSV file to write (replaced whole, or left untouched on error)")
      ->type_name("PATH")
      ->required();
}

// The end of every subcommand's --help: how steps are counted and what the exit codes mean.
inline const char* const kRunFooter =
    "Steps: floor(duration / k); the last row is at t = steps · k.\n"
    "Exit codes: 0 done (a scheme that diverges stops early, with a warning), 1 an I/O error\n"
    "  (a full disk; no file is left), 2 bad input, 128+N killed by signal N (no file left).";

// A whole number in [minimum, maximum].
long parseInteger(const std::string& flag, const std::string& text, long minimum,
                  long maximum = 1'000'000'000);

}  // namespace hamiltone::cli
