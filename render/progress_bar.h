// The render's progress line on stderr, and the one-line summary printed when it is done.
#pragma once

#include <chrono>
#include <cstdio>
#include <string>

namespace hamiltone::cli {

// How the progress is shown: not at all, as a line redrawn in place (a terminal), or as a whole
// line now and then (a log file or a pipe, where '\r' would pile up).
enum class ProgressStyle { none, line, log };
// none under --quiet; else line when stderr is a terminal, log when it is not.
ProgressStyle progressStyle(bool quiet);

class ProgressBar {
 public:
  static constexpr std::chrono::seconds kLogInterval{10};
  // Draws nothing with ProgressStyle::none; `out` is stderr and `logInterval` kLogInterval but for
  // tests.
  ProgressBar(double totalSeconds, ProgressStyle style, std::FILE* out = stderr,
              std::chrono::steady_clock::duration logInterval = kLogInterval);
  ~ProgressBar() { finish(); }  // an exception that ends the render leaves no half line
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  // Redraws the line — "  42%  5.3 s of 12.5 s  ETA 0:07" — at most ten times a second, the
  // first call at once; or, as a log, writes "hamiltone-render:  42%  5.3 s of 12.5 s  ETA 0:07"
  // and a new line once each logInterval, the first after one (a short render writes none). The
  // ETA assumes the rest renders as fast as what is done so far.
  void update(double doneSeconds);
  // Clears the line, so what is printed next starts at the left edge; idempotent.
  void finish();

 private:
  using Clock = std::chrono::steady_clock;
  std::string text(double doneSeconds, Clock::time_point now) const;
  double total_;
  ProgressStyle style_;
  std::FILE* out_;
  Clock::duration logInterval_;
  Clock::time_point start_, lastDraw_;
  int drawnWidth_ = 0;  // characters on the line now, 0 if nothing is drawn
};

// "rendered 12.50 s of audio in 3.10 s (real-time factor 0.248, 4.0x faster than real time)".
// The real-time factor is wall time / audio time: below 1 renders faster than it plays.
// A wall time of 0 (below the clock's resolution) or no audio leaves the factor out.
std::string renderSummary(double renderedSeconds, double wallSeconds);

// "3 keys stolen at the limit of 64 voices, the loudest at -63.2 dB of its own peak", or "no key
// stolen at the limit of 64 voices". `loudestLevel` is Synth::loudestSteal() (1 is the peak).
std::string stealSummary(long steals, double loudestLevel, int limit);

// Whether a render's output is all zeros: the limiter never acted and nothing before it was above
// 0.
inline bool outputSilent(long limitedFrames, double peakIn) {
  return limitedFrames == 0 && !(peakIn > 0.0);
}

// What the master's limiter (PeakLimiter) did to a render: "peak -2.4 dBFS before the limiter,
// 2.2 dB under its ceiling of -0.18 dBFS: it did not act", or "the limiter reduced the gain by
// up to 3.1 dB on 5120 frames (0.107 s; 12 over its ceiling of -0.18 dBFS); peak before it
// +2.9 dBFS". `peakIn` is linear (1 is 0 dBFS).
std::string limiterSummary(long limitedFrames, long overFrames, double deepestReductionDb,
                           double peakIn, double ceiling, double sampleRate);

}  // namespace hamiltone::cli
