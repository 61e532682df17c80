// The callback's work: drain the MIDI queue onto sample offsets, run the synthesizer, interleave,
// tee into the recording ring, measure the load and lower or restore the voice limit.
#include "player.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace hamiltone::app {

Player::Player(Synth& synth, SpscQueue<StampedMessage>& midi, SpscQueue<float>* record,
               double sampleRate, int maxFrames)
    : synth_(synth),
      midi_(midi),
      record_(record),
      sampleRate_(sampleRate),
      left_(maxFrames),
      right_(maxFrames),
      events_(kMaxEventsPerBlock),
      fullLimit_(synth.polyphony()),
      limit_(synth.polyphony()) {
  limitShown_ = limit_;
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
    events_[count++] = {static_cast<int>(std::clamp(offset, 0L, frames - 1L)), m->message};
    last_.store(std::uint32_t{m->message.status} << 16 | m->message.data1 << 8 | m->message.data2,
                std::memory_order_relaxed);
    midi_.drop();
  }
  // Arrivals come in order, so the offsets (clamped or not) never decrease: no sort is needed.
  std::span<float> left(left_.data(), frames), right(right_.data(), frames);
  synth_.process(left, right, std::span(events_.data(), count));
  for (int i = 0; i < frames; ++i) {
    interleaved[2 * i] = left[i];
    interleaved[2 * i + 1] = right[i];
  }
  if (record_) {
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
  voices_.store(synth_.activeVoices(), std::memory_order_relaxed);
  guard_.store(synth_.guardEvents(), std::memory_order_relaxed);
}

// Near the deadline the limit drops by one (the synth fades the keys furthest below their own
// peak first); after a second under kRelief it rises by one, back to the preset's polyphony.
void Player::protect(double load, double blockSeconds) noexcept {
  if (load > kOverload && limit_ > 1) {
    limit_ = std::max(1, std::min(limit_, synth_.activeVoices()) - 1);
    synth_.setPolyphony(limit_);
    reliefTime_ = 0.0;
  } else if (load < kRelief && limit_ < fullLimit_) {
    reliefTime_ += blockSeconds;
    if (reliefTime_ >= 1.0) {
      synth_.setPolyphony(++limit_);
      reliefTime_ = 0.0;
    }
  }
  limitShown_.store(limit_, std::memory_order_relaxed);
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
  s.load = load_.load();
  s.peakLoad = peak_.load();
  s.recordDropped = recordDropped_.load();
  s.late = late_.load();
  s.lastMessage = last_.load();
  return s;
}

}  // namespace hamiltone::app
