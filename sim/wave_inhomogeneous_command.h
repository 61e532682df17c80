// `hamiltone-sim wave-inhomogeneous`: the inhomogeneous wave of [M §4.3.2] on the asynchronous
// (or synchronous) Marazzato scheme, against its exact solution.
#pragma once

#include <CLI/App.hpp>
#include <string>

namespace hamiltone::cli {

// The command line as typed; numbers are parsed and checked by runWaveInhomogeneousCommand().
struct WaveInhomogeneousArguments {
  std::string dx = "5e-4", ratio = "10", duration = "0.5";
  std::string quadrature = "midpoint", start = "paper";
  bool sync = false, allowLongRun = false;
  std::string out;
};

CLI::App* addWaveInhomogeneousCommand(CLI::App& app, WaveInhomogeneousArguments& args);

// Validates, simulates, writes the final state's CSV and prints a summary. Throws UsageError on
// bad input.
int runWaveInhomogeneousCommand(const WaveInhomogeneousArguments& args);

}  // namespace hamiltone::cli
