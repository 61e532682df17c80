// An option whose value was forgotten, the next option taken in its place: CLI11 takes any
// argument as a value, so "--preset --notes C4" loaded a preset named "--notes" and refused the
// note list with a message about something else.
#pragma once

#include <CLI/App.hpp>

namespace hamiltone::cli {

// UsageError for the first option of `app` (or of the subcommand named before it) that takes a
// value and is followed by an argument naming one of the options (or starting with "--"),
// naming both and what the first expects. "--name=value" forms, negative numbers ("--x -3") and
// arguments after "--" are left alone. Call it before app.parse.
void refuseOptionsAsValues(const CLI::App& app, int argc, const char* const* argv);

}  // namespace hamiltone::cli
