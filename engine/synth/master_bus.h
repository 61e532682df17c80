// The master section after the voices are summed: DC blocker, volume (MIDI CC7, smoothed), and a
// safety limiter, so that no sample leaves the engine outside [−1, 1] or non-finite.
#pragma once

#include <span>

#include "voices/pickup.h"

namespace hamiltone {

class MasterBus {
 public:
  static constexpr double kCeiling = 0.98;     // the limiter's threshold, −0.18 dBFS
  static constexpr double kReleaseS = 0.05;    // its gain recovers with this time constant
  static constexpr double kSmoothingS = 0.01;  // the volume follows CC7 with this time constant
  static constexpr double kDcCornerHz = 5.0;

  void prepare(double sampleRate);
  void reset();
  void setVolume(double gain) { volumeTarget_ = gain; }  // linear, ≥ 0

  // In place over both channels. Counts the non-finite samples it replaced by zero.
  void process(std::span<float> left, std::span<float> right) noexcept;

  long nonFinite() const { return nonFinite_; }
  double limiterGain() const { return limiter_; }  // 1 when idle

 private:
  DcBlocker dc_[2];
  double volume_ = 1.0, volumeTarget_ = 1.0, smoothing_ = 0.0;
  double limiter_ = 1.0, release_ = 0.0;
  long nonFinite_ = 0;
};

}  // namespace hamiltone
