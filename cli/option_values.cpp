// The scan over argv for refuseOptionsAsValues, with the option table of the app (and its
// subcommands) as CLI11 holds it.
#include "option_values.h"

#include <string>

#include "usage_error.h"

namespace hamiltone::cli {

namespace {

// The option of `app` (or of its subcommands) that `arg` names, or null.
const CLI::Option* optionNamed(const CLI::App& app, const std::string& arg) {
  for (const CLI::Option* o : app.get_options())
    if (o->check_name(arg)) return o;
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
    if (const CLI::Option* o = optionNamed(*sub, arg)) return o;
  return nullptr;
}

}  // namespace

void refuseOptionsAsValues(const CLI::App& app, int argc, const char* const* argv) {
  for (int i = 1; i + 1 < argc; ++i) {
    const std::string arg = argv[i], next = argv[i + 1];
    if (arg == "--") return;
    if (arg.size() < 2 || arg[0] != '-' || arg.find('=') != std::string::npos) continue;
    const CLI::Option* option = optionNamed(app, arg);
    if (!option || option->get_items_expected_min() <= 0) continue;  // a flag, or not ours
    const bool looksLikeOption =
        next.rfind("--", 0) == 0 || (next.size() > 1 && next[0] == '-' &&
                                     optionNamed(app, next.substr(0, next.find('='))) != nullptr);
    if (!looksLikeOption) continue;
    // "--out=VALUE" holds any value; a short name's "-o=VALUE" would keep the "=".
    const std::string longName =
        option->get_lnames().empty() ? arg : "--" + option->get_lnames().front();
    throw UsageError(arg + " is missing its value: the argument after it, " + next +
                     ", is an option; give " + arg + " " + option->get_type_name() +
                     " (a value that starts with - as " + longName + "=VALUE)");
  }
}

}  // namespace hamiltone::cli
