// The master section, sample by sample: one-pole smoothing of the volume, a 5 Hz DC blocker, and
// a stereo-linked peak limiter with instant attack (so its ceiling is never crossed) and an
// exponential release; a final clamp and a non-finite check make the bound unconditional.
#include "synth/master_bus.h"

#include <algorithm>
#include <cmath>

namespace hamiltone {

void MasterBus::prepare(double sampleRate) {
  smoothing_ = 1.0 - std::exp(-1.0 / (kSmoothingS * sampleRate));
  release_ = 1.0 - std::exp(-1.0 / (kReleaseS * sampleRate));
  for (DcBlocker& d : dc_) d.prepare(kDcCornerHz, sampleRate);
  reset();
}

void MasterBus::reset() {
  for (DcBlocker& d : dc_) d.reset();
  volume_ = volumeTarget_;
  limiter_ = 1.0;
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
    const double peak = std::max(std::abs(x[0]), std::abs(x[1]));
    const double wanted = peak > kCeiling ? kCeiling / peak : 1.0;
    limiter_ = std::min(wanted, limiter_ + release_ * (1.0 - limiter_));
    left[i] = static_cast<float>(std::clamp(limiter_ * x[0], -1.0, 1.0));
    right[i] = static_cast<float>(std::clamp(limiter_ * x[1], -1.0, 1.0));
  }
}

}  // namespace hamiltone
