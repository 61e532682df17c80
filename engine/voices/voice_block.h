// What every voice does around a block: silence a span pair, damp a released note, and tell when
// it has gone quiet — shared by the string and the plate voices.
#pragma once

#include <algorithm>
#include <cmath>
#include <span>

namespace hamiltone {

// Zeroes left and the first rightCount samples of right.
inline void silence(std::span<float> left, std::span<float> right, size_t rightCount) noexcept {
  std::fill(left.begin(), left.end(), 0.0f);
  std::fill(right.begin(), right.begin() + rightCount, 0.0f);
}

// A released voice is free once its output has stayed 80 dB under its loudest since the note
// began for 50 ms, longer than the lowest string's half period; over those 50 ms the output fades
// to zero, so freeing it never clicks. All of it sample by sample — a peak follower with a 20 ms
// release bridges the zero crossings — so it does not depend on the block size. It listens to the
// output, not the energy: near rest the SAV can keep energy where no pickup hears it — a static
// longitudinal stretch held by ψ, or a period-2 longitudinal oscillation (q^{n+1} = q^{n−1},
// which the centred σ0 of the damper cannot touch), measured at C3 at −58 dB of the strike's
// energy with a 0.3 s damper.
// The loss σ0 of a released voice: its own σ0 plus ln(1000) / T60 of its damper, the damper's
// T60 times `scale` (Synth::setDamperScale). The scheme needs σ0 k < 1; prepare() checked the
// preset's damper against it, so a shorter scaled one is held at the larger of that and 0.9 / k.
inline double releasedSigma0(double sigma0, double damperT60, double scale, double k) noexcept {
  constexpr double kLn1000 = 6.907755278982137;  // T60 = ln(1000) / σ
  const double preset = sigma0 + kLn1000 / damperT60;
  return std::min(sigma0 + kLn1000 / (damperT60 * scale), std::max(preset, 0.9 / k));
}

class QuietDetector {
 public:
  static constexpr double kLevel = 1e-4;    // of the loudest: −80 dB
  static constexpr double kHoldS = 0.05;    // s
  static constexpr double kFollowS = 0.02;  // s, the follower's release time constant

  void prepare(double sampleRate) {
    holdSamples_ = std::lround(kHoldS * sampleRate);
    decay_ = std::exp(-1.0 / (kFollowS * sampleRate));
    reset();
  }
  void reset() noexcept { quietSamples_ = 0, envelope_ = loudest_ = 0.0; }
  // Call after each block with its samples: fades them if the voice is going quiet. Returns true
  // when the voice is now free.
  bool update(bool released, std::span<float> left, std::span<float> right,
              size_t rightCount) noexcept {
    for (size_t i = 0; i < left.size(); ++i) {
      const double peak = std::max(std::abs(left[i]), i < rightCount ? std::abs(right[i]) : 0.0f);
      envelope_ = std::max(peak, envelope_ * decay_);
      loudest_ = std::max(loudest_, envelope_);
      quietSamples_ = released && envelope_ <= kLevel * loudest_ ? quietSamples_ + 1 : 0;
      if (quietSamples_ == 0) continue;
      const float gain = static_cast<float>(
          std::max(0.0, 1.0 - static_cast<double>(quietSamples_) / holdSamples_));
      left[i] *= gain;
      if (i < rightCount) right[i] *= gain;
    }
    return quietSamples_ >= holdSamples_;
  }

 private:
  long quietSamples_ = 0, holdSamples_ = 1;
  double envelope_ = 0.0, loudest_ = 0.0, decay_ = 0.0;
};

}  // namespace hamiltone
