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
  void expectRefused(const std::string& args, const std::string& mention) {
    const CliResult r = run(args);
    EXPECT_EQ(r.exitCode, 2) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(mention), std::string::npos) << args << "\nstderr: " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(csv())) << args;
  }
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

}  // namespace
