// What the hamiltone-sim command-line tests share: a scratch directory per test, the program run
// with its output captured, and the readers of its "name: value" summary.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "support/scratch_dir.h"
#include "support/tiny_disk.h"

namespace hamiltone::test {

struct CliResult {
  int exitCode;
  std::string out, err;
};

class SimCliTest : public ::testing::Test {
 protected:
  // `shell` run by /bin/sh; its exit code as the shell reports it (128 + N for a signal N).
  static int shell(const std::string& shell) {
    const int status = std::system(shell.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }

  // `hamiltone-sim [SUBCOMMAND] ARGS` with stdin closed; the scratch directory is left as it was.
  CliResult run(const std::string& args) {
    const std::string cmd = timeout_ + std::string(HAMILTONE_SIM) + " " + subcommand_ + args +
                            " >" + path("stdout") + " 2>" + path("stderr") + " </dev/null";
    const int status = std::system(cmd.c_str());
    CliResult r{WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(path("stdout")),
                slurp(path("stderr"))};
    std::filesystem::remove(path("stdout"));
    std::filesystem::remove(path("stderr"));
    return r;
  }

  // Exit 2, a single line on stderr that mentions `mention`, nothing on stdout, no file left.
  void expectRefused(const std::string& args, const std::string& mention) {
    const CliResult r = run(args);
    EXPECT_EQ(r.exitCode, 2) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(mention), std::string::npos) << args << "\nstderr: " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
    EXPECT_TRUE(std::filesystem::is_empty(dir_)) << args << ": left a file behind";
  }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  // The rows of a CSV text as numbers, after its leading '#' comment lines and its header.
  static std::vector<std::vector<double>> parseCsv(const std::string& text, std::string& header) {
    std::istringstream in(text);
    while (std::getline(in, header) && header.starts_with('#')) {
    }
    std::vector<std::vector<double>> rows;
    for (std::string line; std::getline(in, line);) {
      std::vector<double> row;
      std::istringstream cells(line);
      for (std::string cell; std::getline(cells, cell, ',');) row.push_back(std::stod(cell));
      rows.push_back(row);
    }
    return rows;
  }

  static std::string slurp(const std::filesystem::path& p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }

  // The "name: value" lines of a summary whose value is one number.
  static std::map<std::string, double> summary(const std::string& out) {
    std::map<std::string, double> values;
    std::istringstream lines(out);
    for (std::string line; std::getline(lines, line);) {
      const auto colon = line.find(": ");
      if (colon == std::string::npos) continue;
      char* end = nullptr;
      const std::string value = line.substr(colon + 2);
      const double v = std::strtod(value.c_str(), &end);
      if (end != value.c_str() && *end == '\0') values[line.substr(0, colon)] = v;
    }
    return values;
  }

  hamiltone::testing::ScratchDir scratch_{"hamiltone-cli"};
  const std::filesystem::path dir_ = scratch_.path();
  std::string subcommand_;  // "wave ", "string ", …: put before every run's ARGS, if set
  // "timeout 60 ": for a test whose command would run for ever where the code under test is
  // wrong, so that it fails (exit 124) instead of hanging.
  std::string timeout_;
};

}  // namespace hamiltone::test
