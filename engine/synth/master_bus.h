// The master section after the voices are summed: DC blocker, volume (MIDI CC7, smoothed), and a
// safety limiter, so that no sample leaves the engine outside [−1, 1] or non-finite.
#pragma once

#include <algorithm>
#include <cmath>
#include <span>

#include "voices/pickup.h"

namespace hamiltone {

// The last stage: a stereo-linked peak limiter with zero latency, and its meters. Its threshold
// is its ceiling: below it the gain is exactly 1 and a frame passes unchanged (bit-transparent);
// at the first frame whose peak would cross it the gain drops at once to ceiling/peak (instant
// attack: no sample leaves above the ceiling, no overshoot), holds for kHoldS after the last frame
// that needed it, then recovers towards 1 with the time constant kReleaseS, and is exactly 1 again
// once within kSnap of it. No lookahead: the engine adds no latency for a host or the live player
// to compensate, at the price of a gain step (a little distortion) on the frames it acts on — and
// the presets are set so that it does not act (docs/validation.md, "Dynamics"). When it does, the
// meters say how often and how deep, and the front ends report them.
class PeakLimiter {
 public:
  static constexpr double kCeiling = 0.98;  // −0.18 dBFS
  static constexpr double kHoldS = 0.02;    // about the period of B0: no gain ripple on a bass wave
  static constexpr double kReleaseS = 0.05;  // time constant of the recovery after the hold
  static constexpr double kSnap = 1e-6;      // the gain is 1 again within this (−8.7e-6 dB)

  void prepare(double sampleRate);  // also clears the meters
  void reset();                     // the gain to 1, the hold over; keeps the meters
  void clearMeters();

  // One frame in place.
  void process(double& left, double& right) noexcept {
    const double peak = std::max(std::abs(left), std::abs(right));
    peakIn_ = std::max(peakIn_, peak);
    if (peak * gain_ > kCeiling) {  // attack: the gain this frame needs, at once
      gain_ = kCeiling / peak;
      if (peak * gain_ > kCeiling) gain_ = std::nextafter(gain_, 0.0);  // a rounding up
    }
    if (peak > kCeiling) {  // a frame that needs the limiter restarts the hold
      holdLeft_ = hold_;
      ++over_;
    } else if (holdLeft_ > 0) {
      --holdLeft_;
    } else if (gain_ < 1.0) {  // release, but not this frame if it would cross the ceiling
      const double next = gain_ + release_ * (1.0 - gain_);
      if (1.0 - next < kSnap)
        gain_ = 1.0;  // peak ≤ kCeiling here
      else if (peak * next <= kCeiling)
        gain_ = next;
    }
    if (gain_ < 1.0) {
      ++limited_;
      deepest_ = std::min(deepest_, gain_);
      left *= gain_;
      right *= gain_;
    }
  }

  double gain() const { return gain_; }            // now: 1 when idle
  long overFrames() const { return over_; }        // frames whose input peak was over the ceiling
  long limitedFrames() const { return limited_; }  // frames it reduced (attack, hold and release)
  double deepestGain() const {
    return deepest_;
  }                                          // the lowest gain it applied: 1 if it never acted
  double deepestReductionDb() const;         // −20·log10(deepestGain()), ≥ 0
  double peakIn() const { return peakIn_; }  // the largest |sample| that entered it
  long holdFrames() const { return hold_; }
  double releaseCoefficient() const { return release_; }

 private:
  double gain_ = 1.0, release_ = 0.0;
  long hold_ = 0, holdLeft_ = 0;  // frames
  long over_ = 0, limited_ = 0;
  double deepest_ = 1.0, peakIn_ = 0.0;
};

class MasterBus {
 public:
  static constexpr double kCeiling = PeakLimiter::kCeiling;
  static constexpr double kSmoothingS = 0.01;  // the volume follows CC7 with this time constant
  static constexpr double kDcCornerHz = 5.0;

  void prepare(double sampleRate);  // also clears the meters
  void reset();                     // the filters and the limiter; keeps the meters
  void setVolume(double gain) { volumeTarget_ = gain; }  // linear, ≥ 0
  void settleVolume() { volume_ = volumeTarget_; }       // at once, without the smoothing

  // In place over both channels. Counts the non-finite samples it replaced by zero.
  void process(std::span<float> left, std::span<float> right) noexcept;

  // The meters, since prepare(); read them between two process() calls.
  long nonFinite() const { return nonFinite_; }
  double limiterGain() const { return limiter_.gain(); }  // 1 when idle
  const PeakLimiter& limiter() const { return limiter_; }

 private:
  DcBlocker dc_[2];
  PeakLimiter limiter_;
  double volume_ = 1.0, volumeTarget_ = 1.0, smoothing_ = 0.0;
  long nonFinite_ = 0;
};

}  // namespace hamiltone
