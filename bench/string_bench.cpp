// Cost of the piano string: one StringVoice per audio sample, and (38) against SV on the C3 string.
#include <benchmark/benchmark.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "instruments/piano_scale.h"
#include "instruments/string.h"
#include "recording_reporter.h"
#include "schemes/sav.h"
#include "schemes/stormer_verlet.h"
#include "voices/string_voice.h"

namespace hamiltone {
namespace {

constexpr double kSampleRate = 48000.0;
constexpr int kBlock = 64;
constexpr double kVelocity = 0.7;
// Re-struck every 0.5 s of audio rather than made lossless: the loss is part of what a played
// voice costs — with σ0, σ1 > 0 every step takes the lossy branch, which adds the σ1 stencil and
// the dissipation sums — so a lossless patch would time a cheaper voice than anyone hears. 0.5 s
// is far inside the patch's shortest T60 (4 s at 2 kHz), so the string is loud at every strike and
// the state never decays toward denormals; the few ms of felt contact per strike are timed too, as
// in playing. One lossless, never re-struck C3 voice is timed beside it to show what the loss
// costs.
constexpr int kRestrikeBlocks = static_cast<int>(0.5 * kSampleRate / kBlock);

// An inverted rate is a time per item, shown as e.g. "1.2ns".
benchmark::Counter timePer(double items) {
  return benchmark::Counter(items, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

struct Note {
  int midi;
  const char* name;
};
constexpr Note kNotes[] = {{21, "A0"}, {48, "C3"}, {84, "C6"}};
constexpr GridRule kGrids[] = {GridRule::twoGrid, GridRule::transverse, GridRule::longitudinal};
constexpr int kOversampling[] = {1, 4};

std::string voiceName(const Note& note, GridRule grid, int oversampling, bool lossless) {
  return std::string("StringVoice/") + note.name + "_" + std::to_string(note.midi) + "/" +
         gridRuleName(grid) + "/os:" + std::to_string(oversampling) + (lossless ? "/lossless" : "");
}

struct VoiceCase {
  Note note;
  GridRule grid;
  int oversampling;
  bool lossless;
  int tail = -1;  // −1: re-struck (above); 0, 1: in the tail, the linear tail off or on (below)
};

// The tail: struck once at kTailVelocity and left to ring until the default threshold takes the
// string linear (found on a voice of its own, the same for both cases), then timed for
// kTailBlocks as it decays on — against the same string kept geometric (scheme.linear_below = 0).
constexpr double kTailVelocity = 0.3;
constexpr int kTailBlocks = 1500;  // 2 s of audio
constexpr double kTailLatestS = 30.0;

// One iteration is one block of 64 samples, stereo, as an audio callback would ask for it.
void processVoice(benchmark::State& state, VoiceCase c) {
  StringPatch patch;
  patch.string = pianoString(c.note.midi);
  patch.grid = c.grid;
  patch.oversampling = c.oversampling;
  if (c.lossless) patch.t60Low = patch.t60High = INFINITY;
  if (c.tail == 0) patch.linearBelow = 0.0;
  StringVoice voice;
  try {
    voice.prepare(patch, c.note.midi, kSampleRate);
  } catch (const std::invalid_argument& e) {
    // The longitudinal grid asks h >= sqrt(E/ρ) k: at 48 kHz that is ~0.1 m, more than half of a
    // treble string, so its voice cannot be built without oversampling.
    const std::string why = std::string("no voice for ") + c.note.name + " on the " +
                            gridRuleName(c.grid) + " grid at oversampling " +
                            std::to_string(c.oversampling) + ": " + e.what();
    state.SkipWithError(why.c_str());
    return;
  }
  std::array<float, kBlock> left{}, right{};
  const bool inTail = c.tail >= 0;
  voice.noteOn(inTail ? kTailVelocity : kVelocity);
  if (inTail) {
    StringPatch probePatch = patch;
    probePatch.linearBelow = StringPatch{}.linearBelow;
    StringVoice probe;
    probe.prepare(probePatch, c.note.midi, kSampleRate);
    probe.noteOn(kTailVelocity);
    long start = 0;
    for (; !probe.linear() && start < std::lround(kTailLatestS * kSampleRate / kBlock); ++start)
      probe.process(left, right);
    for (long n = 0; n < start; ++n) voice.process(left, right);
    if (voice.linear() != (c.tail == 1)) {
      state.SkipWithError("the string is not (or is) in its linear tail where the case says");
      return;
    }
    state.counters["tail_from_s"] = static_cast<double>(start * kBlock) / kSampleRate;
  }
  int blocks = 0;
  for (auto _ : state) {
    if (!c.lossless && !inTail && ++blocks == kRestrikeBlocks) {
      voice.noteOn(kVelocity);
      blocks = 0;
    }
    voice.process(left, right);
    benchmark::DoNotOptimize(left.data());
    benchmark::DoNotOptimize(right.data());
  }
  // The guard silences and resets a voice, after which the loop would time an idle one.
  if (voice.guardEvents() > 0 || !voice.active())
    state.SkipWithError("the voice's guard fired: the timing is of a silenced voice");

  const double samples = static_cast<double>(state.iterations()) * kBlock;
  const double unknowns = static_cast<double>(voice.scheme().system().size());
  state.counters["segments"] = voice.segments();
  state.counters["unknowns"] = unknowns;
  // Per audio sample, per unknown per scheme step, and CPU time per second of audio ("12ms" is
  // 1.2 % of one core).
  state.counters["t/sample"] = timePer(samples);
  state.counters["t/unknown/step"] = timePer(samples * c.oversampling * unknowns);
  state.counters["cpu/audio_s"] = timePer(samples / kSampleRate);
}

// (38) against SV on the C3 string (pianoString(48), untuned), lossless, from its first mode.
constexpr int kSchemeNote = 48;
constexpr double kFirstModeAmplitude = 1e-3;  // m: small, so V' stays a small correction
constexpr int kSameGridOversampling = 16;     // k = 1/(48000·16) s: SV is stable on that grid
constexpr double kSvCourant = 0.95;           // SV's k = 0.95 h / sqrt(E/ρ)

constexpr const char* kSv = "StormerVerlet_20";
constexpr const char* kSplit = "SplitSav_38";
// (a) per step, both on the longitudinal grid at k = 1/(48000·16) s;
// (b) each at its own limit: (38) on the transverse grid at 48 kHz, SV on the same segments with
// the step the longitudinal wave needs.
const std::string kSameGrid = "SameGrid_C3_longitudinal_os16/";
const std::string kOwnLimit = "OwnLimit_C3/";
const std::string kOwnLimitSplit = kOwnLimit + kSplit + "/transverse_48k";
const std::string kOwnLimitSv = kOwnLimit + kSv + "/longitudinal_same_segments";

// u = A sin(πx/L) at x = (j+1) h, v = 0, at rest.
InitialState firstMode(const NonlinearString& string) {
  const Eigen::Index points = string.segments() - 1;
  InitialState s{Vector::Zero(string.size()), Vector::Zero(string.size())};
  for (Eigen::Index j = 0; j < points; ++j)
    s.q[j] = kFirstModeAmplitude *
             std::sin(std::numbers::pi * static_cast<double>(j + 1) / string.segments());
  return s;
}

// One iteration is one step; each run steps its own copy of the scheme built at registration.
// stepsPerSecond: how many of its steps one second of audio takes (0: not reported).
template <class Scheme>
void stepScheme(benchmark::State& state, Scheme scheme, double stepsPerSecond) {
  for (auto _ : state) {
    scheme.step();
    benchmark::DoNotOptimize(scheme.q().data());
  }
  if (!scheme.q().allFinite()) state.SkipWithError("the state went non-finite");
  const double steps = static_cast<double>(state.iterations());
  const double unknowns = static_cast<double>(scheme.system().size());
  state.counters["unknowns"] = unknowns;
  state.counters["time/unknown"] = timePer(unknowns * steps);
  if (stepsPerSecond > 0.0) {
    state.counters["steps/audio_s"] = stepsPerSecond;
    state.counters["cpu/audio_s"] = timePer(steps / stepsPerSecond);
  }
}

template <class Scheme>
void addScheme(const std::string& name, const Scheme& prototype, double stepsPerSecond) {
  benchmark::RegisterBenchmark(name.c_str(), &stepScheme<Scheme>, prototype, stepsPerSecond)
      ->UseRealTime();
}

// What the summary needs of the C3 runs, computed at registration.
struct SchemeGrids {
  double sameGridK = 0.0;
  int sameGridSegments = 0;
  int ownLimitSegments = 0;
  double svK = 0.0;
};

SchemeGrids registerBenchmarks() {
  for (const Note& note : kNotes)
    for (GridRule grid : kGrids)
      for (int os : kOversampling)
        benchmark::RegisterBenchmark(voiceName(note, grid, os, false).c_str(), &processVoice,
                                     VoiceCase{note, grid, os, false})
            ->UseRealTime()
            ->Unit(benchmark::kMicrosecond);
  for (const Note& note : kNotes)
    for (int tail : {0, 1})
      benchmark::RegisterBenchmark(
          (voiceName(note, GridRule::twoGrid, 1, false) + (tail ? "/tail" : "/tail_off")).c_str(),
          &processVoice, VoiceCase{note, GridRule::twoGrid, 1, false, tail})
          ->Iterations(kTailBlocks)
          ->UseRealTime()
          ->Unit(benchmark::kMicrosecond);
  benchmark::RegisterBenchmark(voiceName(kNotes[1], GridRule::transverse, 1, true).c_str(),
                               &processVoice, VoiceCase{kNotes[1], GridRule::transverse, 1, true})
      ->UseRealTime()
      ->Unit(benchmark::kMicrosecond);

  using Sv = StormerVerlet<NonlinearString>;
  using Split = SplitSav<NonlinearString>;
  const StringPhysics c3 = pianoString(kSchemeNote);
  SchemeGrids g;

  g.sameGridK = 1.0 / (kSampleRate * kSameGridOversampling);
  g.sameGridSegments = gridSegments(c3, GridRule::longitudinal, g.sameGridK, 0.0, 1.0);
  const NonlinearString fine(c3, g.sameGridSegments);
  const InitialState fineStart = firstMode(fine);
  addScheme(kSameGrid + kSplit, Split(fine, {.k = g.sameGridK}, fineStart), 0.0);
  addScheme(kSameGrid + kSv, Sv(fine, {.k = g.sameGridK}, fineStart), 0.0);

  const double k38 = 1.0 / kSampleRate;
  g.ownLimitSegments = gridSegments(c3, GridRule::transverse, k38, 0.0, 1.0);
  const NonlinearString coarse(c3, g.ownLimitSegments);
  const InitialState coarseStart = firstMode(coarse);
  g.svK = kSvCourant * coarse.spacing() / std::sqrt(c3.young / c3.density);
  addScheme(kOwnLimitSplit, Split(coarse, {.k = k38}, coarseStart), 1.0 / k38);
  addScheme(kOwnLimitSv, Sv(coarse, {.k = g.svK}, coarseStart), 1.0 / g.svK);
  return g;
}

const char* verdict(bool met) { return met ? "met" : "NOT met"; }

void printVoices(const RecordingReporter& reporter) {
  std::printf("\nString voice at %.0f Hz, blocks of %d, real time (median with repetitions):\n",
              kSampleRate, kBlock);
  std::printf("%-4s %-12s %3s %-9s %8s %9s %10s %8s %16s\n", "note", "grid", "os", "loss",
              "segments", "unknowns", "ns/sample", "core %", "ns/unknown/step");
  auto row = [&](const Note& note, GridRule grid, int os, bool lossless) {
    const std::string name = voiceName(note, grid, os, lossless);
    const RecordingReporter::Record* r = reporter.find(name);
    if (r == nullptr) {
      std::printf("%-4s %-12s %3d %-9s %s\n", note.name, gridRuleName(grid), os,
                  lossless ? "lossless" : "patch", "(filtered out or skipped: see the table)");
      return;
    }
    const double nsPerSample = r->seconds / kBlock * 1e9;
    const double unknowns = r->counters.at("unknowns").value;
    std::printf("%-4s %-12s %3d %-9s %8.0f %9.0f %10.1f %8.2f %16.3f\n", note.name,
                gridRuleName(grid), os, lossless ? "lossless" : "patch",
                r->counters.at("segments").value, unknowns, nsPerSample,
                100.0 * nsPerSample * kSampleRate / 1e9, nsPerSample / (os * unknowns));
  };
  for (const Note& note : kNotes)
    for (GridRule grid : kGrids)
      for (int os : kOversampling) row(note, grid, os, false);
  row(kNotes[1], GridRule::transverse, 1, true);

  if (const auto* r = reporter.find(voiceName(kNotes[1], GridRule::transverse, 1, false))) {
    const double perUnknown = r->seconds / kBlock * 1e9 / r->counters.at("unknowns").value;
    std::printf(
        "Goal: C3 voice, transverse grid, os 1, <= 2 ns per unknown per step: %.3f ns, %s\n",
        perUnknown, verdict(perUnknown <= 2.0));
  }
  // Issue 15: a voice on the two grids costs at most 0.7 of one on the transverse grid.
  for (const Note& note : kNotes) {
    const auto* two = reporter.find(voiceName(note, GridRule::twoGrid, 1, false));
    const auto* one = reporter.find(voiceName(note, GridRule::transverse, 1, false));
    if (two == nullptr || one == nullptr) continue;
    const double ratio = two->seconds / one->seconds;
    std::printf("Goal: %s voice, two-grid / transverse cost <= 0.7: %.2f, %s\n", note.name, ratio,
                verdict(ratio <= 0.7));
  }
  // The linear tail against the same string kept geometric, from the same moment.
  for (const Note& note : kNotes) {
    const std::string base = voiceName(note, GridRule::twoGrid, 1, false);
    const auto* on = reporter.find(base + "/tail");
    const auto* off = reporter.find(base + "/tail_off");
    if (on == nullptr || off == nullptr) continue;
    std::printf(
        "%s two-grid voice in its linear tail (from %.1f s after a strike at %.1f): %.0f ns per "
        "sample against %.0f kept geometric, %.2f of the cost\n",
        note.name, on->counters.at("tail_from_s").value, kTailVelocity, on->seconds / kBlock * 1e9,
        off->seconds / kBlock * 1e9, on->seconds / off->seconds);
  }
}

void printSchemes(const RecordingReporter& reporter, const SchemeGrids& g) {
  std::printf("\n(38) against Stormer-Verlet (20) on the C3 string, real time:\n");
  const auto* split = reporter.find(kSameGrid + kSplit);
  const auto* sv = reporter.find(kSameGrid + kSv);
  if (split != nullptr && sv != nullptr) {
    const double ratio = split->seconds / sv->seconds;
    std::printf(
        "(a) per step, same grid (longitudinal, k = 1/%.0f s, %d segments): %s / %s = %.3f "
        "(goal <= 1.3: %s)\n",
        1.0 / g.sameGridK, g.sameGridSegments, kSplit, kSv, ratio, verdict(ratio <= 1.3));
  }
  split = reporter.find(kOwnLimitSplit);
  sv = reporter.find(kOwnLimitSv);
  if (split != nullptr && sv != nullptr) {
    const double splitSteps = kSampleRate, svSteps = 1.0 / g.svK;
    const double splitCost = split->seconds * splitSteps, svCost = sv->seconds * svSteps;
    std::printf("(b) per second of audio, each at its own limit, %d segments:\n",
                g.ownLimitSegments);
    std::printf("    %s  k = 1/%.0f s: %.1f ns/step x %.0f steps = %.3f ms per audio s\n", kSplit,
                splitSteps, split->seconds * 1e9, splitSteps, splitCost * 1e3);
    std::printf("    %s  k = 1/%.0f s: %.1f ns/step x %.0f steps = %.3f ms per audio s\n", kSv,
                svSteps, sv->seconds * 1e9, svSteps, svCost * 1e3);
    std::printf(
        "    %s / %s = %.2f (steps alone: %.2f; per step on this grid: %s / %s = %.3f)\n"
        "    goal: the split scheme wins by about an order of magnitude\n",
        kSv, kSplit, svCost / splitCost, svSteps / splitSteps, kSplit, kSv,
        split->seconds / sv->seconds);
  }
}

}  // namespace
}  // namespace hamiltone

int main(int argc, char** argv) {
  using namespace hamiltone;
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  const SchemeGrids grids = registerBenchmarks();
  RecordingReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();

  printVoices(reporter);
  printSchemes(reporter, grids);
  return 0;
}
