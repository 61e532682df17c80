// A stereo recording as a listener hears it: both channels summed, its loudness envelope, and
// where a sound starts.
#pragma once

#include <sndfile.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <vector>

namespace hamiltone::testing {

// Both channels summed: the pan and the two pickups colour them differently, the pitch is one.
inline std::vector<double> readMono(const std::filesystem::path& path, SF_INFO& info) {
  info = {};
  SNDFILE* f = sf_open(path.c_str(), SFM_READ, &info);
  if (!f || info.channels != 2) {
    if (f) sf_close(f);
    return {};
  }
  std::vector<float> samples(static_cast<size_t>(info.frames) * 2);
  sf_readf_float(f, samples.data(), info.frames);
  sf_close(f);
  std::vector<double> mono(static_cast<size_t>(info.frames));
  for (size_t i = 0; i < mono.size(); ++i) mono[i] = 0.5 * (samples[2 * i] + samples[2 * i + 1]);
  return mono;
}

// The RMS over the 1 ms (48 samples) that end at each sample.
inline std::vector<double> envelope(const std::vector<double>& x) {
  constexpr size_t kWindow = 48;
  std::vector<double> e(x.size());
  double sum = 0.0;
  for (size_t n = 0; n < x.size(); ++n) {
    sum += x[n] * x[n];
    if (n >= kWindow) sum -= x[n - kWindow] * x[n - kWindow];
    e[n] = std::sqrt(std::max(sum, 0.0) / kWindow);
  }
  return e;
}

// The first sample in [from, to) where the envelope reaches a tenth of its largest value there.
inline long onset(const std::vector<double>& e, long from, long to) {
  from = std::max(from, 0L);
  to = std::min(to, static_cast<long>(e.size()));
  if (from >= to) return -1;
  const double peak = *std::max_element(e.begin() + from, e.begin() + to);
  long n = from;
  while (n < to && e[n] < 0.1 * peak) ++n;
  return n;
}

}  // namespace hamiltone::testing
