// What every voice does around a block: silence a span pair, and tell when a released note has
// gone quiet — shared by the string and the plate voices.
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

// A released voice is free once its output has stayed 80 dB under the loudest block since the
// note began for 50 ms, longer than the lowest string's half period; over those 50 ms the output
// fades to zero, so freeing it never clicks. It listens to the output, not the energy: near rest
// the SAV can keep energy where no pickup hears it — a static longitudinal stretch held by ψ, or
// a period-2 longitudinal oscillation (q^{n+1} = q^{n−1}, which the centred σ0 of the damper cannot
// touch), measured at C3 at −58 dB of the strike's energy with a 0.3 s damper.
class QuietDetector {
 public:
  static constexpr double kLevel = 1e-4;  // of the loudest block's peak: −80 dB
  static constexpr double kHold = 0.05;   // s

  void reset() noexcept { quietTime_ = loudest_ = 0.0; }
  // Call after each block with its samples and their peak |x|: fades them if the voice is going
  // quiet. Returns true when the voice is now free.
  bool update(bool released, double peak, double blockSeconds, std::span<float> left,
              std::span<float> right, size_t rightCount) noexcept {
    loudest_ = std::max(loudest_, peak);
    const double before = gain();
    quietTime_ = released && peak <= kLevel * loudest_ ? quietTime_ + blockSeconds : 0.0;
    const double after = gain();
    if (before < 1.0 || after < 1.0) {
      const double n = static_cast<double>(left.size());
      for (size_t i = 0; i < left.size(); ++i) {
        const float g = static_cast<float>(before + (after - before) * (i + 1) / n);
        left[i] *= g;
        if (i < rightCount) right[i] *= g;
      }
    }
    return quietTime_ >= kHold;
  }

 private:
  double gain() const { return std::max(0.0, 1.0 - quietTime_ / kHold); }
  double quietTime_ = 0.0, loudest_ = 0.0;
};

// The largest |x| of left and the first rightCount samples of right.
inline double blockPeak(std::span<const float> left, std::span<const float> right,
                        size_t rightCount) noexcept {
  float peak = 0.0f;
  for (float x : left) peak = std::max(peak, std::abs(x));
  for (size_t i = 0; i < rightCount; ++i) peak = std::max(peak, std::abs(right[i]));
  return peak;
}

}  // namespace hamiltone
