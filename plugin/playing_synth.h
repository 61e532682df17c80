// What the plugin does on the audio thread, apart from any plugin format: plays the synthesizer
// the loader built last — swapped in between blocks, the one before faded out (all sound off, its
// 5 ms fade) and given back to the loader to free, the new one given the pedals, volume and bend
// the old one held — with the player's controls, and MIDI bytes placed on their frames. process()
// never allocates, locks or does I/O.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "synth_loader.h"

#if defined(__clang__) && __clang_major__ >= 20
#define HAMILTONE_PLUGIN_NONBLOCKING [[clang::nonblocking]]
#else
#define HAMILTONE_PLUGIN_NONBLOCKING
#endif

namespace hamiltone::plugin {

// What the player sets beside the preset.
struct Controls {
  double gainDb = 0.0;         // after the synthesizer's own limiter: a level trim
  double velocityCurve = 1.0;  // note-on velocity v becomes 127·(v/127)^curve: > 1 plays softer
  double damperScale = 1.0;    // Synth::setDamperScale
  int polyphony = 0;           // Synth::setPolyphony; 0: the preset's
  bool lightTails = false;     // Synth::setLiveTail: the strings' tails linear from 1e-3
  bool operator==(const Controls&) const = default;
};

// The controls' ranges, as the plugin declares them. A host may send any float (jalv's console,
// a hand-edited session): setControls keeps every value inside its range and takes NaN as the
// default — a gain of +1000 dB once made the output infinite, then NaN for good.
struct ControlRange {
  double min, max, def;
  double held(double value) const { return std::isnan(value) ? def : std::clamp(value, min, max); }
};
inline constexpr ControlRange kGainDbRange{-60.0, 12.0, 0.0};
inline constexpr ControlRange kVelocityCurveRange{0.25, 4.0, 1.0};
inline constexpr ControlRange kDamperScaleRange{0.25, 4.0, 1.0};
inline constexpr ControlRange kPolyphonyRange{0.0, 64.0, 0.0};

// 127·(v/127)^curve, rounded, kept within 1 … 127 (0 would be a note-off).
inline int curvedVelocity(int velocity, double curve) {
  const double v = 127.0 * std::pow(velocity / 127.0, curve);
  return std::clamp(static_cast<int>(std::lround(v)), 1, 127);
}

class PlayingSynth {
 public:
  static constexpr double kGainSmoothingS = 0.01;  // the gain follows its control in 10 ms
  static constexpr double kSwapFadeS = 0.01;       // the outgoing synthesizer is heard this long
  static constexpr int kMaxEvents = 512;           // per piece of a block; more start a new piece

  explicit PlayingSynth(SynthLoader& loader) : loader_(loader) {}
  ~PlayingSynth() { release(); }
  PlayingSynth(const PlayingSynth&) = delete;
  PlayingSynth& operator=(const PlayingSynth&) = delete;

  // Not the audio thread, with none running (the plugin's activate): sized for `sampleRate`. The
  // first setControls() after it takes effect at once (a session's gain is not faded in from
  // 0 dB).
  void prepare(double sampleRate);
  // The same (deactivate): frees the synthesizers this holds.
  void release();

  // The audio thread, before process(): takes effect from this block.
  void setControls(const Controls& controls) noexcept;

  // Writes min(left, right) frames. `midi`: the block's messages in frame order, each with
  // .frame, .size and .data[] (DPF's MidiEvent has them); one longer than 3 bytes (sysex) or not
  // a channel message is skipped, a frame past the block is taken as its last.
  template <class Midi>
  void process(std::span<float> left, std::span<float> right,
               std::span<const Midi> midi) noexcept HAMILTONE_PLUGIN_NONBLOCKING;

  // The recipe of the synthesizer playing, and that synthesizer, or nullptr before the first (for
  // tests).
  const SynthRecipe* playing() const { return current_ ? &current_->recipe : nullptr; }
  const Synth* synth() const { return current_ ? &current_->synth : nullptr; }

 private:
  template <class Midi>
  std::optional<MidiMessage> message(const Midi& m) const noexcept;
  void adopt() noexcept HAMILTONE_PLUGIN_NONBLOCKING;
  void remember(const MidiMessage& m) noexcept HAMILTONE_PLUGIN_NONBLOCKING;
  void applyControls() noexcept HAMILTONE_PLUGIN_NONBLOCKING;
  void render(std::span<float> left, std::span<float> right,
              std::span<const SynthEvent> events) noexcept HAMILTONE_PLUGIN_NONBLOCKING;
  void applyGain(std::span<float> left,
                 std::span<float> right) noexcept HAMILTONE_PLUGIN_NONBLOCKING;

  SynthLoader& loader_;
  BuiltSynth* current_ = nullptr;   // the caller's, from loader_.take()
  BuiltSynth* outgoing_ = nullptr;  // fading out, then given back
  long outgoingLeft_ = 0;           // frames it is still heard
  long swapFade_ = 1;
  Controls controls_;
  double gain_ = 1.0, gainTarget_ = 1.0, gainSmoothing_ = 0.0;
  bool controlsSet_ = false;  // since prepare(): until then the gain jumps to its control
  // The last volume (CC7), sustain, sostenuto and soft pedal and pitch bend played (status 0:
  // none since prepare(), or reset by CC121), for the next synthesizer adopted.
  enum Held { kVolume, kSustain, kSostenuto, kSoft, kBend, kHeldCount };
  MidiMessage held_[kHeldCount] = {};
  SynthEvent events_[kMaxEvents];
  std::vector<float> scratchLeft_, scratchRight_;  // the outgoing synthesizer's output
};

template <class Midi>
std::optional<MidiMessage> PlayingSynth::message(const Midi& m) const noexcept {
  if (m.size < 1 || m.size > 3 || m.data[0] < 0x80 || m.data[0] >= 0xF0) return std::nullopt;
  MidiMessage out{m.data[0], static_cast<std::uint8_t>(m.size > 1 ? m.data[1] & 0x7F : 0),
                  static_cast<std::uint8_t>(m.size > 2 ? m.data[2] & 0x7F : 0)};
  if (out.kind() == midi::noteOn && out.data2 > 0)
    out.data2 = static_cast<std::uint8_t>(curvedVelocity(out.data2, controls_.velocityCurve));
  return out;
}

template <class Midi>
void PlayingSynth::process(std::span<float> left, std::span<float> right,
                           std::span<const Midi> midi) noexcept {
  adopt();
  const size_t frames = std::min(left.size(), right.size());
  size_t done = 0, next = 0;
  while (done < frames) {
    // The messages up to kMaxEvents, at their offsets in this piece; the piece ends at the
    // block's end, or at the frame of the first message that did not fit.
    size_t count = 0, until = frames;
    for (; next < midi.size(); ++next) {
      const size_t at = std::clamp<size_t>(midi[next].frame, done, frames - 1);
      if (count == kMaxEvents) {
        until = std::max(at, done + 1);
        break;
      }
      if (const std::optional<MidiMessage> m = message(midi[next])) {
        events_[count++] = {static_cast<int>(at - done), *m};
        remember(*m);
      }
    }
    render(left.subspan(done, until - done), right.subspan(done, until - done),
           std::span<const SynthEvent>(events_, count));
    done = until;
  }
  applyGain(left.first(frames), right.first(frames));
}

}  // namespace hamiltone::plugin
