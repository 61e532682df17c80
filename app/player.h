// The audio callback's work, apart from any audio API (so it can be tested and sanitised alone):
// MIDI from the queue placed on the block's samples, a score (a MIDI file or --notes, parsed
// beforehand) played from the stream's first sample, the synthesizer, the recording tee, the load
// measurement and the overload protection. Real-time safe: no allocation, lock, I/O or syscall
// beyond reading the steady clock and waking the synthesizer's sleeping workers (sem_post).
#pragma once

#include <pthread.h>

#include <atomic>
#include <cstdint>
#include <optional>
#include <span>

#include "midi_input.h"
#include "synth/nonblocking.h"
#include "synth/spsc_queue.h"
#include "synth/synth.h"

namespace hamiltone::app {

class Player {
 public:
  static constexpr int kMaxEventsPerBlock = 1024;  // of each source; more wait for the next block
  static constexpr double kOverload = 0.8;         // of the buffer period: drop a voice (default)
  static constexpr double kRelief = 0.5;           // below this for 1 s: allow one more
  // Overload protection (protect()): the limit drops only after kOverloadedBlocks blocks in a
  // row over the budget with keys sounding, by one key, then waits kHoldSeconds (the stolen key's
  // 5 ms fade and the blocks after it) before it may drop again, and never below kFloorVoices
  // (or the polyphony, if lower): a late block on a busy server, with or without keys sounding,
  // no longer takes it down to one key.
  static constexpr int kOverloadedBlocks = 2;
  static constexpr double kHoldSeconds = 0.05;
  static constexpr int kFloorVoices = 4;
  // Before a key is dropped, the tails (Synth::setLiveTail): kOverloadedBlocks blocks in a row
  // over kTailShare of the budget (0.6 of the period by default), with keys sounding, let the
  // decaying strings go linear sooner, at a tenth to a fifth of their cost, their pitch off by at
  // most 0.87 cents, and hold any drop for kHoldSeconds; kTailRelief seconds in a row under kRelief
  // give the strings not yet linear their preset's tail again. A new Player takes the synth's tail
  // as off: one synth reused by several players must be set off between them.
  static constexpr double kTailShare = 0.75;
  static constexpr double kTailRelief = 2.0;

  // `record` may be null. The synth must be prepared for blocks of at least `maxFrames`.
  // `overload`: the share of the buffer period above which the protection drops a key.
  Player(Synth& synth, SpscQueue<StampedMessage>& midi, SpscQueue<float>* record, double sampleRate,
         int maxFrames, double overload = kOverload);

  // A score to play from the first rendered sample on: messages in time order, at their time in
  // seconds rounded to the sample. Before the first render() (it allocates); replaces any other.
  // An empty score is played to its end at once (status().finished once no key sounds).
  // `endRecording`: the recording ends with the block in which the score finished (the player
  // then exits), so that it is the same in every run at the same block size, rather than going
  // on for however long the main thread takes to notice — as long as the load never called for
  // the overload protection (its live tail and voice limit change what plays).
  void setScore(std::span<const TimedMessage> score, bool endRecording = false);

  // Fills `frames` interleaved stereo frames. A message that arrived a time d before `nowNs`
  // lands d·rate samples before the end of this block: a constant latency of one buffer, and
  // the spacing of the messages kept to the sample. One stamped up to a period after `nowNs` is
  // left for the next block (once), where it lands in place; earlier or later ones are clamped to
  // this block.
  void render(float* interleaved, int frames, std::int64_t nowNs) noexcept HAMILTONE_NONBLOCKING;

  struct Status {
    int voices = 0, limit = 0, guardEvents = 0;
    // The callback's time from its start until the last key is rendered, on whichever thread
    // (Synth::process returns only then), over the buffer period: what the deadline sees.
    double load = 0.0, peakLoad = 0.0;
    long recordDropped = 0;                 // samples the recording ring had no room for
    long late = 0;                          // blocks whose compute time exceeded their period
    std::uint32_t lastMessage = 0;          // status << 16 | data1 << 8 | data2; 0 before any
    long limitDrops = 0;                    // times the protection lowered the limit
    bool liveTail = false;                  // the strings' live tail is on (kTailShare)
    long liveTails = 0;                     // times the protection turned it on
    double dropLoad = 0.0;                  // the highest load of the blocks that made it drop last
    std::uint64_t ignoredPrograms[2] = {};  // programs past the last preset asked for (Synth's)
    long limitedFrames = 0;         // frames the master's limiter reduced (0: it never acted)
    double limiterDeepestDb = 0.0;  // and by how much at most, in dB
    // The score has been played to its last message (at once for an empty one) and no key sounds
    // any more, nor fades out (false with no score).
    bool finished = false;
  };
  Status status() const;  // from any thread
  // The thread that ran the first render(), once there was one: the audio API's callback thread.
  std::optional<pthread_t> callbackThread() const;  // from any thread

 private:
  void protect(double load, double blockSeconds) noexcept;
  void protectTails(double load, double blockSeconds) noexcept;
  int scoreEvents(int frames) noexcept;  // the score's messages in this block, into scored_

  struct ScoreEvent {
    std::int64_t sample;
    MidiMessage message;
  };

  Synth& synth_;
  SpscQueue<StampedMessage>& midi_;
  SpscQueue<float>* record_;
  double sampleRate_;
  std::vector<float> left_, right_;
  std::vector<SynthEvent> events_, scored_, merged_;
  std::vector<ScoreEvent> score_;
  size_t nextScored_ = 0;
  std::int64_t heldNs_ = -1;  // the stamp of the message render() last left for the next block
  bool hasScore_ = false;     // setScore() was called, even with an empty score
  bool endRecording_ = false, recordingEnded_ = false;
  std::int64_t position_ = 0;  // samples rendered
  double overload_;
  int fullLimit_ = 0, limit_ = 0, overloadedRun_ = 0;
  double reliefTime_ = 0.0, holdTime_ = 0.0, runPeak_ = 0.0;
  int tailRun_ = 0;
  double tailReliefTime_ = 0.0;
  std::atomic<long> liveTails_{0};
  std::atomic<bool> liveTail_{false};
  std::atomic<int> voices_{0}, limitShown_{0}, guard_{0};
  std::atomic<std::uint64_t> ignoredPrograms_[2] = {};
  std::atomic<double> load_{0.0}, peak_{0.0}, dropLoad_{0.0};
  std::atomic<long> recordDropped_{0}, late_{0}, drops_{0}, limitedFrames_{0};
  std::atomic<double> limiterDeepestDb_{0.0};
  std::atomic<bool> finished_{false};
  std::atomic<std::uint32_t> last_{0};
  pthread_t callbackThread_{};  // written once, before callbackKnown_
  std::atomic<bool> callbackKnown_{false};
};

}  // namespace hamiltone::app
