// The string's three grid rules on the grand-piano preset (issue 15 item 6): every key × velocity ×
// {transverse ×1, two-grid ×1, longitudinal ×16} struck once, rendered mono and timed, for the
// validation report (docs/validation/sections/string_grids.py). A measurement tool, not a Google
// Benchmark: each run is one fixed render (the first unison string of the key, the pickup signal
// as the preset has it), its process loop timed whole with steady_clock; the cheap configurations
// take turns over several renders and report the least and the median time, the converged one is
// rendered once. The least is the cost to compare: on a shared machine the other jobs can only add
// to a render's time, and renders of a few tens of milliseconds are often hit (their median
// ratios moved by ±0.1 from one run of the report to the next).
//
//   hamiltone_validate_grids PRESET OUT_DIR [--keys 21,36,...] [--velocities 30,80,127]
//                            [--seconds 0.6] [--repeats 5]
//
// Writes OUT_DIR/runs.csv (one row a run), OUT_DIR/partials.csv (per key and configuration: the
// linear scheme's partials below 20 kHz, schemePartial, and the first three longitudinal modes
// m·sqrt(E/ρ)/(2L) of the continuous string) and OUT_DIR/<note>_v<velocity>_<config>.f32 (the
// samples, little-endian float32, 48 kHz).
#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

#include "instruments/string_tuning.h"
#include "presets/preset_loader.h"
#include "synth/denormals.h"
#include "synth/instrument.h"
#include "voices/string_voice.h"

namespace hamiltone {
namespace {

constexpr double kSampleRate = 48000.0;
constexpr int kBlock = 64;
constexpr double kTopHz = 20000.0;  // the partials listed: those below it
constexpr int kLongitudinalModes = 3;
constexpr double kMinTimedS = 1.0;  // of the cheap configurations' renders, per key and velocity
constexpr int kMaxRepeats = 40;

struct Config {
  const char* name;
  GridRule grid;
  int oversampling;  // the reference's least: doubled per key, up to kMaxReference (below)
  bool cheap;        // timed over several renders; the reference is rendered once
};
constexpr Config kConfigs[] = {{"transverse", GridRule::transverse, 1, true},
                               {"two-grid", GridRule::twoGrid, 1, true},
                               {"longitudinal", GridRule::longitudinal, 16, false}};
// The reference must resolve the transverse wave too: its u grid (the longitudinal grid, h >= 1.05
// sqrt(E/ρ) k) is refined until it has at least twice the two grids' fine segments. At 16 C6 has
// 24 segments to the two grids' 17, and its energy between the partials is 9 dB below what 32 and
// 64 agree on (within 0.2 dB).
constexpr int kMaxReference = 64;

struct Options {
  std::filesystem::path preset, out;
  std::vector<int> keys{21, 36, 48, 60, 72, 84, 96};
  std::vector<int> velocities{30, 80, 127};
  double seconds = 0.6;
  int repeats = 5;
};

std::string noteName(int midi) {
  static constexpr const char* kNames[] = {"C",  "C#", "D",  "D#", "E",  "F",
                                           "F#", "G",  "G#", "A",  "A#", "B"};
  return kNames[midi % 12] + std::to_string(midi / 12 - 1);
}

std::vector<int> parseInts(std::string_view text, const char* flag) {
  std::vector<int> values;
  while (!text.empty()) {
    const size_t comma = std::min(text.find(','), text.size());
    int v = 0;
    const std::string_view item = text.substr(0, comma);
    const auto [end, error] = std::from_chars(item.data(), item.data() + item.size(), v);
    if (error != std::errc() || end != item.data() + item.size())
      throw std::invalid_argument(std::string(flag) + ": '" + std::string(item) +
                                  "' is not an integer");
    values.push_back(v);
    text.remove_prefix(std::min(comma + 1, text.size()));
  }
  if (values.empty()) throw std::invalid_argument(std::string(flag) + ": no values");
  return values;
}

Options parseOptions(int argc, char** argv) {
  Options o;
  std::vector<std::string_view> positional;
  for (int i = 1; i < argc; ++i) {
    const std::string_view a = argv[i];
    if (a.starts_with("--")) {
      if (i + 1 >= argc) throw std::invalid_argument(std::string(a) + " needs a value");
      const std::string_view value = argv[++i];
      if (a == "--keys")
        o.keys = parseInts(value, "--keys");
      else if (a == "--velocities")
        o.velocities = parseInts(value, "--velocities");
      else if (a == "--seconds")
        o.seconds = std::stod(std::string(value));
      else if (a == "--repeats")
        o.repeats = parseInts(value, "--repeats").front();
      else
        throw std::invalid_argument("unknown option " + std::string(a));
    } else {
      positional.push_back(a);
    }
  }
  if (positional.size() != 2) throw std::invalid_argument("expected PRESET and OUT_DIR");
  if (!(o.seconds > 0.0 && o.seconds <= 10.0))
    throw std::invalid_argument("--seconds: between 0 and 10");
  if (o.repeats < 1 || o.repeats > 20) throw std::invalid_argument("--repeats: 1 to 20");
  for (int v : o.velocities)
    if (v < 1 || v > 127) throw std::invalid_argument("--velocities: 1 to 127");
  o.preset = positional[0];
  o.out = positional[1];
  return o;
}

// One strike from rest, rendered into `samples`; returns the seconds the process loop took.
double render(StringVoice& voice, int velocity, std::vector<float>& samples) {
  voice.reset();
  voice.noteOn(velocity / 127.0);
  std::vector<float> unused;  // a mono patch leaves the right channel alone
  const auto start = std::chrono::steady_clock::now();
  for (size_t i = 0; i < samples.size(); i += kBlock) {
    const size_t n = std::min<size_t>(kBlock, samples.size() - i);
    voice.process(std::span<float>(samples.data() + i, n), std::span<float>(unused));
  }
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The linear scheme's partials below kTopHz and the continuous string's first longitudinal modes.
void writePartials(std::ostream& out, const std::string& prefix, const NonlinearString& string,
                   double k) {
  for (int m = 1; m < string.segments(); ++m) {
    const double f = schemePartial(string, k, m);
    if (!(f < kTopHz)) break;
    out << prefix << ",transverse," << m << ',' << f << '\n';
  }
  const StringPhysics& p = string.physics();
  for (int m = 1; m <= kLongitudinalModes; ++m)
    out << prefix << ",longitudinal," << m << ','
        << m * std::sqrt(p.young / p.density) / (2.0 * p.length) << '\n';
}

double least(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }

double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

int run(const Options& o) {
  const Instrument piano = loadPreset(o.preset);
  std::filesystem::create_directories(o.out);
  std::ofstream runs(o.out / "runs.csv"), partials(o.out / "partials.csv");
  runs << "note,midi,velocity,config,oversampling,segments,longitudinal_segments,unknowns,f0_hz,"
          "hammer_m_s,ns_per_sample,ns_median_per_sample,repeats,guard_events,file\n";
  partials << "note,midi,config,kind,m,hz\n";
  const ScopedFlushToZero flush;
  const auto samples = static_cast<size_t>(std::lround(o.seconds * kSampleRate));
  constexpr size_t kCount = std::size(kConfigs);
  for (int midi : o.keys) {
    const std::string note = noteName(midi);
    StringPatch patches[kCount];
    StringVoice voices[kCount];
    for (size_t c = 0; c < kCount; ++c) {
      patches[c] = unisonPatch(piano, midi, 0);
      patches[c].grid = kConfigs[c].grid;
      patches[c].oversampling = kConfigs[c].oversampling;
      patches[c].channels = 1;
      if (!kConfigs[c].cheap) patches[c].linearBelow = 0.0;  // the reference geometric throughout
      voices[c].prepare(patches[c], midi, kSampleRate);
      while (!kConfigs[c].cheap && patches[c].oversampling < kMaxReference &&
             voices[c].segments() < 2 * voices[1].segments()) {  // [1]: the two grids
        patches[c].oversampling *= 2;
        voices[c].prepare(patches[c], midi, kSampleRate);
      }
      writePartials(partials, note + ',' + std::to_string(midi) + ',' + kConfigs[c].name,
                    voices[c].scheme().system().string(),
                    1.0 / (kSampleRate * patches[c].oversampling));
    }
    for (int velocity : o.velocities) {
      // The cheap configurations take turns, so that a change in the shared machine's load
      // falls on both alike; each is rendered at least `repeats` times and for kMinTimedS in all.
      std::vector<double> seconds[kCount];
      std::vector<float> out[kCount];
      double timed = 0.0;
      for (int round = 0; round < kMaxRepeats; ++round) {
        if (round >= o.repeats && timed >= kMinTimedS) break;
        for (size_t c = 0; c < kCount; ++c) {
          if (!kConfigs[c].cheap && round > 0) continue;
          out[c].assign(samples, 0.0f);
          seconds[c].push_back(render(voices[c], velocity, out[c]));
          if (kConfigs[c].cheap) timed += seconds[c].back();
        }
      }
      for (size_t c = 0; c < kCount; ++c) {
        const Config& config = kConfigs[c];
        const StringPatch& patch = patches[c];
        const NonlinearString& string = voices[c].scheme().system().string();
        const std::string file =
            note + "_v" + std::to_string(velocity) + "_" + config.name + ".f32";
        std::ofstream(o.out / file, std::ios::binary)
            .write(reinterpret_cast<const char*>(out[c].data()),
                   static_cast<std::streamsize>(samples * sizeof(float)));
        const double ns = 1e9 * least(seconds[c]) / static_cast<double>(samples);
        const double nsMedian = 1e9 * median(seconds[c]) / static_cast<double>(samples);
        // As StringVoice::noteOn maps the velocity.
        const double speed =
            patch.velocityMin + (patch.velocityMax - patch.velocityMin) *
                                    std::pow(velocity / 127.0, patch.velocityCurve);
        char line[512];
        std::snprintf(
            line, sizeof line, "%s,%d,%d,%s,%d,%d,%d,%lld,%.9g,%.6g,%.6g,%.6g,%zu,%d,%s\n",
            note.c_str(), midi, velocity, config.name, patch.oversampling, string.grid().transverse,
            string.grid().longitudinal, static_cast<long long>(voices[c].scheme().system().size()),
            voices[c].fundamentalHz(), speed, ns, nsMedian, seconds[c].size(),
            voices[c].guardEvents(), file.c_str());
        runs << line << std::flush;
        std::fprintf(stderr,
                     "%-3s v%-3d %-12s x%-2d %3d/%-3d segments %8.0f ns/sample (%zu runs)\n",
                     note.c_str(), velocity, config.name, patch.oversampling,
                     string.grid().transverse, string.grid().longitudinal, ns, seconds[c].size());
      }
    }
  }
  return runs && partials ? 0 : 1;
}

}  // namespace
}  // namespace hamiltone

int main(int argc, char** argv) {
  try {
    return hamiltone::run(hamiltone::parseOptions(argc, argv));
  } catch (const std::exception& e) {
    std::fprintf(stderr,
                 "hamiltone_validate_grids: %s\nusage: hamiltone_validate_grids PRESET OUT_DIR "
                 "[--keys 21,36,...] [--velocities 30,80,127] [--seconds 0.6] [--repeats 5]\n",
                 e.what());
    return 2;
  }
}
