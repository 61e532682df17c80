// Command-line numbers: what each refusal says. A whole number too large for a long is out of
// range, not "not a whole number" (a hostile test's --sample-rate 18446744073709551664); a unit
// reads as the value's, without a stray space.
#include "number_arguments.h"

#include <gtest/gtest.h>

#include <string>

#include "usage_error.h"

namespace hamiltone::cli {
namespace {

template <class Parse>
std::string refusal(Parse&& parse) {
  try {
    parse();
  } catch (const UsageError& e) {
    return e.what();
  }
  return "(accepted)";
}

TEST(NumberArguments, WholeNumbersPastTheLongRangeAreOutOfRange) {
  for (const std::string huge : {"18446744073709551664", "-99999999999999999999"}) {
    const std::string why = refusal([&] { parseInteger("--sample-rate", huge, 8000, 384000); });
    EXPECT_NE(why.find("out of range; expected a whole number from 8000 to 384000"),
              std::string::npos)
        << why;
  }
  EXPECT_NE(refusal([] { parseInteger("--voices", "1.5", 1, 128); }).find("not a whole number"),
            std::string::npos);
  EXPECT_EQ(parseInteger("--voices", "128", 1, 128), 128);
}

TEST(NumberArguments, TheUnitFollowsTheRange) {
  const std::string why =
      refusal([] { parseReal("--tail", "nan", Range::nonNegative, "seconds"); });
  EXPECT_NE(why.find("expected a finite number >= 0 (seconds)"), std::string::npos) << why;
}

}  // namespace
}  // namespace hamiltone::cli
