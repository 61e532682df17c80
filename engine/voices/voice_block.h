// What every voice does around a block: silence a span pair, and tell when a released note has
// gone quiet — shared by the string and the plate voices.
#pragma once

#include <algorithm>
#include <span>

namespace hamiltone {

// Zeroes left and the first rightCount samples of right.
inline void silence(std::span<float> left, std::span<float> right, size_t rightCount) noexcept {
  std::fill(left.begin(), left.end(), 0.0f);
  std::fill(right.begin(), right.begin() + rightCount, 0.0f);
}

// A released voice is free once its kinetic energy — the sound, not what a scheme may hold as
// static potential — has stayed 120 dB under the energy put in for 50 ms, longer than the
// lowest string's half period.
class QuietDetector {
 public:
  void reset() noexcept { quietTime_ = 0.0; }
  // Returns true when the voice is now free.
  bool update(bool released, double kinetic, double injected, double blockSeconds) noexcept {
    quietTime_ = released && kinetic < 1e-12 * injected ? quietTime_ + blockSeconds : 0.0;
    return quietTime_ > 0.05;
  }

 private:
  double quietTime_ = 0.0;
};

}  // namespace hamiltone
