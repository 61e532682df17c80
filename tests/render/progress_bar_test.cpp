// ProgressBar, renderSummary and stealSummary: the summaries' wording and arithmetic, a disabled
// bar that stays silent, an enabled one that draws one '\r' line, throttled, and clears it, and a
// log's whole lines.
#include "progress_bar.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>

namespace {

using hamiltone::cli::limiterSummary;
using hamiltone::cli::ProgressBar;
using hamiltone::cli::ProgressStyle;
using hamiltone::cli::renderSummary;
using hamiltone::cli::stealSummary;

// A temporary stream standing in for stderr; text() is everything written so far.
class CapturedStream {
 public:
  CapturedStream() : file_(std::tmpfile()) {}
  ~CapturedStream() { std::fclose(file_); }
  std::FILE* get() { return file_; }
  std::string text() {
    std::fflush(file_);
    std::string all;
    std::rewind(file_);
    for (int c; (c = std::fgetc(file_)) != EOF;) all.push_back(static_cast<char>(c));
    return all;
  }

 private:
  std::FILE* file_;
};

TEST(RenderSummary, RealTimeFactorIsWallOverAudioTime) {
  EXPECT_EQ(renderSummary(12.5, 3.1),
            "rendered 12.50 s of audio in 3.10 s (real-time factor 0.248, 4.0x faster than real "
            "time)");
  EXPECT_EQ(renderSummary(2.0, 5.0),
            "rendered 2.00 s of audio in 5.00 s (real-time factor 2.500, 2.5x slower than real "
            "time)");
}

TEST(RenderSummary, NoFactorWithoutAWallTimeOrAudio) {
  EXPECT_EQ(renderSummary(12.5, 0.0), "rendered 12.50 s of audio in 0.00 s");
  EXPECT_EQ(renderSummary(0.0, 1.0), "rendered 0.00 s of audio in 1.00 s");
}

TEST(RenderSummary, StealsWithTheLoudestInDecibels) {
  EXPECT_EQ(stealSummary(0, 0.0, 64), "no key stolen at the limit of 64 voices");
  EXPECT_EQ(stealSummary(1, 1e-3, 64),
            "1 key stolen at the limit of 64 voices, the loudest at -60.0 dB of its own peak");
  EXPECT_EQ(stealSummary(12, 0.5, 16),
            "12 keys stolen at the limit of 16 voices, the loudest at -6.0 dB of its own peak");
}

// The limiter's line: the headroom when it did not act, what it did when it did, and a silent
// output said as such (it read "peak -inf dBFS …, inf dB under its ceiling").
TEST(RenderSummary, LimiterHeadroomOrWhatItDid) {
  EXPECT_EQ(limiterSummary(0, 0, 0.0, 0.5, 0.98, 48000.0),
            "peak -6.0 dBFS before the limiter, 5.8 dB under its ceiling of -0.18 dBFS: it did "
            "not act");
  EXPECT_EQ(limiterSummary(4800, 12, 3.1, 1.4, 0.98, 48000.0),
            "the limiter reduced the gain by up to 3.1 dB on 4800 frames (0.100 s; 12 over its "
            "ceiling of -0.18 dBFS); peak before it +2.9 dBFS");
  EXPECT_EQ(limiterSummary(0, 0, 0.0, 0.0, 0.98, 48000.0),
            "the output is silent: every sample is 0 (the limiter did not act)");
}

TEST(ProgressBar, DisabledWritesNothing) {
  CapturedStream out;
  {
    ProgressBar bar(10.0, ProgressStyle::none, out.get());
    bar.update(0.0);
    bar.update(5.0);
    bar.finish();
  }
  EXPECT_EQ(out.text(), "");
}

TEST(ProgressBar, EnabledDrawsOneLineInPlaceAndClearsIt) {
  CapturedStream out;
  ProgressBar bar(10.0, ProgressStyle::line, out.get());
  bar.update(5.0);
  const std::string line = out.text();
  EXPECT_EQ(line.rfind("\r  50%  5.0 s of 10.0 s  ETA ", 0), 0u) << line;
  EXPECT_EQ(line.find('\n'), std::string::npos);

  bar.finish();
  // Back to the left edge, the drawn characters (all but the '\r') overwritten with spaces, and
  // back again.
  std::string blank(line.size() + 1, ' ');
  blank.front() = blank.back() = '\r';
  const std::string cleared = out.text().substr(line.size());
  EXPECT_EQ(cleared, blank);
  bar.finish();
  EXPECT_EQ(out.text().size(), line.size() + cleared.size());  // nothing left to clear
}

TEST(ProgressBar, RedrawsAtMostTenTimesASecond) {
  CapturedStream out;
  const auto start = std::chrono::steady_clock::now();
  ProgressBar bar(10.0, ProgressStyle::line, out.get());
  for (int i = 1; i <= 100; ++i) bar.update(0.1 * i);
  if (std::chrono::steady_clock::now() - start >= std::chrono::milliseconds(100))
    GTEST_SKIP() << "the machine took 100 ms over 100 updates; a second redraw was allowed";
  const std::string text = out.text();
  EXPECT_EQ(std::count(text.begin(), text.end(), '\r'), 1) << text;
}

// Not on a terminal (a log, a pipe): whole lines, once an interval, none before the first has
// passed — a render into a log said nothing until its summary, however long it took.
TEST(ProgressBar, AsALogWritesAWholeLineEachInterval) {
  CapturedStream out;
  {
    ProgressBar bar(10.0, ProgressStyle::log, out.get(), std::chrono::hours(1));
    bar.update(5.0);
  }
  EXPECT_EQ(out.text(), "");  // shorter than the interval: nothing
  {
    ProgressBar bar(10.0, ProgressStyle::log, out.get(), std::chrono::steady_clock::duration(0));
    bar.update(2.5);
    bar.update(5.0);
  }
  const std::string text = out.text();
  EXPECT_EQ(text.rfind("hamiltone-render:   25%  2.5 s of 10.0 s  ETA ", 0), 0u) << text;
  EXPECT_NE(text.find("\nhamiltone-render:   50%  5.0 s of 10.0 s  ETA "), std::string::npos)
      << text;
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 2) << text;
  EXPECT_EQ(text.find('\r'), std::string::npos) << text;
  EXPECT_EQ(text.back(), '\n');
}

TEST(ProgressBar, DestructorClearsTheLine) {
  CapturedStream out;
  { ProgressBar(10.0, ProgressStyle::line, out.get()).update(1.0); }
  const std::string text = out.text();
  ASSERT_FALSE(text.empty());
  EXPECT_EQ(text.back(), '\r');
}

}  // namespace
