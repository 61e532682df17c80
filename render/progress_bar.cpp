// The line is redrawn in place with '\r' and padded with spaces over a longer previous line, so
// it needs no terminal escape codes.
#include "progress_bar.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>

namespace hamiltone::cli {

namespace {

constexpr auto kRedrawInterval = std::chrono::milliseconds(100);

// "0:07", "12:34" or "1:02:03"; "--" beyond 100 h.
std::string formattedEta(double seconds) {
  if (!(seconds >= 0.0 && seconds < 100.0 * 3600.0)) return "--";
  const long s = std::lround(seconds);
  char text[48];
  if (s >= 3600)
    std::snprintf(text, sizeof text, "%ld:%02ld:%02ld", s / 3600, s / 60 % 60, s % 60);
  else
    std::snprintf(text, sizeof text, "%ld:%02ld", s / 60, s % 60);
  return text;
}

}  // namespace

ProgressStyle progressStyle(bool quiet) {
  if (quiet) return ProgressStyle::none;
  return ::isatty(STDERR_FILENO) == 1 ? ProgressStyle::line : ProgressStyle::log;
}

ProgressBar::ProgressBar(double totalSeconds, ProgressStyle style, std::FILE* out,
                         Clock::duration logInterval)
    : total_(totalSeconds),
      style_(style),
      out_(out),
      logInterval_(logInterval),
      start_(Clock::now()),
      lastDraw_(start_) {}

void ProgressBar::update(double doneSeconds) {
  if (style_ == ProgressStyle::none) return;
  const Clock::time_point now = Clock::now();
  if (style_ == ProgressStyle::log) {
    if (now - lastDraw_ < logInterval_) return;
    lastDraw_ = now;
    std::fprintf(out_, "hamiltone-render: %s\n", text(doneSeconds, now).c_str());
    std::fflush(out_);
    return;
  }
  if (drawnWidth_ > 0 && now - lastDraw_ < kRedrawInterval) return;
  lastDraw_ = now;
  const std::string line = text(doneSeconds, now);
  const int width = static_cast<int>(line.size());
  std::fprintf(out_, "\r%s%*s", line.c_str(), std::max(drawnWidth_ - width, 0), "");
  std::fflush(out_);
  drawnWidth_ = width;
}

std::string ProgressBar::text(double doneSeconds, Clock::time_point now) const {
  const double fraction = total_ > 0.0 ? std::clamp(doneSeconds / total_, 0.0, 1.0) : 1.0;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  // Nothing done yet: no estimate.
  const std::string eta =
      doneSeconds > 0.0
          ? formattedEta(std::max(elapsed * (total_ - doneSeconds) / doneSeconds, 0.0))
          : "--";
  char line[96];
  std::snprintf(line, sizeof line, "%4d%%  %.1f s of %.1f s  ETA %s",
                static_cast<int>(100.0 * fraction), doneSeconds, total_, eta.c_str());
  return line;
}

void ProgressBar::finish() {
  if (drawnWidth_ == 0) return;
  std::fprintf(out_, "\r%*s\r", drawnWidth_, "");
  std::fflush(out_);
  drawnWidth_ = 0;
}

std::string renderSummary(double renderedSeconds, double wallSeconds) {
  char text[160];
  const int n = std::snprintf(text, sizeof text, "rendered %.2f s of audio in %.2f s",
                              renderedSeconds, wallSeconds);
  if (renderedSeconds > 0.0 && wallSeconds > 0.0) {
    const double factor = wallSeconds / renderedSeconds;
    const bool faster = factor <= 1.0;
    std::snprintf(text + n, sizeof text - static_cast<std::size_t>(n),
                  " (real-time factor %.3f, %.1fx %s than real time)", factor,
                  faster ? 1.0 / factor : factor, faster ? "faster" : "slower");
  }
  return text;
}

std::string stealSummary(long steals, double loudestLevel, int limit) {
  char text[160];
  if (steals == 0) {
    std::snprintf(text, sizeof text, "no key stolen at the limit of %d voices", limit);
    return text;
  }
  const double db = loudestLevel > 0.0 ? 20.0 * std::log10(loudestLevel) : -INFINITY;
  std::snprintf(
      text, sizeof text,
      "%ld key%s stolen at the limit of %d voices, the loudest at %.1f dB of its own peak", steals,
      steals == 1 ? "" : "s", limit, db);
  return text;
}

std::string limiterSummary(long limitedFrames, long overFrames, double deepestReductionDb,
                           double peakIn, double ceiling, double sampleRate) {
  char text[200];
  const double peakDb = peakIn > 0.0 ? 20.0 * std::log10(peakIn) : -INFINITY;
  const double ceilingDb = 20.0 * std::log10(ceiling);
  if (outputSilent(limitedFrames, peakIn))
    return "the output is silent: every sample is 0 (the limiter did not act)";
  if (limitedFrames == 0) {
    std::snprintf(text, sizeof text,
                  "peak %.1f dBFS before the limiter, %.1f dB under its ceiling of %.2f dBFS: it "
                  "did not act",
                  peakDb, ceilingDb - peakDb, ceilingDb);
    return text;
  }
  std::snprintf(text, sizeof text,
                "the limiter reduced the gain by up to %.1f dB on %ld frames (%.3f s; %ld over its "
                "ceiling of %.2f dBFS); peak before it %+.1f dBFS",
                deepestReductionDb, limitedFrames, static_cast<double>(limitedFrames) / sampleRate,
                overFrames, ceilingDb, peakDb);
  return text;
}

}  // namespace hamiltone::cli
