// The audio callback under RealtimeSanitizer: Player::render is [[clang::nonblocking]], so in this
// binary (every source compiled with -fsanitize=realtime) any allocation, lock or blocking
// syscall made inside it — by the player, the synthesizer, a voice or the C++ library — ends the
// process with a report and a nonzero exit. The synthesizer's workers render keys in the same
// real-time context (WorkerPool::drain is nonblocking too), so their path is checked as well.
// It plays the test performance at 44.1, 48 and 96 kHz in blocks of 1, 64, 256 and 1024 frames
// (from the MIDI queue and, at once, as a score, as --midi and --notes play it),
// on the callback's thread alone and on 3 threads; then, on 3 threads, a chord of six keys under
// the pedal, struck again and again, so that every block shares several keys with the workers.
// It fails too on any sample that is not finite, is subnormal or is outside [−1, 1]. Without
// GoogleTest: nothing but the code under test runs.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "support/player_performance.h"

namespace {

using namespace hamiltone;

// Told a rate this many times lower than the synth's, the player never finds a block late, so its
// overload protection (slow under the sanitizer) drops no key; the messages are stamped on the
// same clock, so they still land at the block's first sample.
constexpr double kGuardOff = 1000.0;

// 0.3 s of the chord at `rate`, struck every 50 ms with the pedal down, through a player told
// rate / kGuardOff, in blocks of `frames`; the samples go to `faults`.
void playChord(app::Player& player, SpscQueue<app::StampedMessage>& midi, double rate, int frames,
               testing::SampleFaults& faults) {
  std::vector<float> interleaved(2 * static_cast<size_t>(frames));
  const long blocks = std::lround(0.3 * rate / frames);
  const long restrike = std::max(1L, std::lround(0.05 * rate / frames));
  const double period = frames / (rate / kGuardOff);
  for (long n = 0; n < blocks; ++n) {
    const std::int64_t nowNs = testing::nanoseconds(static_cast<double>(n + 1) * period);
    const std::int64_t arrival = nowNs - testing::nanoseconds(period);
    if (n == 0) midi.push({arrival, {0xB0, 64, 127}});
    if (n % restrike == 0)
      for (int note : testing::kPerformanceNotes)
        midi.push({arrival, {0x90, static_cast<std::uint8_t>(note), 100}});
    player.render(interleaved.data(), frames, nowNs);
    faults.check(interleaved);
  }
}

}  // namespace

int main() {
  const std::vector<Instrument> instruments = testing::performanceInstruments(HAMILTONE_SOURCE_DIR);
  int failures = 0;
  for (int threads : {1, 3})
    for (double rate : {44100.0, 48000.0, 96000.0}) {
      Synth synth;
      SynthSetup setup = testing::performanceSetup(rate);
      setup.threads = threads;
      synth.prepare(instruments, setup);
      for (int frames : {1, 64, 256, 1024}) {
        synth.setPolyphony(0);  // undo what an earlier run's overload protection lowered
        synth.setLiveTail(false);
        SpscQueue<app::StampedMessage> midi(256);
        SpscQueue<float> record(2 * static_cast<size_t>(rate));
        app::Player player(synth, midi, &record, rate, frames);
        player.setScore(testing::kPerformance);  // the score's path too, merged with the queue's
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
            "%d thread%s, %6.0f Hz, %4d frames: %ld samples recorded, %ld dropped, peak load "
            "%.2f, %ld non-finite, %ld subnormal, %ld outside [-1, 1]\n",
            threads, threads == 1 ? " " : "s", rate, frames, recorded, status.recordDropped,
            status.peakLoad, faults.nonFinite, faults.subnormal, faults.outOfRange);
        std::fflush(stdout);  // before a later violation ends the process
        if (faults.any() || synth.nonFiniteSamples() > 0) ++failures;
      }
    }
  for (int frames : {64, 256}) {
    Synth synth;
    SynthSetup setup = testing::performanceSetup(48000.0);
    setup.threads = 3;
    synth.prepare(instruments, setup);
    synth.setPolyphony(std::size(testing::kPerformanceNotes));
    SpscQueue<app::StampedMessage> midi(256);
    app::Player player(synth, midi, nullptr, 48000.0 / kGuardOff, frames);
    testing::SampleFaults faults;
    playChord(player, midi, 48000.0, frames, faults);
    std::printf(
        "chord of %zu keys on 3 threads, %4d frames: %d sounding, %ld non-finite, %ld "
        "subnormal, %ld outside [-1, 1]\n",
        std::size(testing::kPerformanceNotes), frames, synth.activeVoices(), faults.nonFinite,
        faults.subnormal, faults.outOfRange);
    std::fflush(stdout);
    if (faults.any() || synth.nonFiniteSamples() > 0 ||
        synth.activeVoices() != static_cast<int>(std::size(testing::kPerformanceNotes)))
      ++failures;
  }
  // The modal tail (voices/modal_tail.h) in the callback: the chord struck softly under the pedal
  // with the live tail on, so that its strings go linear and into their modes within 3 s and drop
  // modes as they decay; struck again, they leave them (and, struck this softly, take them again
  // within 0.1 s).
  {
    Synth synth;
    SynthSetup setup = testing::performanceSetup(48000.0);
    setup.threads = 3;
    synth.prepare(instruments, setup);
    synth.setLiveTail(true);
    SpscQueue<app::StampedMessage> midi(256);
    app::Player player(synth, midi, nullptr, 48000.0 / kGuardOff, 256);
    testing::SampleFaults faults;
    std::vector<float> interleaved(2 * 256);
    const double period = 256 / (48000.0 / kGuardOff);
    int inModes = 0, struck = 0;
    for (long n = 0; n < 3 * 48000 / 256 + 20; ++n) {
      const std::int64_t nowNs = testing::nanoseconds(static_cast<double>(n + 1) * period);
      const std::int64_t arrival = nowNs - testing::nanoseconds(period);
      if (n == 0) midi.push({arrival, {0xB0, 64, 127}});
      if (n == 0 || n == 3 * 48000 / 256)
        for (int note : testing::kPerformanceNotes)
          midi.push({arrival, {0x90, static_cast<std::uint8_t>(note), 30}});
      player.render(interleaved.data(), 256, nowNs);
      faults.check(interleaved);
      if (n == 3 * 48000 / 256 - 1) inModes = synth.stringsInModes();
      if (n == 3 * 48000 / 256) struck = synth.stringsInModes();
    }
    std::printf(
        "chord in its modal tail: %d strings in their modes after 3 s, %d at the strike, %d 0.1 s "
        "on; %ld non-finite, %ld subnormal, %ld outside [-1, 1]\n",
        inModes, struck, synth.stringsInModes(), faults.nonFinite, faults.subnormal,
        faults.outOfRange);
    std::fflush(stdout);
    if (faults.any() || synth.nonFiniteSamples() > 0 || inModes == 0 || struck >= inModes)
      ++failures;
  }
  std::printf("%s\n", failures ? "FAILED" : "passed: no real-time violation, every sample clean");
  return failures ? 1 : 0;
}
