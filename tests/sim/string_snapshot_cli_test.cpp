// hamiltone-sim string --snapshots: the whole string at the first step at or after each requested
// time, and every bad request refused with exit code 2, a line naming the flag and no file.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "support/sim_cli.h"

namespace {

using hamiltone::test::CliResult;

namespace fs = std::filesystem;

struct Row {
  double t, x, u, v;
};

class StringSnapshotCli : public hamiltone::test::SimCliTest {
 protected:
  StringSnapshotCli() { subcommand_ = "string "; }

  // The rows of a CSV file whose header is `header`.
  static std::vector<std::vector<double>> read(const std::string& file, const std::string& header) {
    std::string found;
    auto rows = parseCsv(slurp(file), found);
    EXPECT_EQ(found, header);
    return rows;
  }
};

// A 40-segment string on a fixed grid, k = 1 µs, 0.2 ms: small enough to run in milliseconds.
const std::string kGrid = "--segments 40 --k 1e-6 --duration 2e-4 ";
const std::string kRun = kGrid + "--alpha 100 ";

TEST_F(StringSnapshotCli, WritesEveryNodeAtTheFirstStepAtOrAfterEachTime) {
  const CliResult r = run(kRun + "--snapshots 0,5.5e-5,2e-4 --snapshot-out " + path("snap.csv") +
                          " --out " + path("run.csv"));
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto rows = read(path("snap.csv"), "t,x,u,v");
  std::map<double, std::vector<std::vector<double>>> byTime;
  for (const auto& row : rows) {
    ASSERT_EQ(row.size(), 4u);
    byTime[row[0]].push_back(row);
  }
  // t = 5.5e-5 falls on step 55 (k = 1e-6): ceil, not round; 0 and the last step are included.
  ASSERT_EQ(byTime.size(), 3u);
  const std::vector<double> expected{0.0, 55e-6, 200e-6};
  int i = 0;
  for (const auto& [t, nodes] : byTime) {
    EXPECT_NEAR(t, expected[i++], 1e-12);
    ASSERT_EQ(nodes.size(), 41u);  // segments + 1 nodes, the fixed ends included
    const double h = 1.259 / 40;
    for (std::size_t j = 0; j < nodes.size(); ++j) EXPECT_NEAR(nodes[j][1], j * h, 1e-12);
    EXPECT_EQ(nodes.front()[2], 0.0);
    EXPECT_EQ(nodes.back()[3], 0.0);
  }
  // At t = 0 the string is the first mode (70), u = α sqrt(A) sin(πx/L), and v = 0.
  const auto& start = byTime.begin()->second;
  for (const auto& node : start) {
    EXPECT_NEAR(node[2], 100 * std::sqrt(8.87e-7) * std::sin(std::numbers::pi * node[1] / 1.259),
                1e-12);
    EXPECT_EQ(node[3], 0.0);
  }
  // The snapshot's midpoint is the probe column of the main CSV at the same step.
  const auto probe = read(path("run.csv"), "t,u,v,energy,psi");
  ASSERT_EQ(probe.size(), 201u);
  EXPECT_EQ(byTime.rbegin()->second[20][2], probe[200][1]);
  EXPECT_EQ(byTime.rbegin()->second[20][3], probe[200][2]);
}

TEST_F(StringSnapshotCli, WorksWithEverySchemeAndTheHammer) {
  for (const std::string extra : {"--alpha 100 --scheme sv", "--alpha 100 --scheme implicit",
                                  "--alpha 0 --hammer-velocity 2"}) {
    const CliResult r = run(kGrid + extra + " --snapshots 1e-4 --snapshot-out " + path("snap.csv") +
                            " --out " + path("run.csv"));
    ASSERT_EQ(r.exitCode, 0) << extra << "\n" << r.err;
    EXPECT_EQ(read(path("snap.csv"), "t,x,u,v").size(), 41u) << extra;
  }
}

TEST_F(StringSnapshotCli, RefusesBadRequestsNamingTheFlagAndWritesNothing) {
  const std::string files = " --out " + path("run.csv");
  const std::string snap = " --snapshot-out " + path("snap.csv");
  const std::vector<std::pair<std::string, std::string>> cases{
      {"--snapshots 1e-4" + files, "--snapshots"},               // no file for them
      {snap + files, "--snapshot-out"},                          // no times
      {"--snapshots 3e-4" + snap + files, "--snapshots"},        // after --duration
      {"--snapshots -1e-5" + snap + files, "--snapshots"},       // negative
      {"--snapshots 1e-4,abc" + snap + files, "--snapshots"},    // not a number
      {"--snapshots 1e-4,,2e-4" + snap + files, "--snapshots"},  // empty item
      {"--snapshots nan" + snap + files, "--snapshots"},         // not finite
      {"--snapshots 1e-4 --snapshot-out /nonexistent/dir/s.csv" + files, "--snapshot-out"},
      {"--snapshots 1e-4 --snapshot-out " + (dir_ / "." / "run.csv").string() + files,
       "--snapshot-out"},  // --out, spelled differently
  };
  for (const auto& [args, flag] : cases) expectRefused(kRun + args, flag);
}

// Past the file-size limit (ulimit -f) with both files open, SIGXFSZ ends the run with 128 + 25
// and removes both temporaries, not just the last one made.
TEST_F(StringSnapshotCli, AFileSizeLimitLeavesNeitherFileNorTemporary) {
  // 201 fields of 41 nodes (about 700 KB) and 201 rows against a limit of a few KB.
  std::string times = "0";
  for (int i = 1; i <= 200; ++i) {
    times += ',';
    times += std::to_string(i * 1e-6);
  }
  const int code = shell("ulimit -f 16 && " + std::string(HAMILTONE_SIM) + " string " + kRun +
                         "--snapshots " + times + " --snapshot-out " + path("snap.csv") +
                         " --out " + path("run.csv") + " >/dev/null 2>&1");
  if (code != 128 + SIGXFSZ) GTEST_SKIP() << "ulimit -f did not take (exit " << code << ")";
  EXPECT_TRUE(fs::is_empty(dir_)) << fs::directory_iterator(dir_)->path();
}

}  // namespace
