// Windowed-sinc design (Kaiser) and the ring buffer of the last `taps` inputs.
#include "voices/decimator.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace hamiltone {

namespace {

double besselI0(double x) {
  double sum = 1.0, term = 1.0;
  for (int k = 1; k < 50; ++k) {
    term *= (x / (2.0 * k)) * (x / (2.0 * k));
    sum += term;
  }
  return sum;
}

}  // namespace

void Decimator::prepare(int factor) {
  if (factor < 1)
    throw std::invalid_argument("oversampling = " + std::to_string(factor) + ": must be >= 1");
  factor_ = factor;
  taps_.assign(1, 1.0);
  if (factor > 1) {
    // Transition band 0.45 … 0.55 of the output rate: width 0.1/R of the input rate. Kaiser's
    // length for A = 86 dB: (A − 8) / (2.285 · 2π · Δf) ≈ 54 R taps, β = 0.1102 (A − 8.7) ≈ 8.5;
    // a margin over both leaves 80 dB at the band edge.
    const int length = 64 * factor + 1;
    const double cutoff = 0.5 / factor;  // of the input rate, mid-transition
    const double beta = 8.6;
    taps_.resize(length);
    double sum = 0.0;
    for (int i = 0; i < length; ++i) {
      const double x = i - 0.5 * (length - 1);
      const double sinc =
          x == 0.0 ? 2.0 * cutoff
                   : std::sin(2.0 * std::numbers::pi * cutoff * x) / (std::numbers::pi * x);
      const double r = 2.0 * i / (length - 1) - 1.0;
      taps_[i] = sinc * besselI0(beta * std::sqrt(1.0 - r * r)) / besselI0(beta);
      sum += taps_[i];
    }
    for (double& t : taps_) t /= sum;  // unit gain at DC
  }
  history_.assign(2 * taps_.size(), 0.0);
  reset();
}

void Decimator::reset() {
  std::fill(history_.begin(), history_.end(), 0.0);
  phase_ = 0;
  head_ = 0;
}

bool Decimator::filter(double in, double& out) noexcept {
  const int n = static_cast<int>(taps_.size());
  history_[head_] = in;
  history_[head_ + n] = in;
  head_ = head_ + 1 == n ? 0 : head_ + 1;
  if (++phase_ < factor_) return false;
  phase_ = 0;
  // history_[head_ … head_ + n) holds the last n inputs, oldest first.
  const double* x = history_.data() + head_;
  double acc = 0.0;
  for (int i = 0; i < n; ++i) acc += taps_[i] * x[i];
  out = acc;
  return true;
}

}  // namespace hamiltone
