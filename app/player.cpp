// The callback's work: drain the MIDI queue onto sample offsets, merge in the score's messages
// due in the block, run the synthesizer, interleave, tee into the recording ring, measure the load
// and lower or restore the voice limit.
#include "player.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace hamiltone::app {

Player::Player(Synth& synth, SpscQueue<StampedMessage>& midi, SpscQueue<float>* record,
               double sampleRate, int maxFrames, double overload)
    : synth_(synth),
      midi_(midi),
      record_(record),
      sampleRate_(sampleRate),
      left_(maxFrames),
      right_(maxFrames),
      events_(kMaxEventsPerBlock),
      scored_(kMaxEventsPerBlock),
      merged_(2 * kMaxEventsPerBlock),
      overload_(overload),
      fullLimit_(synth.polyphony()),
      limit_(synth.polyphony()) {
  limitShown_ = limit_;
}

void Player::setScore(std::span<const TimedMessage> score, bool endRecording) {
  score_.clear();
  score_.reserve(score.size());
  for (const TimedMessage& m : score)
    score_.push_back({std::llround(m.seconds * sampleRate_), m.message});
  nextScored_ = 0;
  hasScore_ = true;
  endRecording_ = endRecording;
}

// The score's messages due before the block's end, at their offsets (one due before the block —
// left over from a full block — at its first sample).
int Player::scoreEvents(int frames) noexcept {
  int count = 0;
  const std::int64_t end = position_ + frames;
  while (count < kMaxEventsPerBlock && nextScored_ < score_.size() &&
         score_[nextScored_].sample < end) {
    const ScoreEvent& e = score_[nextScored_++];
    scored_[count++] = {static_cast<int>(std::max<std::int64_t>(0, e.sample - position_)),
                        e.message};
  }
  return count;
}

void Player::render(float* interleaved, int frames, std::int64_t nowNs) noexcept {
  const auto start = std::chrono::steady_clock::now();
  if (!callbackKnown_.load(std::memory_order_relaxed)) {
    callbackThread_ = pthread_self();
    callbackKnown_.store(true, std::memory_order_release);
  }
  frames = std::min(frames, static_cast<int>(left_.size()));
  if (frames <= 0) return;
  // The block stands for the buffer period that ended now: [now − P, now).
  const double period = frames / sampleRate_;
  int count = 0;
  while (count < kMaxEventsPerBlock) {
    const StampedMessage* m = midi_.peek();
    if (!m) break;
    const double age = static_cast<double>(nowNs - m->arrivalNs) * 1e-9;
    const long offset = std::lround((period - age) * sampleRate_);
    // Stamped within the next period (the JACK input stamps a period's events from the cycle's
    // start, and its callback may run before ours): left for the next block, where it lands in
    // place — each message once, so that a clock that does not move cannot hold one for good.
    if (offset >= frames && offset < 2L * frames && m->arrivalNs != heldNs_) {
      heldNs_ = m->arrivalNs;
      break;
    }
    events_[count++] = {static_cast<int>(std::clamp(offset, 0L, frames - 1L)), m->message};
    last_.store(std::uint32_t{m->message.status} << 16 | m->message.data1 << 8 | m->message.data2,
                std::memory_order_relaxed);
    midi_.drop();
  }
  // Arrivals come in order, so the offsets (clamped or not) never decrease: no sort is needed.
  // The score's are in order too: the two lists merge (live first at equal offsets).
  std::span<const SynthEvent> events(events_.data(), count);
  if (nextScored_ < score_.size()) {
    const int scored = scoreEvents(frames);
    const auto byOffset = [](const SynthEvent& a, const SynthEvent& b) {
      return a.offset < b.offset;
    };
    const auto end = std::merge(events_.begin(), events_.begin() + count, scored_.begin(),
                                scored_.begin() + scored, merged_.begin(), byOffset);
    events = std::span<const SynthEvent>(merged_.data(), end - merged_.begin());
  }
  std::span<float> left(left_.data(), frames), right(right_.data(), frames);
  synth_.process(left, right, events);
  position_ += frames;
  for (int i = 0; i < frames; ++i) {
    interleaved[2 * i] = left[i];
    interleaved[2 * i + 1] = right[i];
  }
  if (record_ && !recordingEnded_) {
    const size_t samples = 2 * static_cast<size_t>(frames);
    if (!record_->pushAll(interleaved, samples))  // whole frames, or the block is lost
      recordDropped_.fetch_add(static_cast<long>(samples));
  }
  const double busy =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double load = busy / period;
  if (load > 1.0) late_.fetch_add(1, std::memory_order_relaxed);
  protect(load, period);
  load_.store(load, std::memory_order_relaxed);
  if (load > peak_.load(std::memory_order_relaxed)) peak_.store(load, std::memory_order_relaxed);
  const int voices = synth_.activeVoices();
  voices_.store(voices, std::memory_order_relaxed);
  guard_.store(synth_.guardEvents(), std::memory_order_relaxed);
  for (int w = 0; w < 2; ++w)
    ignoredPrograms_[w].store(synth_.ignoredPrograms(w), std::memory_order_relaxed);
  limitedFrames_.store(synth_.limiter().limitedFrames(), std::memory_order_relaxed);
  limiterDeepestDb_.store(synth_.limiter().deepestReductionDb(), std::memory_order_relaxed);
  if (hasScore_ && nextScored_ == score_.size() && voices == 0 && synth_.silent()) {
    finished_.store(true, std::memory_order_relaxed);
    recordingEnded_ = endRecording_;  // this block was the last one recorded
  }
}

// Near the deadline — kOverloadedBlocks blocks in a row over the budget, with keys sounding — the
// limit drops by one below the keys sounding (the synth fades the key furthest below its own peak
// first), then holds for kHoldSeconds, so that the fade is over and its effect measured before it
// may drop again; never below the floor. After a second under kRelief it rises by one, back to the
// preset's polyphony.
//
// It once dropped on any single late block, to one below the keys sounding and at least 1: a
// block made late by the host (a busy JACK server's other clients, a page fault) with no key
// sounding set the limit to 1 at once, and a real overload took it a key per block down to 1,
// since a key fading out (5 ms) is no longer counted but still costs its time — and then it came
// back a key per second at best.
void Player::protect(double load, double blockSeconds) noexcept {
  const int floor = std::min(fullLimit_, kFloorVoices);
  holdTime_ = std::max(0.0, holdTime_ - blockSeconds);
  protectTails(load, blockSeconds);
  if (load > overload_) {
    reliefTime_ = 0.0;
    runPeak_ = overloadedRun_ == 0 ? load : std::max(runPeak_, load);
    ++overloadedRun_;
    const int active = synth_.activeVoices();
    const int lowered = std::max(floor, std::min(limit_, active) - 1);
    if (overloadedRun_ >= kOverloadedBlocks && holdTime_ <= 0.0 &&
        lowered < std::min(limit_, active)) {  // a key goes {
      limit_ = lowered;
      synth_.setPolyphony(limit_);
      holdTime_ = kHoldSeconds;
      overloadedRun_ = 0;
      dropLoad_.store(runPeak_, std::memory_order_relaxed);
      drops_.fetch_add(1, std::memory_order_relaxed);
    }
  } else {
    overloadedRun_ = 0;
    if (load < kRelief && limit_ < fullLimit_) {
      reliefTime_ += blockSeconds;
      if (reliefTime_ >= 1.0) {
        synth_.setPolyphony(++limit_);
        reliefTime_ = 0.0;
      }
    }
  }
  limitShown_.store(limit_, std::memory_order_relaxed);
}

// The first step, at kTailShare of the budget: the strings' live tail, which costs no key and
// moves a decaying string's pitch by under a cent; a key may go only kHoldSeconds after it, once
// its effect is measured (strings under the new threshold go linear within 256 steps). Only with
// keys sounding and an instrument whose strings take it (Synth::takesLiveTail). Off again only
// after kTailRelief seconds of light load, since turning it off raises the load it lowered.
void Player::protectTails(double load, double blockSeconds) noexcept {
  const bool on = liveTail_.load(std::memory_order_relaxed);
  if (load > kTailShare * overload_) {
    tailReliefTime_ = 0.0;
    tailRun_ = std::min(tailRun_ + 1, kOverloadedBlocks);
    if (tailRun_ >= kOverloadedBlocks && !on && synth_.takesLiveTail() &&
        synth_.activeVoices() > 0) {
      synth_.setLiveTail(true);
      liveTail_.store(true, std::memory_order_relaxed);
      liveTails_.fetch_add(1, std::memory_order_relaxed);
      holdTime_ = kHoldSeconds;  // its effect measured before a key may go
    }
    return;
  }
  tailRun_ = 0;
  tailReliefTime_ = on && load < kRelief ? tailReliefTime_ + blockSeconds : 0.0;
  if (tailReliefTime_ >= kTailRelief) {
    synth_.setLiveTail(false);
    liveTail_.store(false, std::memory_order_relaxed);
    tailReliefTime_ = 0.0;
  }
}

std::optional<pthread_t> Player::callbackThread() const {
  if (!callbackKnown_.load(std::memory_order_acquire)) return std::nullopt;
  return callbackThread_;
}

Player::Status Player::status() const {
  Status s;
  s.voices = voices_.load();
  s.limit = limitShown_.load();
  s.guardEvents = guard_.load();
  for (int w = 0; w < 2; ++w) s.ignoredPrograms[w] = ignoredPrograms_[w].load();
  s.limitedFrames = limitedFrames_.load();
  s.limiterDeepestDb = limiterDeepestDb_.load();
  s.load = load_.load();
  s.peakLoad = peak_.load();
  s.recordDropped = recordDropped_.load();
  s.late = late_.load();
  s.lastMessage = last_.load();
  s.limitDrops = drops_.load();
  s.liveTail = liveTail_.load();
  s.liveTails = liveTails_.load();
  s.dropLoad = dropLoad_.load();
  s.finished = finished_.load();
  return s;
}

}  // namespace hamiltone::app
