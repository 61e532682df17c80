// The decimator: flat passband, 80 dB stopband above the output Nyquist, unit gain at DC.
#include "voices/decimator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

namespace hamiltone {
namespace {

// RMS of the decimated output of a unit sine at `hz` (input rate R · 48 kHz), after the filter
// has filled.
double gain(int factor, double hz) {
  Decimator d;
  d.prepare(factor);
  const double rate = 48000.0 * factor;
  std::vector<double> out;
  for (int n = 0; n < 48000 * factor; ++n) {
    double y;
    if (d.push(std::sin(2.0 * std::numbers::pi * hz * n / rate), y)) out.push_back(y);
  }
  double s = 0.0;
  for (size_t i = out.size() / 2; i < out.size(); ++i) s += out[i] * out[i];
  return std::sqrt(s / static_cast<double>(out.size() - out.size() / 2)) * std::sqrt(2.0);
}

TEST(Decimator, PassesTheAudioBandAndRejectsWhatWouldAlias) {
  for (int r : {2, 4, 16}) {
    for (double hz : {100.0, 1000.0, 10000.0, 20000.0})
      EXPECT_NEAR(20.0 * std::log10(gain(r, hz)), 0.0, 0.01) << "R " << r << " at " << hz;
    for (double hz : {26400.0, 30000.0, 40000.0})  // ≥ 0.55 of 48 kHz: would fold into the band
      EXPECT_LT(20.0 * std::log10(gain(r, hz)), -79.0) << "R " << r << " at " << hz;
  }
}

TEST(Decimator, FactorOnePassesSamplesThrough) {
  Decimator d;
  d.prepare(1);
  double y = 0.0;
  ASSERT_TRUE(d.push(0.25, y));
  EXPECT_EQ(y, 0.25);
  EXPECT_THROW(d.prepare(0), std::invalid_argument);
}

}  // namespace
}  // namespace hamiltone
