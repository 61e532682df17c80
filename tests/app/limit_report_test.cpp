// The voice-limit lines the main thread prints (app/limit_report.h): when the limit drops, at most
// one line every kInterval seconds, with the load against the budget, the new limit and the cures;
// one line when it is back.
#include "limit_report.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace hamiltone::app {
namespace {

using ::testing::HasSubstr;

LimitContext context(bool jack = false, int threads = 1) {
  return {.budget = 0.8,
          .frames = 128,
          .sampleRate = 48000.0,
          .threads = threads,
          .cores = 4,
          .polyphony = 16,
          .jack = jack};
}

Player::Status dropped(long drops, int limit, double load) {
  Player::Status s;
  s.limit = limit;
  s.limitDrops = drops;
  s.dropLoad = load;
  return s;
}

TEST(LimitReport, SaysNothingWhileTheLimitHolds) {
  LimitReport report(context());
  Player::Status s;
  s.limit = 16;
  for (double t = 0.0; t < 20.0; t += 0.25) EXPECT_EQ(report.update(s, t), "");
}

TEST(LimitReport, SaysWhyTheLimitDroppedAndHowToAvoidIt) {
  LimitReport report(context());
  const std::string line = report.update(dropped(1, 15, 0.93), 1.0);
  EXPECT_THAT(line, HasSubstr("voice limit lowered to 15 of 16"));
  EXPECT_THAT(line, HasSubstr("the audio callback took 93% of its 2.7 ms period (128 frames at "
                              "48000 Hz), over the 80% budget"));
  EXPECT_THAT(line, HasSubstr("a larger buffer (--buffer 256)"));
  EXPECT_THAT(line, HasSubstr("more --threads (1 now, 4 cores)"));
  EXPECT_THAT(line, HasSubstr("fewer --voices"));
}

TEST(LimitReport, OnJackTheBufferIsTheServersPeriod) {
  LimitReport report(context(true, 4));
  const std::string line = report.update(dropped(1, 15, 0.9), 0.0);
  EXPECT_THAT(line, HasSubstr("(the JACK server's period, jackd -p 256)"));
  EXPECT_THAT(line, ::testing::Not(HasSubstr("--threads")));  // every core is used already
}

// Drops in quick succession: one line, then the ones since, kInterval later, counted.
TEST(LimitReport, IsRateLimitedAndCountsTheDropsBetweenLines) {
  LimitReport report(context());
  EXPECT_THAT(report.update(dropped(1, 15, 0.9), 10.0), HasSubstr("lowered to 15 of 16"));
  EXPECT_EQ(report.update(dropped(2, 14, 0.9), 10.25), "");
  EXPECT_EQ(report.update(dropped(3, 13, 0.95), 14.9), "");
  EXPECT_THAT(report.update(dropped(3, 13, 0.95), 15.0),
              HasSubstr("lowered (2 times) to 13 of 16: the audio callback took 95%"));
  EXPECT_EQ(report.update(dropped(3, 14, 0.95), 15.25), "");  // rising: nothing yet
  EXPECT_EQ(report.update(dropped(3, 16, 0.95), 18.0), "voice limit back to 16");
  EXPECT_EQ(report.update(dropped(3, 16, 0.95), 18.25), "");
  EXPECT_THAT(report.update(dropped(4, 15, 0.85), 19.0), HasSubstr("lowered to 15 of 16"));
}

}  // namespace
}  // namespace hamiltone::app
