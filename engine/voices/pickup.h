// What a voice's pickups hear, and the DC blocker a displacement signal needs.
#pragma once

#include <cmath>
#include <numbers>

namespace hamiltone {

enum class PickupSignal { velocity, displacement };

// y[n] = x[n] − x[n−1] + r y[n−1]: a first-order high-pass at `cornerHz`, so that a displacement
// pickup (whose rest position may drift) leaves the voice DC-free. Velocity needs none.
class DcBlocker {
 public:
  void prepare(double cornerHz, double sampleRate) {
    r_ = std::exp(-2.0 * std::numbers::pi * cornerHz / sampleRate);
    reset();
  }
  void reset() { x1_ = y1_ = 0.0; }
  double process(double x) {
    const double y = x - x1_ + r_ * y1_;
    x1_ = x;
    y1_ = y;
    return y;
  }

 private:
  double r_ = 0.0, x1_ = 0.0, y1_ = 0.0;
};

}  // namespace hamiltone
