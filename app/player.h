// The audio callback's work, apart from any audio API (so it can be tested and sanitised alone):
// MIDI from the queue placed on the block's samples, the synthesizer, the recording tee, the load
// measurement and the overload protection. Real-time safe: no allocation, lock, I/O or syscall
// beyond reading the steady clock and waking the synthesizer's sleeping workers (sem_post).
#pragma once

#include <pthread.h>

#include <atomic>
#include <cstdint>
#include <optional>

#include "midi_input.h"
#include "synth/nonblocking.h"
#include "synth/spsc_queue.h"
#include "synth/synth.h"

namespace hamiltone::app {

class Player {
 public:
  static constexpr int kMaxEventsPerBlock = 1024;  // more wait for the next block
  static constexpr double kOverload = 0.8;         // of the buffer period: drop a voice
  static constexpr double kRelief = 0.5;           // below this for 1 s: allow one more

  // `record` may be null. The synth must be prepared for blocks of at least `maxFrames`.
  Player(Synth& synth, SpscQueue<StampedMessage>& midi, SpscQueue<float>* record, double sampleRate,
         int maxFrames);

  // Fills `frames` interleaved stereo frames. A message that arrived a time d before `nowNs`
  // lands d·rate samples before the end of this block: a constant latency of one buffer, and
  // the spacing of the messages kept to the sample.
  void render(float* interleaved, int frames, std::int64_t nowNs) noexcept HAMILTONE_NONBLOCKING;

  struct Status {
    int voices = 0, limit = 0, guardEvents = 0;
    // The callback's time from its start until the last key is rendered, on whichever thread
    // (Synth::process returns only then), over the buffer period: what the deadline sees.
    double load = 0.0, peakLoad = 0.0;
    long recordDropped = 0;         // samples the recording ring had no room for
    long late = 0;                  // blocks whose compute time exceeded their period
    std::uint32_t lastMessage = 0;  // status << 16 | data1 << 8 | data2; 0 before any
  };
  Status status() const;  // from any thread
  // The thread that ran the first render(), once there was one: the audio API's callback thread.
  std::optional<pthread_t> callbackThread() const;  // from any thread

 private:
  void protect(double load, double blockSeconds) noexcept;

  Synth& synth_;
  SpscQueue<StampedMessage>& midi_;
  SpscQueue<float>* record_;
  double sampleRate_;
  std::vector<float> left_, right_;
  std::vector<SynthEvent> events_;
  int fullLimit_ = 0, limit_ = 0;
  double reliefTime_ = 0.0;
  std::atomic<int> voices_{0}, limitShown_{0}, guard_{0};
  std::atomic<double> load_{0.0}, peak_{0.0};
  std::atomic<long> recordDropped_{0}, late_{0};
  std::atomic<std::uint32_t> last_{0};
  pthread_t callbackThread_{};  // written once, before callbackKnown_
  std::atomic<bool> callbackKnown_{false};
};

}  // namespace hamiltone::app
