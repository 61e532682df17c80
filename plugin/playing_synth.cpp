// The swap (take the newest, fade the old one out, give it back), the controls applied to the
// synthesizer in use, and the gain, smoothed sample by sample.
#include "playing_synth.h"

namespace hamiltone::plugin {

void PlayingSynth::prepare(double sampleRate) {
  release();
  scratchLeft_.assign(kMaxBlock, 0.0f);
  scratchRight_.assign(kMaxBlock, 0.0f);
  gainSmoothing_ = std::exp(-1.0 / (kGainSmoothingS * sampleRate));
  swapFade_ = std::max(1L, std::lround(kSwapFadeS * sampleRate));
  gain_ = gainTarget_;
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
                          .polyphony = static_cast<int>(kPolyphonyRange.held(asked.polyphony))};
  if (controls == controls_) return;
  controls_ = controls;
  gainTarget_ = std::pow(10.0, controls_.gainDb / 20.0);
  applyControls();
}

void PlayingSynth::applyControls() noexcept {
  if (!current_) return;
  current_->synth.setDamperScale(controls_.damperScale);
  current_->synth.setPolyphony(controls_.polyphony);
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
