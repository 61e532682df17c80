// The plugin's run path under RealtimeSanitizer: DPF's CLAP entry is linked into this binary with
// the plugin and the engine (every source compiled with -fsanitize=realtime), and the test host
// (tests/support/clap_host.h) makes each process call from a [[clang::nonblocking]] function. Any
// allocation, lock or blocking syscall in DPF's CLAP wrapper, PlayingSynth, the synthesizer or a
// voice ends the process with a report and a nonzero exit. It plays notes, every parameter, and a
// preset change — the new synthesizer taken, the old one faded out and handed back — at 44.1, 48
// and 96 kHz in blocks of 1 to 4096 frames; and fails too on a sample that is not finite or is
// outside [−1, 1]. The loader's thread builds and frees outside the real-time context, as it
// must. Without GoogleTest: nothing but the code under test runs.
#include <cmath>
#include <cstdio>
#include <span>
#include <vector>

#include "plugin_parameters.h"
#include "support/clap_performance.h"

namespace {

using namespace hamiltone::testing;
using namespace hamiltone::plugin;

// The host's process call, in a real-time context for RTSan.
struct RealtimeProcess {
  void operator()(ClapInstance& plugin, std::span<float> left, std::span<float> right,
                  std::span<const ClapEvent> events) const {
    run(plugin, left, right, events);
  }
  static void run(ClapInstance& plugin, std::span<float> left, std::span<float> right,
                  std::span<const ClapEvent> events) noexcept [[clang::nonblocking]] {
    plugin.process(left, right, events);
  }
};

// Samples that are not finite or lie outside [−1, 1].
long faults(const Take& take) {
  long bad = 0;
  for (const std::vector<float>* channel : {&take.left, &take.right})
    for (float x : *channel) bad += !std::isfinite(x) || std::abs(x) > 1.0f;
  return bad;
}

}  // namespace

int main() {
  const ClapLibrary library(clap_entry, "hamiltone_plugin_rtsan");
  const std::vector<uint32_t> blocks = {64, 4096, 7, 333, 1, 1000, 2, 127};
  int failures = 0;
  for (const double rate : {44100.0, 48000.0, 96000.0}) {
    ClapInstance plugin(library, "hamiltone.synth");
    if (!plugin.activate(rate, 1, 4096)) {
      std::printf("%6.0f Hz: activation failed\n", rate);
      return 1;
    }
    // A note, the controls moved while it sounds, a chord beyond the polyphony, the pedal.
    const Take playing = play(plugin, rate, 1.2,
                              {noteOn(0.05, 69),
                               param(0.3, kGainDb, -6.0),
                               param(0.3, kVelocityCurve, 2.0),
                               param(0.3, kDamperScale, 2.0),
                               param(0.3, kPolyphony, 2.0),
                               noteOn(0.4, 60),
                               noteOn(0.4, 64),
                               noteOn(0.4, 67),
                               noteOff(0.6, 69),
                               {0.7, ClapEvent::midiAt(0, 0xB0, 64, 127)},
                               noteOff(0.8, 60),
                               noteOff(0.8, 64),
                               noteOff(0.8, 67),
                               {1.0, ClapEvent::midiAt(0, 0xB0, 64, 0)},
                               param(1.1, kPreset, 1.0)},
                              blocks, true, RealtimeProcess{});
    // The preset change: silent blocks while the new one is built, then its first block.
    const double status = settle(plugin, kStatus, double(LoadStatus::loading), RealtimeProcess{});
    const Take after = play(plugin, rate, 0.6, {noteOn(0.0, 48), noteOff(0.4, 48)}, blocks, false,
                            RealtimeProcess{});
    const long bad = faults(playing) + faults(after);
    std::printf("%6.0f Hz: %ld samples not finite or outside [-1, 1]; preset change %s\n", rate,
                bad, status == double(LoadStatus::ready) ? "ready" : "not ready");
    std::fflush(stdout);  // before a later violation ends the process
    if (bad > 0 || status != double(LoadStatus::ready) || after.peak(0.0, 0.4) < 1e-3) ++failures;
  }
  std::printf("%s\n", failures ? "FAILED" : "passed: no real-time violation, every sample clean");
  return failures ? 1 : 0;
}
