// A short performance for the live player's tests (the gtest suite, the allocation guard and the
// RealtimeSanitizer run): the bundled grand piano and small cymbal on a few keys, every kind of
// message the synthesizer handles, more keys than the voice limit (so voices are stolen), played
// through a Player in blocks of any size on a simulated clock.
#pragma once

#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "player.h"
#include "presets/preset_loader.h"
#include "synth/synth.h"

namespace hamiltone::testing {

// Piano on program 0 with its limit lowered to 3 keys; the cymbal on program 1 (limit 4).
inline constexpr int kPerformancePolyphony = 3;
inline constexpr int kPerformanceNotes[] = {48, 52, 55, 60, 62, 64};

inline std::vector<Instrument> performanceInstruments(const std::string& sourceDir) {
  Instrument piano = loadPreset(sourceDir + "/presets/grand-piano.toml");
  piano.polyphony = kPerformancePolyphony;
  return {piano, loadPreset(sourceDir + "/presets/small-cymbal.toml")};
}

inline SynthSetup performanceSetup(double sampleRate) {
  SynthSetup setup{.sampleRate = sampleRate, .maxBlock = 1024, .notes = std::vector<bool>(128)};
  for (int note : kPerformanceNotes) setup.notes[note] = true;
  return setup;
}

// 0.3 s: keys beyond the limit, a re-strike, the pedal, bends, both instruments, all notes off,
// all sound off, controllers reset; ff velocities so that the limiter works too.
inline constexpr TimedMessage kPerformance[] = {
    {0.000, {0x90, 48, 100}}, {0.010, {0x90, 52, 80}},  {0.020, {0xB0, 64, 127}},
    {0.030, {0x90, 55, 127}}, {0.040, {0x90, 60, 127}}, {0.050, {0x80, 48, 0}},
    {0.060, {0x90, 64, 127}}, {0.070, {0xE0, 0, 127}},  {0.090, {0x90, 48, 127}},
    {0.100, {0xB0, 7, 100}},  {0.110, {0xB0, 64, 0}},   {0.120, {0xC0, 1, 0}},
    {0.125, {0x90, 60, 127}}, {0.130, {0x90, 62, 127}}, {0.140, {0xE0, 0, 0}},
    {0.150, {0x90, 64, 127}}, {0.170, {0xB0, 123, 0}},  {0.180, {0xC0, 0, 0}},
    {0.185, {0x90, 52, 127}}, {0.190, {0x90, 55, 127}}, {0.200, {0xB0, 120, 0}},
    {0.210, {0xB0, 121, 0}},  {0.220, {0x90, 60, 64}},  {0.230, {0x90, 62, 90}},
    {0.240, {0x99, 64, 110}}, {0.260, {0x80, 60, 0}},   {0.270, {0xB0, 7, 127}}};
inline constexpr double kPerformanceSeconds = 0.3;

inline std::int64_t nanoseconds(double seconds) { return std::llround(seconds * 1e9); }

// Plays kPerformance through `player` in blocks of `frames` into `interleaved` (2·frames floats).
// The clock is simulated: block n ends at (n + 1)·frames/rate, and each message is queued, stamped
// with its time, just before the first block that ends after it. After each block
// onBlock(std::span<const float>) sees the block's samples.
template <class OnBlock>
void playPerformance(app::Player& player, SpscQueue<app::StampedMessage>& midi, double sampleRate,
                     int frames, std::span<float> interleaved, OnBlock&& onBlock) {
  const long blocks = std::lround(std::ceil(kPerformanceSeconds * sampleRate / frames));
  size_t next = 0;
  for (long n = 0; n < blocks; ++n) {
    const std::int64_t nowNs = nanoseconds(static_cast<double>(n + 1) * frames / sampleRate);
    for (; next < std::size(kPerformance) && nanoseconds(kPerformance[next].seconds) < nowNs;
         ++next)
      midi.push({nanoseconds(kPerformance[next].seconds), kPerformance[next].message});
    player.render(interleaved.data(), frames, nowNs);
    onBlock(std::span<const float>(interleaved.data(), 2 * static_cast<size_t>(frames)));
  }
}

// What the player's output must never contain.
struct SampleFaults {
  long nonFinite = 0, subnormal = 0, outOfRange = 0;  // outside [−1, 1]

  void check(std::span<const float> samples) noexcept {
    for (float x : samples) {
      if (!std::isfinite(x))
        ++nonFinite;
      else if (std::fpclassify(x) == FP_SUBNORMAL)
        ++subnormal;
      else if (std::abs(x) > 1.0f)
        ++outOfRange;
    }
  }
  bool any() const { return nonFinite + subnormal + outOfRange > 0; }
};

}  // namespace hamiltone::testing
