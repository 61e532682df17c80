// The voice of one key of a string instrument: its 1 to 3 unison strings, a few cents apart,
// played as one — each on a rigid end, or all on the key's bridge, which couples them.
#pragma once

#include <span>
#include <vector>

#include "instruments/bridge.h"
#include "synth/instrument.h"
#include "voices/string_voice.h"
#include "voices/voice_block.h"

namespace hamiltone {

class UnisonStrings {
 public:
  // The key's unison strings, each on its unisonPatch(), and its bridge when the key has one
  // (bridge mass > 0). May allocate; throws std::invalid_argument naming the patch field (from
  // the voices and the bridge).
  void prepare(const Instrument& instrument, int note, double sampleRate, int maxBlock);
  void reset() noexcept;

  // unaCorda (the soft pedal, CC67): the action shifted, the hammer misses the first string of a
  // three-string unison and strikes the other two; keys of one or two strings are struck as ever.
  // On a bridge the missed string rings too, driven through the bridge.
  void noteOn(double velocity, bool unaCorda = false) noexcept;
  void release(double damperScale, double contact) noexcept;
  void setBend(double semitones) noexcept;
  void setLiveTail(bool on) noexcept;         // each string's (StringVoice::setLiveTail)
  bool takesLiveTail() const;                 // a string of the key does (StringVoice's)
  int stringsInModes() const;                 // its strings stepping their modes (modal_tail.h)
  void setQuietFloor(double floor) noexcept;  // each string's: the caller shares it among them

  // Writes (not adds) the key's next left.size() samples (at most maxBlock; right as long): the
  // strings' pickups summed, a mono patch's on both channels. Never allocates.
  void process(std::span<float> left, std::span<float> right) noexcept;
  int channels() const { return strings_.front().channels(); }

  bool bridged() const { return bridged_; }
  // The force the bridge passed to the soundboard over the last process(), one value per output
  // sample (the mean over its scheme steps), N; zeros without a bridge.
  std::span<const float> boardForce() const { return {boardForce_.data(), frames_}; }

  bool active() const;  // a string sounds
  // The bridged key fell silent for good in the last process(): from this sample on its output and
  // board force are 0, whatever the block size. −1 if it did not.
  long freedAt() const { return freedAt_; }
  int guardEvents() const;
  double fundamentalHz() const { return strings_.front().fundamentalHz(); }  // the first string's
  size_t size() const { return strings_.size(); }
  std::span<StringVoice> strings() { return strings_; }
  // Strings, bridge and coupling: H^{n+½} less the losses' share, J (the guard's, the tests').
  double energy() const;
  // By the strikes and the bend, all strings. Not the work of their longitudinal end force on the
  // bridge (Bridge::supplied(), −46 dB of a note at 1°): the guard does not excuse growth fed by
  // that one-way drive.
  double injectedEnergy() const;

 private:
  void processBridged(std::span<float> left, std::span<float> right) noexcept;

  std::vector<StringVoice> strings_;
  Bridge bridge_;
  double sinAngle_ = 0.0;  // sin α of the bridge: the share of the tension change that pushes it
  bool bridged_ = false, active_ = false;  // active_: the bridged key's, as one voice
  int guardEvents_ = 0;
  static constexpr int kGuardEvery = 256;  // samples between the guard's looks at the energy
  int sinceGuard_ = 0;                     // samples since the last look (or the key's start)
  long freedAt_ = -1;
  QuietDetector quiet_;  // the bridged key's, on its summed output
  std::vector<float> boardForce_, scratchLeft_, scratchRight_;
  size_t frames_ = 0;
  double wBefore_ = 0.0;  // w^n, for the coupling energy at n+½
};

}  // namespace hamiltone
