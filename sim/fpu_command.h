// `hamiltone-sim fpu`: the Fermi–Pasta–Ulam test problem of BDZ §4.1 with any scheme of the engine.
#pragma once

#include <CLI/App.hpp>
#include <string>

namespace hamiltone::cli {

// The command line as typed; numbers are parsed and checked by run().
struct FpuArguments {
  std::string scheme;
  std::string quadrature;
  std::string k = "1e-3", duration = "1", alpha = "1", omega, pairs = "3";  // ω: 50, or √10
  std::string epsilon = "0", sigma0 = "0", every = "1";
  std::string out;
  // --slow-fast: the chain of [M §4.3.1] on the asynchronous scheme (or --sync: synchronous).
  bool slowFast = false, sync = false, allowLongRun = false;
  std::string hs = "1e-2", hf = "2e-4";
  // Set by addFpuCommand: its options' counts tell which flags were given (whatever the text).
  const CLI::App* command = nullptr;
};

// Registers the subcommand and its options on `app`; the returned pointer tells if it was chosen.
CLI::App* addFpuCommand(CLI::App& app, FpuArguments& args);

// Validates, simulates, writes the CSV and prints a summary. Throws UsageError on bad input.
int runFpuCommand(const FpuArguments& args);

}  // namespace hamiltone::cli
