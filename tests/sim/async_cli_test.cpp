// hamiltone-sim fpu --slow-fast and wave-inhomogeneous: summaries that parse as "name: value",
// and bad input refused with exit code 2 and one line naming the flag.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "support/sim_cli.h"

namespace {

using hamiltone::test::CliResult;

namespace fs = std::filesystem;

class AsyncCli : public hamiltone::test::SimCliTest {
 protected:
  std::string csv() const { return (dir_ / "run.csv").string(); }
};

TEST_F(AsyncCli, SlowFastSummaryGivesCountsAndEta) {
  const CliResult r = run("fpu --slow-fast --hs 0.01 --hf 2e-4 --duration 1 --out " + csv());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto s = summary(r.out);
  ASSERT_TRUE(s.count("force evaluations") && s.count("paper N_a") && s.count("paper eta"))
      << r.out;
  EXPECT_EQ(s.at("force evaluations"), 81200.0);  // 4 × 100 × (50·4 + 3)
  EXPECT_NEAR(s.at("paper N_a"), 81200.0, 1e-6);
  EXPECT_NEAR(s.at("paper N_s"), 140000.0, 1e-6);
  EXPECT_NEAR(s.at("paper eta"), 1.015 / 1.75, 1e-12);
  const CliResult sync =
      run("fpu --slow-fast --sync --hs 0.01 --hf 2e-4 --duration 1 --out " + csv());
  ASSERT_EQ(sync.exitCode, 0) << sync.err;
  EXPECT_EQ(summary(sync.out).at("force evaluations"), 140000.0);
}

TEST_F(AsyncCli, WaveSummaryParses) {
  const CliResult r = run("wave-inhomogeneous --dx 2e-3 --sync --out " + csv());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto s = summary(r.out);
  ASSERT_TRUE(s.count("max displacement error") && s.count("force evaluations") &&
              s.count("pseudo-energy drift") && s.count("time"))
      << r.out;
  EXPECT_EQ(s.at("time"), 0.5);
  EXPECT_EQ(s.at("force evaluations"), 1250000.0);  // 2500 steps × 500 springs
  EXPECT_LT(s.at("max displacement error"), 1e-2);
  EXPECT_LT(s.at("pseudo-energy drift"), 1e-12);
  std::ifstream in(csv());
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header, "x,u,exact");
}

TEST_F(AsyncCli, BadInputIsRefused) {
  expectRefused("fpu --slow-fast --hs 0.01 --hf 3e-3 --out " + csv(), "--hs / --hf");
  expectRefused("fpu --slow-fast --hs 1 --hf 0.5 --out " + csv(), "--hf");
  expectRefused("fpu --slow-fast --scheme sv --out " + csv(), "--scheme");
  expectRefused("fpu --slow-fast --quadrature simpson --out " + csv(), "--quadrature");
  expectRefused("fpu --sync --scheme sv --out " + csv(), "--sync");
  expectRefused("fpu --out " + csv(), "--scheme");
  expectRefused("wave-inhomogeneous --ratio 5 --out " + csv(), "--ratio");
  expectRefused("wave-inhomogeneous --dx 3e-3 --out " + csv(), "dx");
  expectRefused("wave-inhomogeneous --duration 0.6 --out " + csv(), "--duration");
  expectRefused("wave-inhomogeneous --ratio 1.5 --out " + csv(), "--ratio");
}

// The total steps of h_F (coarse steps × K) and the particle steps are counted before any step,
// in double: a product beyond `long` or beyond the caps is refused, not run for ever.
TEST_F(AsyncCli, SlowFastStepCountsAreBoundedBeforeRunning) {
  const std::string huge = " --hs 1 --hf 1e-9 --duration 1e10 --every 1000000000 --out ";
  expectRefused("fpu --slow-fast --sync" + huge + csv(), "--duration / --hf");
  expectRefused("fpu --slow-fast" + huge + csv(), "--duration / --hf");
  expectRefused("fpu --slow-fast --hs 1 --hf 1e-9 --duration 1e10 --out " + csv(), "--hs");
  // 1e4 coarse steps × K = 1e4 = 1e8 steps of h_F, but × 1e6 pairs: 1e14 particle steps.
  expectRefused(
      "fpu --slow-fast --pairs 1000000 --hs 1 --hf 1e-4 --duration 1e4 --every "
      "1000000000 --out " +
          csv(),
      "particle steps");
}

// λmax of the fast springs is a closed form: no dense m × m eigenvalue solve before the first
// step (--pairs 4000 took 27 s, --pairs 1000000 died of std::bad_alloc), and --pairs is capped.
TEST_F(AsyncCli, SlowFastLargePairsStartPromptly) {
  const CliResult r = run("fpu --slow-fast --pairs 100000 --duration 0.01 --out " + csv());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("100000 pairs"), std::string::npos) << r.out;
  fs::remove(csv());
  expectRefused("fpu --slow-fast --pairs 1000001 --out " + csv(), "--pairs");
  const CliResult help = run("fpu --help");
  EXPECT_NE(help.out.find("2 … 1e6"), std::string::npos) << help.out;
}

// 1/Δx is bounded before the model is built (--dx 2e-8 built 5 GB and wrote a 2 GB CSV).
TEST_F(AsyncCli, WaveInhomogeneousRefusesAGridBeyondTheMemoryAndOutputGuards) {
  expectRefused("wave-inhomogeneous --dx 2e-8 --duration 1e-7 --out " + csv(), "--dx");
  expectRefused("wave-inhomogeneous --dx 1e-300 --duration 1e-7 --out " + csv(), "--dx");
  expectRefused("wave-inhomogeneous --dx 0.3 --out " + csv(), "--dx = 0.3");
}

// Each message names the flags the command takes: no --k where there is none, the real limit.
TEST_F(AsyncCli, MessagesNameTheFlagsThatApply) {
  const auto expectNoK = [&](const std::string& args, const std::string& mention) {
    expectRefused(args, mention);
    EXPECT_EQ(run(args).err.find("--k"), std::string::npos) << args;
  };
  expectNoK("wave-inhomogeneous --duration 1e-9 --out " + csv(), "--dx");
  expectNoK("fpu --slow-fast --duration 1e-3 --out " + csv(), "--hs");
  expectRefused("fpu --slow-fast --hs 10 --hf 1e-9 --out " + csv(), "at most 1e9");
  expectRefused("fpu --slow-fast --hs 1e-2 --hf 3e-3 --out " + csv(), "integer multiple");
  for (const char* omega : {"1e308", "1e-200"}) {
    const std::string args = "fpu --slow-fast --omega " + std::string(omega) + " --out " + csv();
    expectRefused(args, "--omega");
    EXPECT_EQ(run(args).err.find("CFL"), std::string::npos) << args;
  }
  expectRefused("fpu --scheme sv --omega 1e200 --out " + csv(), "--omega");
}

// "Given" means on the command line, whatever the spelling of its value.
TEST_F(AsyncCli, FlagsCountAsGivenWhateverTheirSpelling) {
  for (const char* hs : {"0.01", "1e-2"})
    expectRefused("fpu --scheme sv --duration 0.01 --hs " + std::string(hs) + " --out " + csv(),
                  "--hs");
  expectRefused("fpu --scheme sv --duration 0.01 --hf 2e-4 --out " + csv(), "--hf");
  for (const char* k : {"1e-3", "0.001"})
    expectRefused("fpu --slow-fast --k " + std::string(k) + " --out " + csv(), "--k");
  for (const char* epsilon : {"0", "0.0"})
    expectRefused("fpu --slow-fast --epsilon " + std::string(epsilon) + " --out " + csv(),
                  "--epsilon");
  expectRefused("fpu --slow-fast --sigma0 0 --out " + csv(), "--sigma0");
  expectRefused("fpu --slow-fast --omega '' --out " + csv(), "--omega");
  expectRefused("fpu --scheme sv --omega '' --out " + csv(), "--omega");
  expectRefused("fpu --slow-fast --hs '' --out " + csv(), "--hs");
  // The defaults written out are still accepted where the flag applies.
  EXPECT_EQ(run("fpu --scheme sv --duration 0.01 --k 1e-3 --omega 50 --out " + csv()).exitCode, 0);
  EXPECT_EQ(
      run("fpu --slow-fast --duration 0.01 --hs 1e-2 --hf 2e-4 --omega 3 --out " + csv()).exitCode,
      0);
}

// The asynchronous scheme's instability overflows at Δx = 2e-5 (t ≈ 0.237): the run stops at
// the first non-finite state and says so. The cheapest case found; about 15 s.
TEST_F(AsyncCli, WaveInhomogeneousStopsAtTheFirstNonFiniteState) {
  const CliResult r = run("wave-inhomogeneous --dx 2e-5 --duration 0.3 --out " + csv());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.err.find("non-finite"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("stopped"), std::string::npos) << r.err;
  EXPECT_LT(summary(r.out).at("time"), 0.3);
}

}  // namespace
