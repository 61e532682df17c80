// hamiltone-sim fpu as a user meets it: the CSV it writes, and every bad input refused with
// exit code 2, one line naming the argument, and no output file.
#include "support/sim_cli.h"

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace {

using hamiltone::test::CliResult;

namespace fs = std::filesystem;

class SimCli : public hamiltone::test::SimCliTest {
 protected:
  std::string csv() const { return (dir_ / "run.csv").string(); }
};

TEST_F(SimCli, WritesTheDocumentedCsv) {
  const CliResult r =
      run("fpu --scheme sav-split --k 1e-3 --duration 0.01 --alpha 10 --every 3 --out " + csv());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("max relative energy drift (51)"), std::string::npos) << r.out;
  std::string header;
  const auto rows = parseCsv(slurp(csv()), header);
  EXPECT_EQ(header, "t,q1,q2,q3,q4,q5,q6,energy,kinetic,potential");
  // Steps 0, 3, 6, 9 of 10.
  ASSERT_EQ(rows.size(), 4u);
  for (size_t i = 0; i < rows.size(); ++i) {
    ASSERT_EQ(rows[i].size(), 10u);
    EXPECT_NEAR(rows[i][0], 3e-3 * static_cast<double>(i), 1e-15);
    EXPECT_NEAR(rows[i][7], rows[0][7], 1e-12 * rows[0][7]);  // (41) conserved
    EXPECT_NEAR(rows[i][7], rows[i][8] + rows[i][9], 1e-12 * rows[0][7]);
  }
  EXPECT_EQ(rows[0][4], 10.0);  // q(0) = α e₄, printed exactly
  EXPECT_TRUE(fs::is_regular_file(csv()));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1);
}

TEST_F(SimCli, EverySchemeRunsAndDivergenceIsReported) {
  for (const std::string scheme : {"sv", "sav", "sav-split", "marazzato --quadrature gl5"}) {
    const CliResult r = run("fpu --scheme " + scheme + " --duration 0.05 --out " + csv());
    EXPECT_EQ(r.exitCode, 0) << scheme << ": " << r.err;
    EXPECT_TRUE(r.err.empty()) << r.err;
  }
  // Störmer–Verlet at α = 100, k = 0.02 blows up; the run stops with a warning, the file is whole.
  const CliResult r = run("fpu --scheme sv --alpha 100 --k 0.02 --duration 10 --out " + csv());
  EXPECT_EQ(r.exitCode, 0);
  EXPECT_NE(r.err.find("non-finite"), std::string::npos) << r.err;
  std::string header;
  const auto rows = parseCsv(slurp(csv()), header);
  ASSERT_FALSE(rows.empty());
  EXPECT_LT(rows.size(), 500u);
  EXPECT_FALSE(std::isfinite(rows.back()[7]) && std::isfinite(rows.back()[4]));
}

TEST_F(SimCli, HelpDocumentsTheOptions) {
  const CliResult r = run("fpu --help");
  EXPECT_EQ(r.exitCode, 0);
  for (const char* flag : {"--scheme", "--quadrature", "--k", "--duration", "--alpha", "--omega",
                           "--pairs", "--epsilon", "--sigma0", "--every", "--out", "H^{n+1/2}"})
    EXPECT_NE(r.out.find(flag), std::string::npos) << flag;
}

TEST_F(SimCli, RefusesBadInput) {
  const std::string ok = "fpu --scheme sav --out " + csv();
  expectRefused(ok + " --bogus 1", "--bogus");
  expectRefused(ok + " --k abc", "--k");
  expectRefused(ok + " --k 1e-3x", "--k");
  expectRefused(ok + " --k nan", "--k");
  expectRefused(ok + " --k inf", "--k");
  expectRefused(ok + " --k 0", "--k");
  expectRefused(ok + " --k -1e-3", "--k");
  expectRefused(ok + " --duration 0", "--duration");
  expectRefused(ok + " --omega -50", "--omega");
  expectRefused(ok + " --pairs 1", "--pairs");
  expectRefused(ok + " --pairs 2.5", "--pairs");
  expectRefused(ok + " --every 0", "--every");
  expectRefused(ok + " --sigma0 -1", "--sigma0");
  expectRefused(ok + " --quadrature gl2", "--quadrature");
  expectRefused("fpu --scheme rk4 --out " + csv(), "--scheme");
  expectRefused("fpu --scheme marazzato --quadrature simpson --out " + csv(), "--quadrature");
  expectRefused("fpu --scheme marazzato --sigma0 1 --out " + csv(), "--sigma0");
  expectRefused("fpu --scheme sv --epsilon 1 --out " + csv(), "--epsilon");
  expectRefused("fpu --scheme sav-split --k 0.05 --out " + csv(), "(44)");
  expectRefused("fpu --scheme sav", "--out");
  expectRefused("", "subcommand");
}

TEST_F(SimCli, RefusesAnUnwritableOutput) {
  expectRefused("fpu --scheme sav --out " + (dir_ / "missing-dir" / "run.csv").string(), "--out");
  expectRefused("fpu --scheme sav --out " + dir_.string(), "--out");
}

// The stability error comes after the output file was opened: the old file must survive it.
TEST_F(SimCli, LeavesAnExistingFileAloneOnError) {
  { std::ofstream(csv()) << "keep\n"; }
  const CliResult r = run("fpu --scheme sav-split --k 0.05 --out " + csv());
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_NE(r.err.find("(44)"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(csv()), "keep\n");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1);
}

// Times print exactly (17 digits: 3 · 0.1 is 0.30000000000000004), the last step is written,
// and duration / k = 2.9999999999999996 still counts as 3 steps.
TEST_F(SimCli, TimesAreExactAndTheLastStepIsWritten) {
  ASSERT_EQ(run("fpu --scheme sav --k 0.1 --duration 0.3 --out " + csv()).exitCode, 0);
  std::string header;
  const auto rows = parseCsv(slurp(csv()), header);
  ASSERT_EQ(rows.size(), 4u);
  for (size_t n = 0; n < rows.size(); ++n) EXPECT_EQ(rows[n][0], static_cast<double>(n) * 0.1);
}

// With loss the reported drift is that of energy + dissipated, which (50) keeps constant.
TEST_F(SimCli, LossyRunReportsTheBalanceDrift) {
  const CliResult r = run("fpu --scheme sav-split --sigma0 2 --alpha 10 --out " + csv());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto at = r.out.find("drift (51): ");
  ASSERT_NE(at, std::string::npos) << r.out;
  EXPECT_LT(std::stod(r.out.substr(at + 12)), 1e-12) << r.out;
  EXPECT_NE(r.out.find("dissipated"), std::string::npos) << r.out;
}

TEST_F(SimCli, RefusesSpecialFilesAndFollowsSymlinks) {
  expectRefused("fpu --scheme sav --out /dev/null", "not a regular file");
  const fs::path target = dir_ / "target.csv", link = dir_ / "link.csv";
  { std::ofstream(target) << "old\n"; }
  fs::permissions(target, fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
  fs::create_symlink(target, link);
  ASSERT_EQ(run("fpu --scheme sav --duration 0.01 --out " + link.string()).exitCode, 0);
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(slurp(target).rfind("t,q1", 0), 0u);
  EXPECT_EQ(fs::status(target).permissions() & fs::perms::all,
            fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
}

TEST_F(SimCli, RefusesStartsAndOutputsBeyondDoublePrecision) {
  const std::string ok = "fpu --scheme sav --out " + csv();
  expectRefused(ok + " --alpha 1e100", "--alpha");
  expectRefused(ok + " --alpha 1e-320", "too small");
  expectRefused(ok + " --pairs 1000000 --duration 100", "--every");
}

// Killed mid-run, the program leaves neither the output nor its temporary.
// Messages name the flag at fault and print computed numbers to a few digits: not a step count
// in 300 fixed-point digits, a NaN as "-nan", or "--duration / --k" for a --k longer than the run.
TEST_F(SimCli, MessagesNameTheFlagAtFaultWithReadableNumbers) {
  const struct {
    std::string args, mention;
  } cases[] = {
      {"fpu --scheme sav --k 1e300", "--k = 1e+300 s: longer than --duration = 1 s"},
      {"fpu --scheme sav --duration 1e300", "--duration / --k = 1e+303 steps"},
      {"particle --k 1e-300", "--duration / --k = 1e+300 steps"},
      {"string --k 1e-300 --duration 1e-299", "the grid would have 2.364e+296 segments"},
      {"string --alpha 1e300", "energy is NaN"},
      {"plate --thickness 1e-300", "is NaN"},
      {"plate --poisson 1e300", "--poisson = 1e300"},
      {"plate --young 1e300", "h = 1.653e+70 m"},
  };
  const std::regex longNumber("[0-9]{10,}");
  for (const auto& c : cases) {
    const hamiltone::test::CliResult r = run(c.args + " --out " + path("out.csv"));
    EXPECT_EQ(r.exitCode, 2) << c.args << "\n" << r.err;
    EXPECT_NE(r.err.find(c.mention), std::string::npos) << c.args << "\n" << r.err;
    EXPECT_EQ(r.err.find("nan"), std::string::npos) << c.args << "\n" << r.err;
    EXPECT_FALSE(std::regex_search(r.err, longNumber)) << c.args << "\n" << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
  EXPECT_TRUE(std::filesystem::is_empty(dir_));
}

// A run that would take days is refused before it starts, with the estimate, unless asked for:
// --allow-long-run lifts the limit (here the next check, an unwritable --out, then speaks).
TEST_F(SimCli, RefusesARunThatWouldTakeTooLongUnlessAllowed) {
  timeout_ = "timeout 120 ";
  const std::string fpu =
      "fpu --scheme sav --pairs 1000000 --k 1e-6 --duration 100 --every 1000000000";
  const std::string wave = "wave --dx 1e-6 --k 1e-7 --duration 10 --every 1000000000";
  // The string and the plate started runs of a day or more without a word.
  const std::string string = "string --segments 2000 --k 1e-10 --duration 1 --every 1000000000";
  const std::string plate = "plate --k 1e-7 --duration 3 --every 1000000000";
  for (const std::string& args : {fpu, wave, string, plate}) {
    for (const char* mention : {"days", "--allow-long-run", "per second"})
      expectRefused(args + " --out " + path("out.csv"), mention);
    expectRefused(args + " --allow-long-run --out " + path("no-dir/out.csv"), "--out");
  }
  expectRefused(
      "fpu --scheme marazzato --quadrature gl5 --pairs 1000000 --k 1e-3 --duration 1000 "
      "--every 1000000000 --out " +
          path("out.csv"),
      "--allow-long-run");
  expectRefused(
      "plate --scheme implicit --k 1e-7 --duration 0.1 --every 1000000000 --out " + path("out.csv"),
      "point²-steps");
  // Under its cap of 1e12 particle-steps, yet over an hour (about 1.1 h at midpoint): it ran on.
  for (const char* mention : {"1.111 h", "--allow-long-run"})
    expectRefused("wave-inhomogeneous --dx 1e-7 --duration 0.001 --out " + path("out.csv"),
                  mention);
}

TEST_F(SimCli, InterruptedRunLeavesNoFile) {
  const std::string cmd = std::string(HAMILTONE_SIM) +
                          " fpu --scheme sav --pairs 1000 --duration 1e4 --every 1000 --out " +
                          csv() +
                          " >/dev/null 2>&1 & pid=$!; sleep 1; kill -TERM $pid; wait $pid; exit $?";
  const int status = std::system(cmd.c_str());
  EXPECT_EQ(WEXITSTATUS(status), 128 + SIGTERM);
  EXPECT_TRUE(fs::is_empty(dir_)) << fs::directory_iterator(dir_)->path();
}

TEST_F(SimCli, StringWritesTheDocumentedCsv) {
  const CliResult r = run("string --duration 1e-3 --every 500 --out " + csv());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  std::istringstream text(slurp(csv()));
  std::string comment;
  std::getline(text, comment);
  EXPECT_EQ(comment.rfind("# segments=909 h=0.00138503850385", 0), 0u) << comment;
  std::string rest((std::istreambuf_iterator<char>(text)), std::istreambuf_iterator<char>());
  std::string header;
  const auto rows = parseCsv(rest, header);
  EXPECT_EQ(header, "t,u,v,energy,psi");
  ASSERT_EQ(rows.size(), 8u);  // 3846 steps, every 500
  // (70) at the probe x = L/2 (grid point 454 of 909: x = 0.4994 L), α = 300.
  EXPECT_NEAR(rows[0][1], 300.0 * std::sqrt(8.87e-7) * std::sin(M_PI * 454.0 / 909.0), 1e-15);
  for (const auto& row : rows) {
    ASSERT_EQ(row.size(), 5u);
    EXPECT_NEAR(row[3], rows[0][3], 1e-10 * rows[0][3]);  // (41) conserved
  }
}

// The voices' two grids from the research CLI: the paper's C3 (no stiffness) at 48 kHz has 11
// coarse cells (floor(L / (1.05 c_L k))) and u's grid at 1.5 T0 rounded down to a multiple of them;
// the comment line says both; a first-mode start at α = 10 (with a gauge shift, SCHEMES §3b)
// conserves (41); the snapshot's v is linear between the coarse points; --segments fixes one grid,
// so it is refused with the two.
TEST_F(SimCli, StringOnTwoGrids) {
  const std::string snaps = path("snaps.csv");
  const CliResult r =
      run("string --grid two-grid --k 2.0833333333333333e-05 --alpha 10 --epsilon "
          "0.01 --duration 0.01 --every 48 --snapshots 0.005 --snapshot-out " +
          snaps + " --out " + csv());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  std::istringstream text(slurp(csv()));
  std::string comment;
  std::getline(text, comment);
  EXPECT_NE(comment.find(" longitudinal_segments=11 "), std::string::npos) << comment;
  const int segments = std::stoi(comment.substr(comment.find('=') + 1));
  EXPECT_EQ(segments % 11, 0) << comment;
  EXPECT_LT(segments, 136);  // the T0 bound's grid: u is sized for 1.5 T0
  std::string rest((std::istreambuf_iterator<char>(text)), std::istreambuf_iterator<char>());
  std::string header;
  const auto rows = parseCsv(rest, header);
  ASSERT_EQ(rows.size(), 11u);  // 480 steps, every 48
  for (const auto& row : rows) EXPECT_NEAR(row[3], rows[0][3], 1e-10 * rows[0][3]);
  std::string snapHeader;
  const auto nodes = parseCsv(slurp(snaps), snapHeader);
  ASSERT_EQ(nodes.size(), static_cast<size_t>(segments + 1));
  const int cell = segments / 11;  // fine segments per coarse cell
  for (int j = 1; j < cell; ++j)   // inside the first cell, v is on the line from 0 to v(x_1)
    EXPECT_NEAR(nodes[j][3], nodes[cell][3] * j / cell, 1e-12 * std::abs(nodes[cell][3]) + 1e-300)
        << j;
  EXPECT_NE(nodes[cell][3], 0.0);
  std::filesystem::remove(csv());
  std::filesystem::remove(snaps);
  expectRefused("string --grid two-grid --segments 40 --out " + csv(), "--segments = 40");
  expectRefused("string --grid two-grid --tension-margin 0.5 --out " + csv(),
                "--tension-margin = 0.5: out of range");
}

// The implicit reference (67)–(68) writes the same columns and conserves its energy; its u tracks
// the split scheme's on the same grid and step.
TEST_F(SimCli, StringImplicitReferenceWritesTheSameCsv) {
  const std::string common = "string --segments 40 --k 2e-6 --alpha 300 --duration 2e-4 --every 10";
  const CliResult r = run(common + " --scheme implicit --out " + csv());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  std::istringstream text(slurp(csv()));
  std::string comment;
  std::getline(text, comment);
  EXPECT_EQ(comment.rfind("# segments=40 ", 0), 0u) << comment;
  std::string rest((std::istreambuf_iterator<char>(text)), std::istreambuf_iterator<char>());
  std::string header;
  const auto rows = parseCsv(rest, header);
  EXPECT_EQ(header, "t,u,v,energy,psi");
  ASSERT_EQ(rows.size(), 11u);  // 100 steps, every 10
  for (const auto& row : rows) {
    ASSERT_EQ(row.size(), 5u);
    EXPECT_NEAR(row[3], rows[0][3], 1e-10 * rows[0][3]);
    EXPECT_EQ(row[4], 0.0);
  }
  ASSERT_EQ(run(common + " --scheme sav-split --out " + csv()).exitCode, 0);
  std::istringstream other(slurp(csv()));
  std::getline(other, comment);
  std::string rest2((std::istreambuf_iterator<char>(other)), std::istreambuf_iterator<char>());
  const auto sav = parseCsv(rest2, header);
  ASSERT_EQ(sav.size(), rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i)
    EXPECT_NEAR(rows[i][1], sav[i][1], 1e-3 * std::abs(rows[0][1])) << "row " << i;
}

TEST_F(SimCli, StringStrikeWithTheHammer) {
  const CliResult r =
      run("string --grid transverse --k 2.0833333333e-5 --stiffness on --alpha 0 "
          "--hammer-velocity 3 --duration 0.05 --out " +
          csv());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("energy at t = 0: 0.042525"), std::string::npos) << r.out;  // ½ M_H v²
}

TEST_F(SimCli, StringRefusesBadInput) {
  const std::string ok = "string --duration 1e-5 --out " + csv();
  expectRefused(ok + " --probe 1", "--probe");
  expectRefused(ok + " --grid-factor 0.5", "--grid-factor");
  expectRefused(ok + " --grid diagonal", "--grid");
  expectRefused(ok + " --stiffness maybe", "--stiffness");
  expectRefused(ok + " --tension 2e5", "tension");
  expectRefused(ok + " --rho -1", "--rho");
  expectRefused(ok + " --hammer-velocity 3", "--hammer-velocity");
  expectRefused(ok + " --scheme sv --epsilon 1", "--epsilon");
  expectRefused(ok + " --scheme implicit --epsilon 1", "--epsilon");
  expectRefused(ok + " --scheme implicit --sigma0 1", "implicit");
  expectRefused(ok + " --scheme implicit --alpha 0 --hammer-velocity 3", "implicit");
  expectRefused(ok + " --segments 1", "--segments");
  expectRefused(ok + " --segments 100000 --k 1e-5", "(44)");
  expectRefused(ok + " --length 1e-4", "length");
  expectRefused("string --out " + (dir_ / "no" / "x.csv").string(), "--out");
}

TEST_F(SimCli, PlateWritesTheDocumentedCsv) {
  const CliResult r = run("plate --duration 1e-4 --out " + csv());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  std::istringstream text(slurp(csv()));
  std::string comment;
  std::getline(text, comment);
  EXPECT_EQ(comment.rfind("# nx=44 ny=44 h=0.0111111", 0), 0u) << comment;
  std::string rest((std::istreambuf_iterator<char>(text)), std::istreambuf_iterator<char>());
  std::string header;
  const auto rows = parseCsv(rest, header);
  EXPECT_EQ(header, "t,q,energy,psi");
  ASSERT_EQ(rows.size(), 11u);
  for (const auto& row : rows) EXPECT_NEAR(row[2], rows[0][2], 1e-10 * rows[0][2]);  // (41)
  // (85) at the probe's grid point, x = round(0.3·45) = 14, y = 18 segments in: α = 10.
  EXPECT_NEAR(rows[0][1],
              10.0 * 0.002 * std::sin(14.0 * M_PI / 45.0) * std::sin(18.0 * M_PI / 45.0), 1e-15);
}

TEST_F(SimCli, PlateRefusesBadInput) {
  const std::string ok = "plate --duration 1e-4 --out " + csv();
  expectRefused(ok + " --probe 0.3", "--probe");
  expectRefused(ok + " --probe 0.3,1.5", "--probe");
  expectRefused(ok + " --poisson 0.6", "poisson");
  expectRefused(ok + " --thickness 0", "--thickness");
  expectRefused(ok + " --grid-factor 0.9", "--grid-factor");
  expectRefused("plate --k 1 --duration 10 --out " + csv(), "(84)");
  expectRefused(ok + " --scheme sv --alpha 1e200", "--alpha");
}

TEST_F(SimCli, ParticleWritesTheDocumentedCsv) {
  const CliResult r =
      run("particle --quadrature lobatto3 --k 0.01 --duration 1 --every 10 --out " + csv());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  std::string header;
  const auto rows = parseCsv(slurp(csv()), header);
  EXPECT_EQ(header, "t,q,p,q_exact,error,energy,kinetic,potential");
  ASSERT_EQ(rows.size(), 11u);  // steps 0, 10, …, 100
  EXPECT_EQ(rows[0][1], 2.0);   // q(π/2) = 2, p = 0: the start t0 = π/2
  EXPECT_EQ(rows[0][2], 0.0);
  for (const auto& row : rows) {
    ASSERT_EQ(row.size(), 8u);
    EXPECT_NEAR(row[3], std::pow(std::sin(M_PI / 2 + row[0]), 4) + 1.0, 1e-14);  // sin⁴t + 1
    EXPECT_EQ(row[4], row[1] - row[3]);
    // Second order at k = 0.01: the max error is 2.1e-4 (tests/problems/particle_test.cpp).
    EXPECT_LT(std::abs(row[4]), 5e-4) << "t = " << row[0];
    // (13) is H(0) = 0 up to the quadrature error, O(k²) = 1e-4 ([M Remark 2]); measured 2.4e-9.
    EXPECT_LT(std::abs(row[5]), 1e-4) << "t = " << row[0];
  }
}

TEST_F(SimCli, ParticleRefusesBadInput) {
  const std::string ok = "particle --out " + csv();
  expectRefused(ok + " --quadrature simpson", "--quadrature");
  expectRefused(ok + " --k 0", "--k");
  expectRefused(ok + " --duration 1x", "--duration");
  expectRefused(ok + " --every 0", "--every");
}

}  // namespace
