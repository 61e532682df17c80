// The master section, sample by sample: one-pole smoothing of the volume, a 5 Hz DC blocker, and
// the peak limiter (master_bus.h); a final clamp and a non-finite check make the bound
// unconditional even for a limiter fed a value it cannot reduce (an infinity is zeroed first).
#include "synth/master_bus.h"

#include <algorithm>
#include <cmath>

namespace hamiltone {

void PeakLimiter::prepare(double sampleRate) {
  hold_ = std::lround(kHoldS * sampleRate);
  release_ = 1.0 - std::exp(-1.0 / (kReleaseS * sampleRate));
  reset();
  clearMeters();
}

void PeakLimiter::reset() {
  gain_ = 1.0;
  holdLeft_ = 0;
}

void PeakLimiter::clearMeters() {
  over_ = limited_ = 0;
  deepest_ = 1.0;
  peakIn_ = 0.0;
}

double PeakLimiter::deepestReductionDb() const { return -20.0 * std::log10(deepest_); }

void MasterBus::prepare(double sampleRate) {
  smoothing_ = 1.0 - std::exp(-1.0 / (kSmoothingS * sampleRate));
  for (DcBlocker& d : dc_) d.prepare(kDcCornerHz, sampleRate);
  limiter_.prepare(sampleRate);
  nonFinite_ = 0;
  reset();
}

void MasterBus::reset() {
  for (DcBlocker& d : dc_) d.reset();
  volume_ = volumeTarget_;
  limiter_.reset();
}

void MasterBus::process(std::span<float> left, std::span<float> right) noexcept {
  for (size_t i = 0; i < left.size(); ++i) {
    volume_ += smoothing_ * (volumeTarget_ - volume_);
    double x[2] = {left[i], right[i]};
    for (int c = 0; c < 2; ++c) {
      if (!std::isfinite(x[c])) {
        x[c] = 0.0;
        ++nonFinite_;
      }
      x[c] = volume_ * dc_[c].process(x[c]);
    }
    limiter_.process(x[0], x[1]);
    left[i] = static_cast<float>(std::clamp(x[0], -1.0, 1.0));
    right[i] = static_cast<float>(std::clamp(x[1], -1.0, 1.0));
  }
}

}  // namespace hamiltone
