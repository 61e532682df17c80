// A partial's frequency measured from a recording: the Hann-windowed DFT at any frequency, the
// peak of its magnitude near an expected frequency, found by golden-section search, and a note's
// pitch glide from those peaks.
#pragma once

#include <cmath>
#include <complex>
#include <numbers>
#include <span>

namespace hamiltone::testing {

// Σ w[n] x[n] e^{−2πi f n / rate}, w the Hann window over x, n from x's first sample.
inline std::complex<double> windowedDft(std::span<const double> x, double hz, double rate) {
  double re = 0.0, im = 0.0;
  const double n = static_cast<double>(x.size());
  for (size_t i = 0; i < x.size(); ++i) {
    const double w = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * i / n);
    const double phase = 2.0 * std::numbers::pi * hz * i / rate;
    re += w * x[i] * std::cos(phase);
    im -= w * x[i] * std::sin(phase);
  }
  return {re, im};
}

inline double windowedMagnitude(std::span<const double> x, double hz, double rate) {
  return std::abs(windowedDft(x, hz, rate));
}

// The spectral peak within ±`cents` of `expected`: for a partial isolated from its neighbours the
// Hann-windowed peak sits on its frequency (60 golden-section steps: far below a millicent).
inline double peakFrequency(std::span<const double> x, double expected, double rate,
                            double cents = 30.0) {
  double a = expected * std::pow(2.0, -cents / 1200.0),
         b = expected * std::pow(2.0, cents / 1200.0);
  const double g = (std::sqrt(5.0) - 1.0) / 2.0;
  for (int i = 0; i < 60; ++i) {
    const double c = b - g * (b - a), d = a + g * (b - a);
    if (windowedMagnitude(x, c, rate) > windowedMagnitude(x, d, rate))
      b = d;
    else
      a = c;
  }
  return 0.5 * (a + b);
}

// A struck note's pitch glide in cents: its fundamental (the peak within ±60 cents of f0) over the
// first 0.1 s against 0.4–0.5 s, each Hann-windowed. x holds at least 0.5 s.
inline double glideCents(std::span<const double> x, double f0, double rate) {
  const auto tenth = static_cast<size_t>(0.1 * rate);
  return 1200.0 * std::log2(peakFrequency(x.subspan(0, tenth), f0, rate, 60.0) /
                            peakFrequency(x.subspan(4 * tenth, tenth), f0, rate, 60.0));
}

}  // namespace hamiltone::testing
