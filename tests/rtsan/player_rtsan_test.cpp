// The audio callback under RealtimeSanitizer: Player::render is [[clang::nonblocking]], so in this
// binary (every source compiled with -fsanitize=realtime) any allocation, lock or blocking
// syscall made inside it — by the player, the synthesizer, a voice or the C++ library — ends the
// process with a report and a nonzero exit. It plays the test performance at 44.1, 48 and 96 kHz
// in blocks of 1, 64, 256 and 1024 frames, and fails too on any sample that is not finite, is
// subnormal or is outside [−1, 1]. Without GoogleTest: nothing but the code under test runs.
#include <cstdio>
#include <vector>

#include "support/player_performance.h"

int main() {
  using namespace hamiltone;
  const std::vector<Instrument> instruments = testing::performanceInstruments(HAMILTONE_SOURCE_DIR);
  int failures = 0;
  for (double rate : {44100.0, 48000.0, 96000.0}) {
    Synth synth;
    synth.prepare(instruments, testing::performanceSetup(rate));
    for (int frames : {1, 64, 256, 1024}) {
      synth.setPolyphony(0);  // undo what an earlier run's overload protection lowered
      SpscQueue<app::StampedMessage> midi(256);
      SpscQueue<float> record(2 * static_cast<size_t>(rate));
      app::Player player(synth, midi, &record, rate, frames);
      std::vector<float> interleaved(2 * static_cast<size_t>(frames)), drained(2 * 1024);
      testing::SampleFaults faults;
      long recorded = 0;
      testing::playPerformance(
          player, midi, rate, frames, interleaved, [&](std::span<const float> block) {
            faults.check(block);
            recorded += static_cast<long>(record.pop(drained.data(), drained.size()));
          });
      const app::Player::Status status = player.status();
      std::printf(
          "%6.0f Hz, %4d frames: %ld samples recorded, %ld dropped, peak load %.2f, "
          "%ld non-finite, %ld subnormal, %ld outside [-1, 1]\n",
          rate, frames, recorded, status.recordDropped, status.peakLoad, faults.nonFinite,
          faults.subnormal, faults.outOfRange);
      std::fflush(stdout);  // before a later violation ends the process
      if (faults.any() || synth.nonFiniteSamples() > 0) ++failures;
    }
  }
  std::printf("%s\n", failures ? "FAILED" : "passed: no real-time violation, every sample clean");
  return failures ? 1 : 0;
}
