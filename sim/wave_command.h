// `hamiltone-sim wave`: the nonlinear wave equation of [M §3.3] on Marazzato's scheme with the
// consistent P1 mass matrix, at a fixed step or with the adaptive step of [M Remark 8].
#pragma once

#include <CLI/App.hpp>
#include <string>

namespace hamiltone::cli {

// The command line as typed; numbers are parsed and checked by runWaveCommand().
struct WaveArguments {
  std::string quadrature = "midpoint";
  std::string alpha = "0.99", amplitude = "0.3", dx = "0.01";
  std::string k = "0.0033", duration = "1", every = "1";
  bool adaptive = false, allowLongRun = false;
  std::string epsFly = "3e-4", minStep;            // minStep not given: k / 1024
  bool epsFlyGiven = false, minStepGiven = false;  // typed on the command line (need --adaptive)
  std::string snapshots, snapshotOut;
  std::string out;
};

CLI::App* addWaveCommand(CLI::App& app, WaveArguments& args);

// Validates, simulates, writes the CSV (and the snapshots) and prints a summary. Throws
// UsageError on bad input, std::runtime_error when the adaptive step falls below --min-step.
int runWaveCommand(const WaveArguments& args);

}  // namespace hamiltone::cli
