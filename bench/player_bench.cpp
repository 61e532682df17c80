// Cost of the live player's audio callback: Player::render — the MIDI drained onto the block, the
// synthesizer, the interleave — timed call by call with N grand-piano keys held (C3 upward,
// re-struck every 2 s) at 128 and 256 frames: the mean, the 99.9th percentile and the maximum per
// buffer, in ms and as a share of the buffer period. Then, per buffer size, the fewest keys at
// which the 99.9th percentile reaches 70 % of the period: what one core can promise with headroom
// left for the audio server and the rest of the system.
//
// --blocks=N sets the buffers timed per run (default 1000, the fewest a 99.9th percentile needs).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "player.h"
#include "presets/preset_loader.h"
#include "recording_reporter.h"
#include "synth/synth.h"

namespace hamiltone {
namespace {

using Clock = std::chrono::steady_clock;

constexpr double kSampleRate = 48000.0;
constexpr int kLowestKey = 48;      // C3: keys C3, C#3, … upward, the middle register
constexpr double kRestrikeS = 2.0;  // well inside the keys' T60s: every key keeps sounding
constexpr double kBudget = 0.7;     // of the buffer period
constexpr int kMaxVoices = 32;
constexpr int kBufferSizes[] = {128, 256};
constexpr int kVoiceCounts[] = {8, 16, 32};
// The Player is told a rate this many times lower than the synth's. Its overload guard (fewer
// voices above 80 % of the period) then never engages, so the keys asked for are the keys timed;
// the MIDI offsets come from the same rate and clock, so they are unchanged.
constexpr double kGuardOff = 1000.0;

int blocks = 1000;

const Instrument& piano() {
  static const Instrument instrument = loadPreset(HAMILTONE_SOURCE_DIR "/presets/grand-piano.toml");
  return instrument;
}

// A Player around a synth that holds `voices` keys from C3, struck by MIDI at the first buffer
// and every 2 s of audio after it, as a keyboard would through the player's queue.
class Rig {
 public:
  Rig(int voices, int frames)
      : voices_(voices),
        frames_(frames),
        restrike_(static_cast<long>(kRestrikeS * kSampleRate / frames)),
        out_(2 * static_cast<size_t>(frames)) {
    std::vector<bool> notes(128, false);
    for (int i = 0; i < voices; ++i) notes[kLowestKey + i] = true;
    synth_.prepare({piano()}, {.sampleRate = kSampleRate, .maxBlock = frames, .notes = notes});
    synth_.setPolyphony(voices);
    player_ =
        std::make_unique<app::Player>(synth_, midi_, nullptr, kSampleRate / kGuardOff, frames);
  }

  // One callback; returns the seconds it took.
  double render() {
    const double period = frames_ / (kSampleRate / kGuardOff);
    const std::int64_t nowNs = std::llround((block_ + 1) * period * 1e9);
    if (block_++ % restrike_ == 0)  // arrived a period ago: at the block's first sample
      for (int i = 0; i < voices_; ++i)
        midi_.push({nowNs - std::llround(period * 1e9),
                    {0x90, static_cast<std::uint8_t>(kLowestKey + i), 90}});
    const Clock::time_point start = Clock::now();
    player_->render(out_.data(), frames_, nowNs);
    const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
    benchmark::DoNotOptimize(out_.data());
    return seconds;
  }

  int activeVoices() const { return synth_.activeVoices(); }

 private:
  int voices_, frames_;
  long restrike_, block_ = 0;
  Synth synth_;
  SpscQueue<app::StampedMessage> midi_{app::MidiInput::kQueueSize};
  std::unique_ptr<app::Player> player_;
  std::vector<float> out_;
};

struct Timing {
  double mean = 0.0, p999 = 0.0, max = 0.0;  // seconds per buffer
};

// The nearest-rank 99.9th percentile: with 1000 calls, the second slowest.
Timing summarize(std::vector<double> seconds) {
  std::sort(seconds.begin(), seconds.end());
  Timing t;
  for (double s : seconds) t.mean += s / static_cast<double>(seconds.size());
  const size_t rank = static_cast<size_t>(std::ceil(0.999 * static_cast<double>(seconds.size())));
  t.p999 = seconds[std::max<size_t>(rank, 1) - 1];
  t.max = seconds.back();
  return t;
}

Timing timeRig(int voices, int frames) {
  Rig rig(voices, frames);
  std::vector<double> seconds(static_cast<size_t>(blocks));
  for (double& s : seconds) s = rig.render();
  return summarize(std::move(seconds));
}

// Each iteration is one callback, so the table's time column is the mean per buffer.
void callback(benchmark::State& state, int voices, int frames) {
  Rig rig(voices, frames);
  std::vector<double> seconds(static_cast<size_t>(blocks));
  size_t i = 0;
  for (auto _ : state) seconds[i++] = rig.render();
  if (rig.activeVoices() != voices) state.SkipWithError("not every key kept sounding");
  const Timing t = summarize(std::move(seconds));
  const double period = frames / kSampleRate;
  state.counters["mean_ms"] = 1e3 * t.mean;
  state.counters["p99.9_ms"] = 1e3 * t.p999;
  state.counters["max_ms"] = 1e3 * t.max;
  state.counters["mean_%"] = 100.0 * t.mean / period;
  state.counters["p99.9_%"] = 100.0 * t.p999 / period;
  state.counters["max_%"] = 100.0 * t.max / period;
}

// Steps the polyphony up from 1 key until the 99.9th percentile reaches 70 % of the period;
// "voices" is that count, 0 if even 32 keys stay below it.
void budget(benchmark::State& state, int frames) {
  const double period = frames / kSampleRate;
  int found = 0;
  for (auto _ : state)
    for (int voices = 1; voices <= kMaxVoices && found == 0; ++voices)
      if (timeRig(voices, frames).p999 >= kBudget * period) found = voices;
  state.counters["voices"] = found;
}

}  // namespace
}  // namespace hamiltone

int main(int argc, char** argv) {
  using namespace hamiltone;
  std::vector<char*> args;
  for (int i = 0; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg.rfind("--blocks=", 0) == 0)
      blocks = std::max(1, std::atoi(arg.c_str() + 9));
    else
      args.push_back(argv[i]);
  }
  int count = static_cast<int>(args.size());
  benchmark::Initialize(&count, args.data());
  if (benchmark::ReportUnrecognizedArguments(count, args.data())) return 1;

  for (int frames : kBufferSizes)
    for (int voices : kVoiceCounts)
      benchmark::RegisterBenchmark(
          ("callback/frames:" + std::to_string(frames) + "/voices:" + std::to_string(voices))
              .c_str(),
          [voices, frames](benchmark::State& s) { callback(s, voices, frames); })
          ->Iterations(blocks)
          ->Unit(benchmark::kMillisecond);
  for (int frames : kBufferSizes)
    benchmark::RegisterBenchmark(("polyphony_at_70pct/frames:" + std::to_string(frames)).c_str(),
                                 [frames](benchmark::State& s) { budget(s, frames); })
        ->Iterations(1)
        ->Unit(benchmark::kSecond);

  RecordingReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  std::printf("\n%d buffers timed per run\n", blocks);
  for (int frames : kBufferSizes) {
    const auto* r = reporter.find("polyphony_at_70pct/frames:" + std::to_string(frames));
    if (!r) continue;
    const int voices = static_cast<int>(r->counters.at("voices").value);
    if (voices > 0)
      std::printf(
          "%d frames (%.2f ms): the 99.9th percentile reaches 70 %% of the period at %d "
          "grand-piano key%s\n",
          frames, 1e3 * frames / kSampleRate, voices, voices == 1 ? "" : "s");
    else
      std::printf(
          "%d frames (%.2f ms): the 99.9th percentile stays below 70 %% of the period up "
          "to %d keys\n",
          frames, 1e3 * frames / kSampleRate, kMaxVoices);
  }
  benchmark::Shutdown();
}
