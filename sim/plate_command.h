// `hamiltone-sim plate`: the von Kármán plate of BDZ §4.3, started in its first mode (85), with
// Störmer–Verlet (82), the split scheme (38) or the linearly implicit reference (83).
#pragma once

#include <CLI/App.hpp>
#include <string>

namespace hamiltone::cli {

// The command line as typed; numbers are parsed and checked by runPlateCommand().
struct PlateArguments {
  std::string scheme = "sav-split";
  std::string k = "1e-5", alpha = "10", gridFactor = "1", duration = "0.01", probe = "0.3,0.4";
  std::string every = "1";
  std::string young = "2e11", density = "7850", poisson = "0.3", thickness = "0.002", lx = "0.5",
              ly = "0.5";
  std::string sigma0 = "0", sigma1 = "0";
  std::string snapshots, snapshotOut;  // "t1,t2,…" and the file of the whole fields
  std::string out;
  bool allowLongRun = false;
};

CLI::App* addPlateCommand(CLI::App& app, PlateArguments& args);

// Validates, simulates, writes the CSV and prints a summary. Throws UsageError on bad input.
int runPlateCommand(const PlateArguments& args);

}  // namespace hamiltone::cli
