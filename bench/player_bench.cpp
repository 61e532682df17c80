// Cost of the live player's audio callback: Player::render — the MIDI drained onto the block, the
// synthesizer, the interleave — timed call by call, as a share of the buffer period.
//
// On one core (the keys on the callback's thread alone): N grand-piano keys held (C3 upward,
// re-struck every 2 s) at 128 and 256 frames — the mean, the percentiles and the maximum per
// buffer — and, per buffer size, the fewest keys at which the 99.9th percentile reaches 70 % of
// the period: what one core can promise with headroom left for the audio server and the rest.
//
// On the worker pool (2 threads, or --threads=N): chords of 8 to 32 grand-piano keys spread evenly
// from A0 to C8, the pedal down and the chord struck again every 0.5 s, at 64, 128 and 256 frames;
// at the end a table of the 50th, 99th and 99.9th percentiles and the maximum per buffer size and
// chord. The callback's time includes the workers': Synth::process returns when every key is done.
//
// A pedalled texture at full polyphony (sustained/…): 32, 48 or 64 keys spread from A0 to C8 all
// sounding under the pedal, 8 of them struck every 0.5 s in turn (each key every 2 to 4 s), timed
// after 8 s of it, when the keys struck earlier ring in their tails as in playing — the
// polyphony issue's "64 keys live" as a pianist asks for it, where the pool/… chords strike every
// key at once every 0.5 s, the worst case. The same 64 keys with the strings' live tail on
// (sustained_live_tail/…, Synth::setLiveTail), as the player turns it on under load before it
// drops a key: the decaying strings go linear at a tension modulation of 1e-3, not the preset's
// 5e-5, and drop their modes under −80 dB, not −100 dB. Their tables give what a strike adds to
// its buffer: the mean of the buffers with one less the others' (counter strike_%), and under each
// a line counting the slowest 1 % of the buffers by the group of 8 keys struck last before them
// (counters slowest_after_g<g>): which strikes hold the 99th and 99.9th percentiles.
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
#include "presets/parameters.h"
#include "presets/preset_loader.h"
#include "recording_reporter.h"
#include "synth/synth.h"

namespace hamiltone {
namespace {

using Clock = std::chrono::steady_clock;

constexpr double kSampleRate = 48000.0;
constexpr int kLowestKey = 48;   // C3: keys C3, C#3, … upward, the middle register
constexpr double kBudget = 0.7;  // of the buffer period
constexpr int kMaxVoices = 32;
constexpr int kBufferSizes[] = {128, 256};
constexpr int kVoiceCounts[] = {8, 16, 32};
constexpr int kPoolBufferSizes[] = {64, 128, 256};
constexpr int kChordSizes[] = {8, 16, 24, 32};
constexpr int kSustainedKeys[] = {32, 48, 64};
constexpr int kSustainedFrames = 256;
constexpr int kLiveTailKeys = 64;
// The Player is told a rate this many times lower than the synth's. Its overload guard (fewer
// voices above 80 % of the period) then never engages, so the keys asked for are the keys timed;
// the MIDI offsets come from the same rate and clock, so they are unchanged.
constexpr double kGuardOff = 1000.0;

int blocks = 1000;
int poolThreads = 2;

const Instrument& piano() {
  static const Instrument instrument = loadPreset(HAMILTONE_SOURCE_DIR "/presets/grand-piano.toml");
  return instrument;
}

// What the keyboard plays: these keys, struck together at the first buffer and every `restrikeS`
// of audio after it, with the pedal down or not, on a synth of `threads` threads.
struct Playing {
  std::vector<int> keys;
  double restrikeS = 2.0;
  bool pedal = false;
  int threads = 1;
  int group = 0;          // keys struck at each restrike, in turn; 0: all of them
  double warmupS = 0.0;   // of audio played before the timing
  bool liveTail = false;  // Synth::setLiveTail from the start
};

// `count` keys from C3 upward, held and struck every 2 s (well inside their T60s: they keep
// sounding), on the callback's thread alone.
Playing fromC3(int count) {
  Playing p;
  for (int i = 0; i < count; ++i) p.keys.push_back(kLowestKey + i);
  return p;
}

// `count` keys spread evenly from A0 to C8, the pedal down, the chord struck every 0.5 s, on the
// worker pool.
Playing acrossTheKeyboard(int count) {
  Playing p{.keys = {}, .restrikeS = 0.5, .pedal = true, .threads = poolThreads};
  const Instrument& instrument = piano();
  const int span = instrument.highestNote - instrument.lowestNote;
  for (int i = 0; i < count; ++i)
    p.keys.push_back(instrument.lowestNote +
                     static_cast<int>(std::lround(static_cast<double>(i) * span / (count - 1))));
  return p;
}

// `count` keys spread as above, all sounding under the pedal, 8 struck every 0.5 s in turn, timed
// after 8 s.
Playing sustained(int count) {
  Playing p = acrossTheKeyboard(count);
  p.group = 8;
  p.warmupS = 8.0;
  return p;
}

// A Player around a synth that plays `playing` by MIDI through the player's queue, as a keyboard
// would.
class Rig {
 public:
  Rig(const Playing& playing, int frames)
      : playing_(playing),
        frames_(frames),
        restrike_(std::max(1L, std::lround(playing.restrikeS * kSampleRate / frames))),
        out_(2 * static_cast<size_t>(frames)) {
    std::vector<bool> notes(128, false);
    for (int key : playing.keys) notes[key] = true;
    synth_.prepare({piano()}, {.sampleRate = kSampleRate,
                               .maxBlock = frames,
                               .notes = notes,
                               .threads = playing.threads});
    synth_.setPolyphony(static_cast<int>(playing.keys.size()));
    synth_.setLiveTail(playing.liveTail);
    player_ =
        std::make_unique<app::Player>(synth_, midi_, nullptr, kSampleRate / kGuardOff, frames);
  }

  // One callback; returns the seconds it took.
  double render() {
    const double period = frames_ / (kSampleRate / kGuardOff);
    const std::int64_t nowNs = std::llround((block_ + 1) * period * 1e9);
    const std::int64_t arrival = nowNs - std::llround(period * 1e9);  // the block's first sample
    if (block_ == 0 && playing_.pedal) midi_.push({arrival, {0xB0, 64, 127}});
    struck_ = block_++ % restrike_ == 0;
    if (struck_) {
      const size_t n = playing_.keys.size();
      const size_t group = playing_.group > 0 ? static_cast<size_t>(playing_.group) : n;
      for (size_t i = 0; i < group; ++i) {
        const int key = playing_.keys[(strikes_ * group + i) % n];
        midi_.push({arrival, {0x90, static_cast<std::uint8_t>(key), 90}});
      }
      ++strikes_;
    }
    const Clock::time_point start = Clock::now();
    player_->render(out_.data(), frames_, nowNs);
    const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
    benchmark::DoNotOptimize(out_.data());
    return seconds;
  }

  int sounding() const { return synth_.activeVoices(); }
  bool struck() const { return struck_; }  // the last buffer had keys struck at its start
  // Which of the keys' groups (playing.group keys each, in order) was struck last; −1 before any
  // strike or where every key is struck at once.
  int lastGroup() const {
    if (playing_.group <= 0 || strikes_ == 0) return -1;
    const size_t groups = playing_.keys.size() / static_cast<size_t>(playing_.group);
    return groups == 0 ? -1 : static_cast<int>((strikes_ - 1) % groups);
  }
  int inModes() const { return synth_.stringsInModes(); }
  bool allSounding() const {
    return synth_.activeVoices() == static_cast<int>(playing_.keys.size());
  }

 private:
  Playing playing_;
  int frames_;
  long restrike_, block_ = 0;
  bool struck_ = false;
  size_t strikes_ = 0;
  Synth synth_;
  SpscQueue<app::StampedMessage> midi_{app::MidiInput::kQueueSize};
  std::unique_ptr<app::Player> player_;
  std::vector<float> out_;
};

struct Timing {
  double mean = 0.0, p50 = 0.0, p99 = 0.0, p999 = 0.0, max = 0.0;  // seconds per buffer
};

// Nearest-rank percentiles: with 1000 calls the 99.9th is the second slowest.
Timing summarize(std::vector<double> seconds) {
  std::sort(seconds.begin(), seconds.end());
  auto percentile = [&](double p) {
    const size_t rank = static_cast<size_t>(std::ceil(p * static_cast<double>(seconds.size())));
    return seconds[std::max<size_t>(rank, 1) - 1];
  };
  Timing t;
  for (double s : seconds) t.mean += s / static_cast<double>(seconds.size());
  t.p50 = percentile(0.5);
  t.p99 = percentile(0.99);
  t.p999 = percentile(0.999);
  t.max = seconds.back();
  return t;
}

Timing timeRig(const Playing& playing, int frames) {
  Rig rig(playing, frames);
  std::vector<double> seconds(static_cast<size_t>(blocks));
  for (double& s : seconds) s = rig.render();
  return summarize(std::move(seconds));
}

// Each iteration is one callback, so the table's time column is the mean per buffer.
void callback(benchmark::State& state, const Playing& playing, int frames) {
  Rig rig(playing, frames);
  for (long n = 0; n < std::lround(playing.warmupS * kSampleRate / frames); ++n) rig.render();
  std::vector<double> seconds(static_cast<size_t>(blocks));
  std::vector<int> after(static_cast<size_t>(blocks));  // the group struck last, each buffer
  size_t i = 0;
  double sounding = 0.0, inModes = 0.0;
  double struck[2] = {}, count[2] = {};  // the buffers without a strike, and with
  for (auto _ : state) {
    const double s = rig.render();
    after[i] = rig.lastGroup();
    seconds[i++] = s;
    sounding += rig.sounding();
    inModes += rig.inModes();
    struck[rig.struck()] += s;
    ++count[rig.struck()];
  }
  // Struck in turn, the top keys (no dampers, T60s of a second or two) may fall silent and free
  // themselves between their strikes, as in playing; the chords must all keep sounding.
  if (playing.group == 0 && !rig.allSounding()) state.SkipWithError("not every key kept sounding");
  // The slowest 1 % of the buffers (at least 10), counted by the group struck last before each
  // (the sustained textures' 32, 48 or 64 keys make whole groups of 8):
  // which strikes hold the tail (counters slowest_after_g<g>).
  if (playing.group > 0) {
    std::vector<size_t> order(seconds.size());
    for (size_t b = 0; b < order.size(); ++b) order[b] = b;
    const size_t slowest = std::min(order.size(), std::max<size_t>(10, order.size() / 100));
    std::partial_sort(order.begin(), order.begin() + slowest, order.end(),
                      [&](size_t a, size_t b) { return seconds[a] > seconds[b]; });
    const size_t groups = playing.keys.size() / static_cast<size_t>(playing.group);
    for (size_t g = 0; g < groups; ++g) state.counters["slowest_after_g" + std::to_string(g)] = 0;
    for (size_t b = 0; b < slowest; ++b)
      if (after[order[b]] >= 0)
        state.counters["slowest_after_g" + std::to_string(after[order[b]])]++;
  }
  state.counters["sounding"] = sounding / static_cast<double>(blocks);
  state.counters["in_modes"] = inModes / static_cast<double>(blocks);
  const Timing t = summarize(std::move(seconds));
  const double period = frames / kSampleRate;
  state.counters["mean_ms"] = 1e3 * t.mean;
  state.counters["p99.9_ms"] = 1e3 * t.p999;
  state.counters["max_ms"] = 1e3 * t.max;
  state.counters["mean_%"] = 100.0 * t.mean / period;
  state.counters["p50_%"] = 100.0 * t.p50 / period;
  state.counters["p99_%"] = 100.0 * t.p99 / period;
  state.counters["p99.9_%"] = 100.0 * t.p999 / period;
  state.counters["max_%"] = 100.0 * t.max / period;
  // What a strike adds to its buffer: the mean of the buffers with one over the others'.
  if (count[0] > 0 && count[1] > 0)
    state.counters["strike_%"] = 100.0 * (struck[1] / count[1] - struck[0] / count[0]) / period;
}

// Steps the polyphony up from 1 key until the 99.9th percentile reaches 70 % of the period;
// "voices" is that count, 0 if even 32 keys stay below it.
void budget(benchmark::State& state, int frames) {
  const double period = frames / kSampleRate;
  int found = 0;
  for (auto _ : state)
    for (int voices = 1; voices <= kMaxVoices && found == 0; ++voices)
      if (timeRig(fromC3(voices), frames).p999 >= kBudget * period) found = voices;
  state.counters["voices"] = found;
}

std::string poolName(int frames, int keys, const char* kind = "pool") {
  return std::string(kind) + "/threads:" + std::to_string(poolThreads) +
         "/frames:" + std::to_string(frames) + "/keys:" + std::to_string(keys);
}

void printRow(int keys, int frames, const benchmark::UserCounters& c, bool sounding = false) {
  std::printf("| %d | %d | %.0f %% | %.0f %% | %.0f %% | %.0f %% |", keys, frames,
              c.at("p50_%").value, c.at("p99_%").value, c.at("p99.9_%").value, c.at("max_%").value);
  if (sounding)
    std::printf(" %.1f | %.1f | %+.0f %% |", c.at("sounding").value, c.at("in_modes").value,
                c.at("strike_%").value);
  std::printf("\n");
}

// The sustained run's slowest buffers by the group of keys struck last before each, as a line
// under its table: "A0–G1 0, G#1–F#2 6, …".
void printSlowest(int keys, const benchmark::UserCounters& c) {
  const Playing p = sustained(keys);
  std::printf(
      "slowest 1 %% (at least 10) of the %d-key buffers, by the keys struck last before them:",
      keys);
  for (size_t g = 0; g * p.group < p.keys.size(); ++g) {
    const auto count = c.find("slowest_after_g" + std::to_string(g));
    if (count == c.end()) break;
    std::printf("%s %s–%s %.0f", g == 0 ? "" : ",", noteName(p.keys[g * p.group]).c_str(),
                noteName(p.keys[(g + 1) * p.group - 1]).c_str(), count->second.value);
  }
  std::printf("\n");
}

// The pool's runs as Markdown tables, for the README.
void printPoolTable(const RecordingReporter& reporter) {
  bool header = false;
  for (int frames : kPoolBufferSizes)
    for (int keys : kChordSizes) {
      const auto* r = reporter.find(poolName(frames, keys));
      if (!r) continue;
      if (!header) {
        std::printf(
            "\ngrand-piano chords spread from A0 to C8, pedal down, struck every 0.5 s, on %d "
            "thread%s: callback time as %% of the buffer period (%d buffers per run)\n\n"
            "| keys | frames | p50 | p99 | p99.9 | max |\n|---:|---:|---:|---:|---:|---:|\n",
            poolThreads, poolThreads == 1 ? "" : "s", blocks);
        header = true;
      }
      printRow(keys, frames, r->counters);
    }
  header = false;
  for (int keys : kSustainedKeys) {
    const auto* r = reporter.find(poolName(kSustainedFrames, keys, "sustained"));
    if (!r) continue;
    if (!header) {
      std::printf(
          "\ngrand-piano keys spread from A0 to C8 all sounding, pedal down, 8 struck every 0.5 s "
          "in turn, after 8 s, on %d thread%s (%d buffers per run; the mean of the keys sounding "
          "and of their strings stepping their modes, and what a strike adds to its buffer's mean, "
          "in the last columns)\n\n"
          "| keys | frames | p50 | p99 | p99.9 | max | sounding | strings in modes | a strike |\n"
          "|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
          poolThreads, poolThreads == 1 ? "" : "s", blocks);
      header = true;
    }
    printRow(keys, kSustainedFrames, r->counters, true);
  }
  for (int keys : kSustainedKeys)
    if (const auto* r = reporter.find(poolName(kSustainedFrames, keys, "sustained")))
      printSlowest(keys, r->counters);
  if (const auto* r =
          reporter.find(poolName(kSustainedFrames, kLiveTailKeys, "sustained_live_tail"))) {
    std::printf(
        "\nthe same %d keys with the strings' live tail on (the player's first step under "
        "load)\n\n| keys | frames | p50 | p99 | p99.9 | max | sounding | strings in modes | a "
        "strike |\n|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
        kLiveTailKeys);
    printRow(kLiveTailKeys, kSustainedFrames, r->counters, true);
    printSlowest(kLiveTailKeys, r->counters);
  }
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
    else if (arg.rfind("--threads=", 0) == 0)
      poolThreads = std::clamp(std::atoi(arg.c_str() + 10), 1, Synth::kMaxThreads);
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
          [voices, frames](benchmark::State& s) { callback(s, fromC3(voices), frames); })
          ->Iterations(blocks)
          ->Unit(benchmark::kMillisecond);
  for (int frames : kBufferSizes)
    benchmark::RegisterBenchmark(("polyphony_at_70pct/frames:" + std::to_string(frames)).c_str(),
                                 [frames](benchmark::State& s) { budget(s, frames); })
        ->Iterations(1)
        ->Unit(benchmark::kSecond);
  for (int frames : kPoolBufferSizes)
    for (int keys : kChordSizes)
      benchmark::RegisterBenchmark(
          poolName(frames, keys).c_str(),
          [keys, frames](benchmark::State& s) { callback(s, acrossTheKeyboard(keys), frames); })
          ->Iterations(blocks)
          ->Unit(benchmark::kMillisecond);

  for (int keys : kSustainedKeys)
    benchmark::RegisterBenchmark(
        poolName(kSustainedFrames, keys, "sustained").c_str(),
        [keys](benchmark::State& s) { callback(s, sustained(keys), kSustainedFrames); })
        ->Iterations(blocks)
        ->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark(
      poolName(kSustainedFrames, kLiveTailKeys, "sustained_live_tail").c_str(),
      [](benchmark::State& s) {
        Playing p = sustained(kLiveTailKeys);
        p.liveTail = true;
        callback(s, p, kSustainedFrames);
      })
      ->Iterations(blocks)
      ->Unit(benchmark::kMillisecond);

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
  printPoolTable(reporter);
  benchmark::Shutdown();
}
