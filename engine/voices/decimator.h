// Anti-alias decimation by an integer factor: a Kaiser-windowed sinc low-pass, evaluated once per
// output sample (polyphase), from a history buffer allocated in prepare().
#pragma once

#include <vector>

namespace hamiltone {

class Decimator {
 public:
  // factor 1 passes samples through. Passband to 0.45 of the output rate, stopband from 0.55,
  // ≥ 80 dB down (Kaiser β = 8.6). May allocate; throws std::invalid_argument for factor < 1.
  void prepare(int factor);
  void reset();  // clears the history
  int factor() const { return factor_; }

  // Feed one input sample; returns true when an output sample is ready in `out`.
  bool push(double in, double& out) noexcept {
    if (factor_ == 1) {  // the one tap 1.0: the filter's sum, 0 + 1·in, bit for bit (−0 gives +0)
      out = in + 0.0;
      return true;
    }
    return filter(in, out);
  }

 private:
  bool filter(double in, double& out) noexcept;  // factor > 1

  int factor_ = 1;
  int phase_ = 0;
  int head_ = 0;
  std::vector<double> taps_;
  std::vector<double> history_;  // twice the taps, so a window is always contiguous
};

}  // namespace hamiltone
