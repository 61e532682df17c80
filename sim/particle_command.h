// `hamiltone-sim particle`: the single particle of [M §3.1] on Marazzato's scheme, against its
// exact solution q(t) = sin⁴t + 1.
#pragma once

#include <CLI/App.hpp>
#include <string>

namespace hamiltone::cli {

// The command line as typed; numbers are parsed and checked by runParticleCommand().
struct ParticleArguments {
  std::string quadrature = "midpoint";
  std::string k = "1e-2", duration = "1", every = "1";
  std::string out;
};

CLI::App* addParticleCommand(CLI::App& app, ParticleArguments& args);

// Validates, simulates, writes the CSV and prints a summary. Throws UsageError on bad input.
int runParticleCommand(const ParticleArguments& args);

}  // namespace hamiltone::cli
