// --record: the exact output, teed by the audio thread into a lock-free ring and written to a
// WAV, FLAC or Ogg Vorbis file by a thread of its own. The file appears whole when the recorder
// finishes (on a normal stop or on Ctrl-C), never half-written. A write error (a full disk) stops
// the recording, not the sound: the writer then discards what comes, and finish() keeps what was
// written before.
#pragma once

#include <atomic>
#include <mutex>
#include <string>
#include <thread>

#include "synth/spsc_queue.h"
#include "wav_writer.h"

namespace hamiltone::app {

class Recorder {
 public:
  static constexpr double kRingSeconds = 10.0;  // of stereo audio the writer may fall behind
  static constexpr long kMaxFrames = (4294967295L - 1024L) / 6;  // 24-bit stereo in a 4 GiB WAV

  // Creates the temporary now (so a bad path fails before playing); throws cli::UsageError, and
  // std::invalid_argument for a rate the type cannot hold (Ogg Vorbis above kOggMaxRate). WAV and
  // FLAC hold 24-bit samples.
  Recorder(const std::string& path, int sampleRate, cli::FileType type = cli::FileType::wav);
  ~Recorder();  // stops the writer; the temporary goes unless finish() put it in place
  SpscQueue<float>& ring() { return ring_; }
  void start();
  // Stops the writer once the ring is drained and renames the file into place: after a write
  // error, the frames written before it (a valid WAV), or no file if even that fails (then the
  // temporary is removed). A recording of no frame at all (the stream never ran) is not put in
  // place either: a file already at the path stays as it was. From any thread, one at a time
  // (the stop signals' thread completes the recording when the audio server hangs); a second
  // call returns what the first did. Never throws. Returns the seconds in the file (0 when there
  // is none).
  double finish() noexcept;
  // After finish(), what became of the recording, for the player's last line: "recorded 2.50 s
  // to take.wav", "the recording failed (…); no file written", …; `gaps`: the ring overflowed.
  std::string outcome(double seconds, bool gaps) const;
  long truncatedFrames() const { return truncated_; }  // past kMaxFrames, not written

  // Whether a write failed; from any thread. The recording stopped there.
  bool failed() const { return failed_.load(std::memory_order_acquire); }
  // Once failed(): where (seconds into the recording) and why, naming the file.
  double failedAtSeconds() const { return failedAt_; }
  const std::string& error() const { return error_; }
  // After finish(): whether the file is in place, and whether there was nothing to put there.
  bool kept() const { return kept_; }
  bool empty() const { return finished_ && frames_ == 0 && !failed(); }
  const std::string& path() const { return wav_.path(); }
  // After finish(): where the file is. A file another program wrote at the path meanwhile (a
  // second player recording there) is kept, and this take goes beside it: take-2.wav.
  const std::string& publishedPath() const { return wav_.publishedPath(); }
  bool movedAside() const { return wav_.movedAside(); }

 private:
  void drain();

  cli::WavWriter wav_;
  SpscQueue<float> ring_;
  std::thread writer_;
  std::atomic<bool> stopping_{false}, failed_{false};
  std::string error_;      // written before failed_ is set (release), read after (acquire)
  double failedAt_ = 0.0;  // likewise
  long frames_ = 0, truncated_ = 0;
  long maxFrames_;  // kMaxFrames for a WAV file; FLAC and Ogg have no such limit
  int sampleRate_;
  std::mutex finishing_;
  bool finished_ = false, kept_ = false;
};

}  // namespace hamiltone::app
