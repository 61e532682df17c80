// What every voice does around a block: silence a span pair, damp a released note, and tell when a
// note has gone quiet — shared by the string and the plate voices.
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

// The loss σ0 of a released voice: its own σ0 plus ln(1000) / T60 of its damper, the damper's
// T60 times `scale` (Synth::setDamperScale). The scheme needs σ0 k < 1; prepare() checked the
// preset's damper against it, so a shorter scaled one is held at the larger of that and 0.9 / k.
// A damper touching the string partly (the half-pedal, Synth::damperContact) adds `contact`
// (0 … 1) of its loss rate: the decay rate, 1/T60, moves linearly from the voice's own (0) to the
// fully damped one (1), which is the value above to the bit. The loss stays ≥ σ0 ≥ 0 and under the
// full damper's, so the scheme stays stable and only removes energy whatever the contact.
inline double releasedSigma0(double sigma0, double damperT60, double scale, double k,
                             double contact = 1.0) noexcept {
  constexpr double kLn1000 = 6.907755278982137;  // T60 = ln(1000) / σ
  const double preset = sigma0 + kLn1000 / damperT60;
  const double full = std::min(sigma0 + kLn1000 / (damperT60 * scale), std::max(preset, 0.9 / k));
  if (!(contact < 1.0)) return full;  // NaN too
  return contact > 0.0 ? sigma0 + contact * (full - sigma0) : sigma0;
}

// A voice is free once its output has stayed 80 dB under its loudest since its last strike, and
// under an absolute floor, for 50 ms — held, sustained by the pedal or released alike: what is
// not heard is not computed. The floor is −100 dBFS at the instrument's output (KeyVoice scales
// it by the instrument's gain, the key's pan and its unison strings, so a key's freed strings
// together stay under it); the relative bound keeps a soft note to its own decay. Over those 50
// ms, longer than the lowest string's half period, the output fades to zero, so freeing it
// never clicks, and what is cut is under both bounds. The follower cannot fall 80 dB in less
// than 184 ms (20 ms · ln 10⁴), so no voice goes within 0.23 s of its loudest. All of
// it sample by sample — a peak follower with a 20 ms release bridges the zero crossings — so it
// does not depend on the block size. It listens to the output, not the energy: near rest the
// SAV can keep energy where no pickup hears it — a static longitudinal stretch held by ψ, or a
// period-2 longitudinal oscillation (q^{n+1} = q^{n−1}, which the centred σ0 of the damper cannot
// touch), measured at C3 at −58 dB of the strike's energy with a 0.3 s damper.
class QuietDetector {
 public:
  static constexpr double kLevel = 1e-4;    // of the loudest since the strike: −80 dB
  static constexpr double kFloor = 1e-5;    // of full scale at the instrument's output: −100 dB
  static constexpr double kHoldS = 0.05;    // s
  static constexpr double kFollowS = 0.02;  // s, the follower's release time constant

  void prepare(double sampleRate) {
    holdSamples_ = std::lround(kHoldS * sampleRate);
    decay_ = std::exp(-1.0 / (kFollowS * sampleRate));
    reset();
  }
  void reset() noexcept { quietSamples_ = 0, envelope_ = loudest_ = 0.0; }
  // The absolute floor in the voice's own output units (kFloor for a voice heard at unit gain);
  // negative: never free the voice (tests compare against such a run). Kept by reset().
  void setFloor(double floor) noexcept { floor_ = floor; }
  // A strike starts a new note: its loudest is measured from here.
  void strike() noexcept { quietSamples_ = 0, loudest_ = envelope_; }
  // Call after each block with its samples: fades them (and `alongside`, when given: a signal that
  // must fall silent with them, sample for sample) if the voice is going quiet. Returns true when
  // the voice is now free; freedAt() then says from which of these samples it is silent.
  bool update(std::span<float> left, std::span<float> right, size_t rightCount,
              std::span<float> alongside = {}) noexcept {
    freedAt_ = -1;
    for (size_t i = 0; i < left.size(); ++i) {
      // Free from the sample the hold ends, for good: what the voice would do after it in this
      // block must not matter, or the moment it is freed would depend on where blocks end.
      if (freedAt_ < 0) {
        const double peak = std::max(std::abs(left[i]), i < rightCount ? std::abs(right[i]) : 0.0f);
        envelope_ = std::max(peak, envelope_ * decay_);
        loudest_ = std::max(loudest_, envelope_);
        const bool quiet = envelope_ <= kLevel * loudest_ && envelope_ <= floor_;
        quietSamples_ = quiet ? quietSamples_ + 1 : 0;
        if (quietSamples_ == 0) continue;
        if (quietSamples_ == holdSamples_) freedAt_ = static_cast<long>(i);  // gain 0 from here
      }
      const float gain = static_cast<float>(
          std::max(0.0, 1.0 - static_cast<double>(quietSamples_) / holdSamples_));
      left[i] *= gain;
      if (i < rightCount) right[i] *= gain;
      if (i < alongside.size()) alongside[i] *= gain;
    }
    return freedAt_ >= 0;
  }
  // The sample of the last update() at which the hold ended (its output 0 from there on), or −1.
  long freedAt() const noexcept { return freedAt_; }

 private:
  long quietSamples_ = 0, holdSamples_ = 1, freedAt_ = -1;
  double envelope_ = 0.0, loudest_ = 0.0, decay_ = 0.0, floor_ = kFloor;
};

}  // namespace hamiltone
