// refuseOptionsAsValues: an option followed by another option, its value forgotten, is refused
// naming both (CLI11 took "--notes" as the preset's name and refused the notes for another
// reason); values that merely start with -, and the forms that hold them, pass.
#include "option_values.h"

#include <gtest/gtest.h>

#include <CLI/App.hpp>
#include <CLI/Config.hpp>
#include <CLI/Formatter.hpp>
#include <string>
#include <vector>

#include "usage_error.h"

namespace {

using hamiltone::cli::refuseOptionsAsValues;
using hamiltone::cli::UsageError;

struct Fixture {
  CLI::App app{"test"};
  std::vector<std::string> presets;
  std::string out, tail, notes;
  bool quiet = false;
  Fixture() {
    app.add_option("--preset", presets)->type_name("FILE|NAME");
    app.add_option("-o,--out", out)->type_name("FILE");
    app.add_option("--tail", tail)->type_name("SECONDS");
    app.add_option("--notes", notes)->type_name("LIST");
    app.add_flag("--quiet", quiet);
  }
  // The message refuseOptionsAsValues gives, or "" when it lets the arguments pass.
  std::string refusal(std::vector<const char*> args) {
    args.insert(args.begin(), "prog");
    try {
      refuseOptionsAsValues(app, static_cast<int>(args.size()), args.data());
    } catch (const UsageError& e) {
      return e.what();
    }
    return "";
  }
};

TEST(OptionValues, AnOptionInPlaceOfAValueIsRefusedNamingBoth) {
  Fixture f;
  EXPECT_EQ(f.refusal({"--preset", "--notes", "C4"}),
            "--preset is missing its value: the argument after it, --notes, is an option; give "
            "--preset FILE|NAME (a value that starts with - as --preset=VALUE)");
  EXPECT_EQ(f.refusal({"--notes", "C4", "-o", "--quiet"}),
            "-o is missing its value: the argument after it, --quiet, is an option; give -o FILE "
            "(a value that starts with - as --out=VALUE)");
  EXPECT_NE(f.refusal({"--preset", "-o", "x.wav"}), "");    // a short option's name
  EXPECT_NE(f.refusal({"--out", "--no-such-option"}), "");  // any -- argument
}

TEST(OptionValues, ValuesThatStartWithADashAndTheirFormsPass) {
  Fixture f;
  EXPECT_EQ(f.refusal({"--tail", "-0.5"}), "");  // a negative number: its parser says why
  EXPECT_EQ(f.refusal({"--out=--x.wav", "--quiet"}), "");
  EXPECT_EQ(f.refusal({"--quiet", "--notes", "C4"}), "");  // a flag takes no value
  EXPECT_EQ(f.refusal({"--", "--preset", "--notes"}), "");
  EXPECT_EQ(f.refusal({"--notes"}), "");  // no value at all: CLI11's own message
}

}  // namespace
