// hamiltone-sim wave as a user meets it: the CSV and snapshot file it writes, a summary of
// "name: value" lines, and every bad input refused with exit code 2, one line naming the flag.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "support/sim_cli.h"

namespace {

using hamiltone::test::CliResult;

namespace fs = std::filesystem;

class WaveCli : public hamiltone::test::SimCliTest {
 protected:
  WaveCli() { subcommand_ = "wave "; }
};

TEST_F(WaveCli, WritesTheDocumentedCsvAndSummary) {
  // 0.1 / 0.0033 → 30 steps; rows at n = 0, 5, …, 30.
  const CliResult r =
      run("--alpha 0.8 --amplitude 0.1 --quadrature gl3 --duration 0.1 --every 5 "
          "--out " +
          path("run.csv"));
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  std::string header;
  const auto rows = parseCsv(slurp(path("run.csv")), header);
  EXPECT_EQ(header, "t,h,pseudo_energy,energy,gap,u1_mid,u2_mid");
  ASSERT_EQ(rows.size(), 7u);
  EXPECT_DOUBLE_EQ(rows[0][5], 0.1);  // u(0.5, 0) = u0 sin(π/2)
  for (size_t i = 0; i < rows.size(); ++i) {
    ASSERT_EQ(rows[i].size(), 7u);
    EXPECT_NEAR(rows[i][0], 0.0165 * static_cast<double>(i), 1e-15);
    EXPECT_EQ(rows[i][1], i > 0 ? 0.0033 : 0.0);
    EXPECT_NEAR(rows[i][2], rows[0][2], 1e-13 * rows[0][2]);  // (13) conserved (gl3)
    EXPECT_NEAR(rows[i][4], rows[i][3] - rows[i][2], 1e-16);  // gap = H − H̃
    EXPECT_GE(rows[i][4], 0.0);                               // (18)
  }
  const auto s = summary(r.out);
  EXPECT_EQ(s.at("steps"), 30);
  EXPECT_EQ(s.at("rejected steps"), 0);
  EXPECT_EQ(s.at("force evaluations"), 90);
  EXPECT_EQ(s.at("pseudo-energy at t = 0"), rows[0][2]);
  EXPECT_LT(s.at("max relative pseudo-energy drift"), 1e-13);
  EXPECT_LT(s.at("max absolute pseudo-energy drift"), 1e-13 * rows[0][2]);
  EXPECT_EQ(s.at("min step"), 0.0033);
  EXPECT_EQ(s.at("max step"), 0.0033);
  EXPECT_EQ(s.count("max gap / (eps_fly pseudo-energy)"), 0u);
}

TEST_F(WaveCli, SnapshotsHoldEveryNodeAtTheFirstStepAtOrAfterEachTime) {
  const CliResult r = run("--duration 0.1 --dx 0.05 --snapshots 0.05,0,0.1 --snapshot-out " +
                          path("snap.csv") + " --out " + path("run.csv"));
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("snapshots: wrote"), std::string::npos) << r.out;
  std::string header;
  const auto rows = parseCsv(slurp(path("snap.csv")), header);
  EXPECT_EQ(header, "t,x,u1,u2");
  ASSERT_EQ(rows.size(), 3u * 21u);  // 3 times × (19 interior nodes + 2 ends)
  // 0 → t = 0; 0.05 → step 16 (0.0528); 0.1 is past the last step (30 · 0.0033 = 0.099).
  const double times[] = {0.0, 16 * 0.0033, 30 * 0.0033};
  for (int s = 0; s < 3; ++s)
    for (int j = 0; j <= 20; ++j) {
      const auto& row = rows[s * 21 + j];
      EXPECT_NEAR(row[0], times[s], 1e-15) << s;
      EXPECT_NEAR(row[1], 0.05 * j, 1e-15);
      if (j == 0 || j == 20) {
        EXPECT_EQ(row[2], 0.0);
        EXPECT_EQ(row[3], 0.0);
      }
    }
  EXPECT_DOUBLE_EQ(rows[10][2], 0.3);  // u1(0.5, 0) = u0
}

TEST_F(WaveCli, AdaptiveRunReportsItsStepsAndTheGapBound) {
  const CliResult r = run("--adaptive --k 0.005 --duration 0.3 --out " + path("run.csv"));
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto s = summary(r.out);
  EXPECT_LE(s.at("max gap / (eps_fly pseudo-energy)"), 1.0);
  EXPECT_GT(s.at("rejected steps"), 0);
  EXPECT_LT(s.at("min step"), 0.005);
  EXPECT_EQ(s.at("max step"), 0.005);
  EXPECT_EQ(s.at("force evaluations"), s.at("steps") + s.at("rejected steps"));  // midpoint
  std::string header;
  const auto rows = parseCsv(slurp(path("run.csv")), header);
  ASSERT_EQ(static_cast<double>(rows.size()), s.at("steps") + 1);
  EXPECT_LE(rows.back()[0], 0.3 + 1e-12);
  EXPECT_GT(rows.back()[0] + s.at("max step"), 0.3);
  for (const auto& row : rows) EXPECT_LE(row[4], 3e-4 * row[2] * (1 + 1e-9));
}

// Parameters that cannot run are bad input (exit 2, as failure-behaviour.md's table says), not an
// I/O error (1), even when found after the start; the message names the subcommand.
TEST_F(WaveCli, AStepBelowTheMinimumEndsTheRunWithAnError) {
  const CliResult r = run("--adaptive --eps-fly 1e-12 --min-step 0.001 --out " + path("run.csv"));
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_NE(r.err.find("hamiltone-sim wave:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--min-step"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::is_empty(dir_));
}

TEST_F(WaveCli, HelpDocumentsTheOptions) {
  const CliResult r = run("--help");
  EXPECT_EQ(r.exitCode, 0);
  for (const char* text : {"--alpha", "--amplitude", "--quadrature", "--dx", "--k", "--duration",
                           "--adaptive", "--eps-fly", "--min-step", "--every", "--snapshots",
                           "--snapshot-out", "--out", "sin πx", "doubles"})
    EXPECT_NE(r.out.find(text), std::string::npos) << text;
}

TEST_F(WaveCli, RefusesBadInput) {
  const std::string ok = "--out " + path("run.csv");
  expectRefused(ok + " --alpha 1", "--alpha");
  expectRefused(ok + " --alpha -0.1", "--alpha");
  expectRefused(ok + " --alpha x", "--alpha");
  expectRefused(ok + " --amplitude 0", "--amplitude");
  expectRefused(ok + " --dx 0.03", "--dx");
  expectRefused(ok + " --dx 0.7", "--dx");
  expectRefused(ok + " --dx 0", "--dx");
  expectRefused(ok + " --k 0", "--k");
  expectRefused(ok + " --k 1e-3x", "--k");
  expectRefused(ok + " --duration -1", "--duration");
  expectRefused(ok + " --every 0", "--every");
  expectRefused(ok + " --quadrature simpson", "--quadrature");
  expectRefused(ok + " --adaptive --eps-fly 0", "--eps-fly");
  expectRefused(ok + " --adaptive --min-step 0.01", "--min-step");
  expectRefused(ok + " --adaptive --min-step nan", "--min-step");
  expectRefused(ok + " --snapshots 0.5", "--snapshot-out");
  expectRefused(ok + " --snapshot-out " + path("s.csv"), "--snapshots");
  expectRefused(ok + " --snapshots 2 --snapshot-out " + path("s.csv"), "--snapshots");
  expectRefused(ok + " --snapshots 0.1,abc --snapshot-out " + path("s.csv"), "--snapshots");
  expectRefused(ok + " --snapshots 0.1, --snapshot-out " + path("s.csv"), "--snapshots");
  expectRefused("--alpha 0.5", "--out");
}

// k < dx/√3, the scheme's linear stability bound (c = 1, consistent mass), in both modes; the
// message names --k, the bound and --dx.
TEST_F(WaveCli, RefusesAStepAtOrAboveTheStabilityBound) {
  const std::string ok = "--duration 0.02 --out " + path("run.csv");
  for (const std::string& args : {ok + " --k 0.006", ok + " --k 0.006 --adaptive",
                                  ok + " --k 0.0057736", ok + " --dx 0.02 --k 0.0116"}) {
    expectRefused(args, "--k");
    expectRefused(args, "--dx");
    expectRefused(args, args.find("--dx 0.02") != std::string::npos ? "0.0115470" : "0.0057735");
  }
  EXPECT_EQ(run(ok + " --k 0.0057").exitCode, 0);
  EXPECT_EQ(run(ok + " --dx 0.02 --k 0.0115 --adaptive").exitCode, 0);
}

// --eps-fly and --min-step mean nothing at a fixed step: refused without --adaptive, even when
// empty; with it, an empty value is refused rather than taken as the default.
TEST_F(WaveCli, AdaptiveOnlyFlagsNeedAdaptive) {
  const std::string ok = "--duration 0.02 --out " + path("run.csv");
  expectRefused(ok + " --eps-fly 1e-3", "--eps-fly");
  expectRefused(ok + " --eps-fly 1e-3", "--adaptive");
  expectRefused(ok + " --min-step 1e-4", "--min-step");
  expectRefused(ok + " --min-step 1e-4", "--adaptive");
  expectRefused(ok + " --eps-fly 3e-4", "--adaptive");  // the default value, typed
  expectRefused(ok + " --min-step ''", "--adaptive");
  expectRefused(ok + " --adaptive --min-step ''", "--min-step");
  expectRefused(ok + " --adaptive --eps-fly ''", "--eps-fly");
  EXPECT_EQ(run(ok + " --adaptive --eps-fly 1e-3 --min-step 1e-4").exitCode, 0);
}

// A start with no energy (a tiny amplitude underflows V to 0): the summary says so instead of a
// NaN, and --adaptive, whose bound is relative to that energy, is refused naming --amplitude.
TEST_F(WaveCli, AStartWithNoEnergyHasNoDriftAndNoAdaptiveStep) {
  const CliResult r = run("--amplitude 1e-200 --duration 0.02 --out " + path("run.csv"));
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(r.out.find("nan"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("inf"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("max relative pseudo-energy drift: no energy to drift"), std::string::npos)
      << r.out;
  EXPECT_EQ(summary(r.out).at("pseudo-energy at t = 0"), 0.0);
  fs::remove(path("run.csv"));
  expectRefused("--amplitude 1e-200 --adaptive --out " + path("run.csv"), "--amplitude");
  expectRefused("--amplitude 1e-160 --adaptive --out " + path("run.csv"), "--amplitude");
}

// --snapshot-out naming --out's file in another spelling is refused, as in string and plate.
TEST_F(WaveCli, RefusesSnapshotsIntoTheMainCsv) {
  const std::string ok = "--duration 0.02 --snapshots 0 --out " + path("run.csv");
  expectRefused(ok + " --snapshot-out " + path("run.csv"), "--snapshot-out");
  expectRefused(ok + " --snapshot-out " + (dir_ / "." / "run.csv").string(), "--snapshot-out");
  expectRefused(ok + " --snapshot-out " + dir_.string() + "//run.csv", "--snapshot-out");
}

// Killed with both files open, the run leaves neither temporary (the signal handler knows both).
TEST_F(WaveCli, InterruptedRunWithSnapshotsLeavesNoFile) {
  const int code =
      shell(std::string(HAMILTONE_SIM) +
            " wave --dx 0.001 --k 5e-4 --duration 1e4 --every 1000000 --snapshots 0,1e4" +
            " --snapshot-out " + path("snap.csv") + " --out " + path("run.csv") +
            " >/dev/null 2>&1 & pid=$!; sleep 0.3; kill -TERM $pid; wait $pid; exit $?");
  EXPECT_EQ(code, 128 + SIGTERM);
  EXPECT_TRUE(fs::is_empty(dir_)) << fs::directory_iterator(dir_)->path();
}

// A full disk under the snapshot file: exit 1, and the main CSV, written whole, is not published
// alone.
TEST_F(WaveCli, AFullDiskForTheSnapshotsLeavesNeitherFile) {
  const fs::path full = dir_ / "full";
  hamiltone::test::TinyDisk disk(full);
  if (!disk.mounted()) GTEST_SKIP() << "cannot mount a 64 KiB tmpfs here (needs root)";
  std::string times = "0";
  for (int i = 1; i <= 30; ++i) {
    times += ',';
    times += std::to_string(i * 0.0033);
  }  // 31 fields of 101 nodes: about 100 KB
  const CliResult r = run("--duration 0.1 --snapshots " + times + " --snapshot-out " +
                          (full / "snap.csv").string() + " --out " + path("run.csv"));
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_NE(r.err.find("snap.csv"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("run.csv")));
  EXPECT_TRUE(fs::is_empty(full));
}

}  // namespace
