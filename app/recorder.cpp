// The recorder's writer thread: it empties the ring every 10 ms into the WAV writer, and after a
// write error into nothing.
#include "recorder.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <limits>
#include <vector>

namespace hamiltone::app {

Recorder::Recorder(const std::string& path, int sampleRate, cli::FileType type)
    : wav_(path, "--record", sampleRate, 2, cli::SampleFormat::pcm24, type, true),
      ring_(static_cast<size_t>(kRingSeconds * sampleRate * 2)),
      maxFrames_(type == cli::FileType::wav ? kMaxFrames : std::numeric_limits<long>::max()),
      sampleRate_(sampleRate) {}

Recorder::~Recorder() {
  if (!finished_ && writer_.joinable()) {
    stopping_ = true;
    writer_.join();
  }
}

void Recorder::start() {
  writer_ = std::thread([this] {
    while (!stopping_.load()) {
      drain();
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    drain();
  });
}

void Recorder::drain() {
  std::vector<float> chunk(8192);
  size_t n;
  while ((n = ring_.pop(chunk.data(), chunk.size())) > 0) {
    if (failed_.load(std::memory_order_relaxed)) continue;  // emptied, so the audio goes on
    // Frames (the audio thread pushes whole ones), up to what a WAV file can hold: 4 GiB of
    // 24-bit stereo, 4.1 h at 48 kHz; the rest is dropped and counted.
    const long frames = std::min(static_cast<long>(n / 2), maxFrames_ - frames_);
    try {
      if (frames > 0) wav_.write(chunk.data(), static_cast<size_t>(frames));
    } catch (const std::exception& e) {
      frames_ = static_cast<long>(wav_.framesWritten());
      failedAt_ = static_cast<double>(frames_) / sampleRate_;
      error_ = e.what();
      failed_.store(true, std::memory_order_release);
      continue;
    }
    frames_ += std::max(frames, 0L);
    truncated_ += static_cast<long>(n / 2) - std::max(frames, 0L);
  }
}

double Recorder::finish() noexcept {
  const std::lock_guard<std::mutex> lock(finishing_);
  if (!finished_) {
    stopping_ = true;
    if (writer_.joinable()) writer_.join();
    finished_ = true;
    // No temporary outlives finish(): the stop signals' thread may end the program by _exit.
    if (frames_ == 0 && !failed()) {
      wav_.discard();
      return 0.0;
    }
    try {
      wav_.commit();
      kept_ = true;
    } catch (const std::exception& e) {
      wav_.discard();
      // Say why, after the first error if there was one.
      error_ = failed() ? error_ + "; then " + e.what() : std::string(e.what());
      failed_.store(true, std::memory_order_release);
    }
  }
  return kept_ ? static_cast<double>(frames_) / sampleRate_ : 0.0;
}

std::string Recorder::outcome(double seconds, bool gaps) const {
  char line[256];
  if (empty()) {
    return "nothing was recorded (no audio was played); " + path() +
           (std::filesystem::exists(path()) ? " is as it was" : " was not written");
  }
  if (!failed()) {
    std::snprintf(line, sizeof line, "recorded %.2f s to ", seconds);
    return line + publishedPath() +
           (movedAside() ? " (beside " + path() + ", which another program wrote meanwhile: kept)"
                         : "") +
           (gaps ? " (with gaps: the disk fell behind)" : "") +
           (truncatedFrames() ? " (cut at the 4 GiB a WAV file holds)" : "");
  }
  if (kept()) {
    std::snprintf(line, sizeof line, "the recording stopped at %.2f s (", failedAtSeconds());
    std::string text = line + error() + "); " + publishedPath();
    std::snprintf(line, sizeof line, " holds the %.2f s written before", seconds);
    return text + line;
  }
  return "the recording failed (" + error() + "); no file written";
}

}  // namespace hamiltone::app
