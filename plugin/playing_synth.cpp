// The swap (take the newest, fade the old one out, give it back), the controls applied to the
// synthesizer in use, and the gain, smoothed sample by sample.
#include "playing_synth.h"

namespace hamiltone::plugin {

void PlayingSynth::prepare(double sampleRate) {
  release();
  scratchLeft_.assign(kMaxBlock, 0.0f);
  scratchRight_.assign(kMaxBlock, 0.0f);
  // A rate no synthesizer builds at (a host's NaN) leaves nothing to play: the smoothing stays
  // finite, so the output is silence rather than NaN.
  const double rate = std::isfinite(sampleRate) && sampleRate > 0.0 ? sampleRate : 48000.0;
  gainSmoothing_ = std::exp(-1.0 / (kGainSmoothingS * rate));
  swapFade_ = std::max(1L, std::lround(kSwapFadeS * rate));
  gain_ = gainTarget_;
  controlsSet_ = false;
  std::fill(std::begin(held_), std::end(held_), MidiMessage{});
}

void PlayingSynth::release() {
  delete current_;
  delete outgoing_;
  current_ = outgoing_ = nullptr;
}

void PlayingSynth::setControls(const Controls& asked) noexcept {
  const Controls controls{.gainDb = kGainDbRange.held(asked.gainDb),
                          .velocityCurve = kVelocityCurveRange.held(asked.velocityCurve),
                          .damperScale = kDamperScaleRange.held(asked.damperScale),
                          .polyphony = static_cast<int>(kPolyphonyRange.held(asked.polyphony)),
                          .lightTails = asked.lightTails};
  const bool first = !controlsSet_;
  controlsSet_ = true;
  if (controls == controls_ && !first) return;
  controls_ = controls;
  gainTarget_ = std::pow(10.0, controls_.gainDb / 20.0);
  if (first) gain_ = gainTarget_;  // a restored session's gain, not a fade from the last one
  applyControls();
}

void PlayingSynth::applyControls() noexcept {
  if (!current_) return;
  current_->synth.setDamperScale(controls_.damperScale);
  current_->synth.setPolyphony(controls_.polyphony);
  current_->synth.setLiveTail(controls_.lightTails);
}

// One swap at a time: a newer synthesizer waits in the loader's slot while one fades.
void PlayingSynth::adopt() noexcept {
  if (outgoing_) return;
  BuiltSynth* fresh = loader_.take();
  if (!fresh) return;
  if (current_) {
    current_->synth.handle({0xB0, midi::allSoundOff, 0});
    outgoing_ = current_;
    outgoingLeft_ = swapFade_;
  }
  current_ = fresh;
  applyControls();
  // The pedal held down, the volume turned down and the wheel bent stay so across the swap.
  for (const MidiMessage& m : held_)
    if (m.status != 0) current_->synth.handle(m);
  current_->synth.settleVolume();
}

void PlayingSynth::remember(const MidiMessage& m) noexcept {
  if (m.kind() == midi::pitchBend) {
    held_[kBend] = m;
    return;
  }
  if (m.kind() != midi::controller) return;
  switch (m.data1) {
    case midi::volume:
      held_[kVolume] = m;
      break;
    case midi::sustainPedal:
      held_[kSustain] = m;
      break;
    case midi::sostenutoPedal:
      held_[kSostenuto] = m;
      break;
    case midi::softPedal:
      held_[kSoft] = m;
      break;
    case midi::resetControllers:  // bend centred, pedals up (Synth::handle); the volume stays
      held_[kSustain] = held_[kSostenuto] = held_[kSoft] = held_[kBend] = MidiMessage{};
      break;
    default:
      break;
  }
}

void PlayingSynth::render(std::span<float> left, std::span<float> right,
                          std::span<const SynthEvent> events) noexcept {
  if (current_) {
    current_->synth.process(left, right, events);
  } else {
    std::fill(left.begin(), left.end(), 0.0f);
    std::fill(right.begin(), right.end(), 0.0f);
  }
  if (!outgoing_) return;
  for (size_t done = 0; done < left.size() && outgoingLeft_ > 0;) {
    const size_t n =
        std::min({left.size() - done, scratchLeft_.size(), static_cast<size_t>(outgoingLeft_)});
    const std::span<float> l(scratchLeft_.data(), n), r(scratchRight_.data(), n);
    outgoing_->synth.process(l, r, {});
    for (size_t i = 0; i < n; ++i) {
      left[done + i] += l[i];
      right[done + i] += r[i];
    }
    done += n;
    outgoingLeft_ -= static_cast<long>(n);
  }
  if (outgoingLeft_ <= 0 && loader_.giveBack(outgoing_)) outgoing_ = nullptr;
}

void PlayingSynth::applyGain(std::span<float> left, std::span<float> right) noexcept {
  for (size_t i = 0; i < left.size(); ++i) {
    gain_ = gainTarget_ + (gain_ - gainTarget_) * gainSmoothing_;
    left[i] = static_cast<float>(left[i] * gain_);
    right[i] = static_cast<float>(right[i] * gain_);
  }
}

}  // namespace hamiltone::plugin
