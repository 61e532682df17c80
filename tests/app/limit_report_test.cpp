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

// The live tail, the step before any drop, is said once: its first turn on, not each one after.
TEST(LimitReport, SaysOnceThatTheTailsWentLive) {
  LimitReport report(context());
  Player::Status s;
  s.limit = 16;
  s.liveTail = true;
  s.liveTails = 1;
  EXPECT_THAT(report.update(s, 1.0),
              HasSubstr("live tails on: the audio callback took over 60% of its period"));
  EXPECT_EQ(report.update(s, 2.0), "");
  s.liveTails = 3;
  EXPECT_EQ(report.update(s, 20.0), "");
  EXPECT_THAT(report.update(dropped(1, 15, 0.9), 21.0), HasSubstr("lowered to 15 of 16"));
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
  // Back, then down again: still no more than a line of it every kInterval.
  EXPECT_EQ(report.update(dropped(4, 15, 0.85), 19.0), "");
  EXPECT_THAT(report.update(dropped(4, 15, 0.85), 20.0), HasSubstr("lowered to 15 of 16"));
}

// A load that hovers at the budget: the limit drops by one, comes back after a second of
// headroom, drops again … The lines came two a cycle (lowered, back), every 1.25 s here, where
// the README promises one every 5 s at most; and drops reported after the limit came back say so.
TEST(LimitReport, ALimitThatComesAndGoesIsStillSaidOnceEveryInterval) {
  LimitReport report(context());
  long drops = 0;
  int lowered = 0, back = 0;
  std::string last;
  for (int step = 0; step <= 80; ++step) {  // 20 s, polled every 0.25 s
    const double t = 0.25 * step;
    if (step % 5 == 0) ++drops;  // down at 0, 1.25, 2.5 … s, back 1 s later
    const int limit = step % 5 < 4 ? 15 : 16;
    const std::string line = report.update(dropped(drops, limit, 0.85), t);
    if (line.find("lowered") != std::string::npos) ++lowered, last = line;
    if (line.find("back") != std::string::npos && line.find("lowered") == std::string::npos) ++back;
  }
  EXPECT_LE(lowered, 5);  // at 0, 5, 10, 15 and 20 s
  EXPECT_LE(back, lowered);
  EXPECT_THAT(last, HasSubstr("lowered (4 times) to 15 of 16"));
  // Drops that were all undone by the time they are said.
  LimitReport later(context());
  EXPECT_THAT(later.update(dropped(1, 15, 0.9), 0.0), HasSubstr("lowered to 15"));
  EXPECT_EQ(later.update(dropped(1, 16, 0.9), 1.0), "voice limit back to 16");
  EXPECT_EQ(later.update(dropped(2, 15, 0.9), 2.0), "");
  EXPECT_THAT(later.update(dropped(2, 16, 0.9), 5.0),
              HasSubstr("voice limit lowered and back to 16: the audio callback took 90%"));
  EXPECT_EQ(later.update(dropped(2, 16, 0.9), 6.0), "");
}

}  // namespace
}  // namespace hamiltone::app
