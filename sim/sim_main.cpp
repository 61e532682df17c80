// hamiltone-sim: the papers' test problems from the command line, one subcommand each.
#include <CLI/App.hpp>
#include <CLI/Config.hpp>
#include <CLI/Formatter.hpp>
#include <cstdio>
#include <exception>
#include <string>

#include "fpu_command.h"
#include "option_values.h"
#include "particle_command.h"
#include "plate_command.h"
#include "standard_output.h"
#include "string_command.h"
#include "usage_error.h"
#include "version.h"
#include "wave_command.h"
#include "wave_inhomogeneous_command.h"

namespace {

int runMain(int argc, char** argv) {
  using namespace hamiltone::cli;
  CLI::App app{
      "hamiltone-sim: runs the test problems of Bilbao, Ducceschi & Zama (2022) and "
      "Marazzato et al. (2020) on Hamiltone's schemes and writes CSV."};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("hamiltone-sim ") + versionText());
  FpuArguments fpu;
  CLI::App* fpuCommand = addFpuCommand(app, fpu);
  StringArguments string;
  CLI::App* stringCommand = addStringCommand(app, string);
  PlateArguments plate;
  CLI::App* plateCommand = addPlateCommand(app, plate);
  ParticleArguments particle;
  CLI::App* particleCommand = addParticleCommand(app, particle);
  WaveInhomogeneousArguments waveInhomogeneous;
  CLI::App* waveInhomogeneousCommand = addWaveInhomogeneousCommand(app, waveInhomogeneous);
  WaveArguments wave;
  CLI::App* waveCommand = addWaveCommand(app, wave);

  try {
    refuseOptionsAsValues(app, argc, argv);
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {  // --help, --help-all, --version
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "hamiltone-sim: %s (see hamiltone-sim --help)\n", e.what());
    return kExitUsage;
  } catch (const UsageError& e) {
    std::fprintf(stderr, "hamiltone-sim: %s (see hamiltone-sim --help)\n", e.what());
    return kExitUsage;
  }

  try {
    if (fpuCommand->parsed()) return runFpuCommand(fpu);
    if (stringCommand->parsed()) return runStringCommand(string);
    if (plateCommand->parsed()) return runPlateCommand(plate);
    if (particleCommand->parsed()) return runParticleCommand(particle);
    if (waveInhomogeneousCommand->parsed()) return runWaveInhomogeneousCommand(waveInhomogeneous);
    if (waveCommand->parsed()) return runWaveCommand(wave);
  } catch (const UsageError& e) {
    std::fprintf(stderr, "hamiltone-sim %s: %s\n",
                 app.get_subcommands().front()->get_name().c_str(), e.what());
    return kExitUsage;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hamiltone-sim: error: %s\n", e.what());
    return 1;
  }
  return kExitUsage;
}

}  // namespace

int main(int argc, char** argv) {
  return hamiltone::cli::checkedStandardOutput("hamiltone-sim", runMain(argc, argv));
}
