// `hamiltone-sim string`: the geometrically exact string of BDZ §4.2, started in its first mode
// (70) or struck by a felt hammer, with Störmer–Verlet (66), the split scheme (38) or the implicit
// discrete-gradient reference (67)–(68).
#pragma once

#include <CLI/App.hpp>
#include <string>

namespace hamiltone::cli {

// The command line as typed; numbers are parsed and checked by runStringCommand().
struct StringArguments {
  std::string scheme = "sav-split", grid = "longitudinal", stiffness = "off";
  std::string k = "2.6e-7", gridFactor = "1.05", alpha = "300", epsilon = "0", duration = "0.01";
  std::string probe = "0.5", every = "1", hammerVelocity = "0", segments, tensionMargin = "1.5";
  std::string density = "7850", area = "8.87e-7", length = "1.259", young = "2.02e11",
              tension = "759";
  std::string sigma0 = "0", sigma1 = "0";
  std::string snapshots, snapshotOut;  // "t1,t2,..." and the CSV of the whole string at those t
  std::string out;
  bool allowLongRun = false;
};

CLI::App* addStringCommand(CLI::App& app, StringArguments& args);

// Validates, simulates, writes the CSV and prints a summary. Throws UsageError on bad input.
int runStringCommand(const StringArguments& args);

}  // namespace hamiltone::cli
