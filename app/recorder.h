// --record: the exact output, teed by the audio thread into a lock-free ring and written to a WAV
// file by a thread of its own. The file appears whole when the recorder finishes (on a normal
// stop or on Ctrl-C), never half-written.
#pragma once

#include <atomic>
#include <string>
#include <thread>

#include "synth/spsc_queue.h"
#include "wav_writer.h"

namespace hamiltone::app {

class Recorder {
 public:
  static constexpr double kRingSeconds = 10.0;  // of stereo audio the writer may fall behind
  static constexpr long kMaxFrames = (4294967295L - 1024L) / 6;  // 24-bit stereo in 4 GiB

  // Creates the temporary now (so a bad path fails before playing); throws cli::UsageError.
  Recorder(const std::string& path, int sampleRate);
  ~Recorder();  // finish() if not done
  SpscQueue<float>& ring() { return ring_; }
  void start();
  // Stops the writer once the ring is drained and renames the file into place. Returns the
  // seconds recorded.
  double finish();
  long truncatedFrames() const { return truncated_; }  // past kMaxFrames, not written

 private:
  void drain();

  cli::WavWriter wav_;
  SpscQueue<float> ring_;
  std::thread writer_;
  std::atomic<bool> stopping_{false};
  long frames_ = 0, truncated_ = 0;
  int sampleRate_;
  bool finished_ = false;
};

}  // namespace hamiltone::app
