// One key of the synthesizer: the key's unison strings (or its plate), its place in the stereo
// image, and the key's state — held, sustained by the pedal, released, or fading out when stolen.
#pragma once

#include <memory>
#include <span>
#include <vector>

#include "synth/instrument.h"

namespace hamiltone {

class KeyVoice {
 public:
  static constexpr double kFadeS = 0.005;  // a stolen or silenced voice fades over 5 ms

  // May allocate; throws std::invalid_argument naming the patch field (from the voices).
  void prepare(const Instrument& instrument, int note, double sampleRate, int maxBlock);

  void strike(double velocity, long order) noexcept;  // 0 … 1; re-strikes a sounding key
  void release() noexcept;                            // the damper falls
  void fadeOut() noexcept;                            // stolen: fades, then frees itself
  // A note-on for a fading key waits for the fade to end, so the re-strike starts from rest.
  void strikeAfterFade(double velocity, long order) noexcept;
  void setBend(double semitones) noexcept;

  // Adds the key's next left.size() samples, times `gain`, into left and right. Never allocates.
  void process(std::span<float> left, std::span<float> right, double gain) noexcept;

  bool sounding() const;
  bool fading() const { return fadeLeft_ > 0; }
  double lastPeak() const { return lastPeak_; }  // of the latest block, before gain
  long order() const { return order_; }          // when it was struck: higher is newer
  int guardEvents() const;
  double fundamentalHz() const;

  bool down = false;       // the key is held
  bool sustained = false;  // released while the pedal was down: waits for the pedal to lift

 private:
  void render(std::span<float> left, std::span<float> right, double gain) noexcept;

  std::vector<StringVoice> strings_;  // the unisons (string model)
  std::unique_ptr<PlateVoice> plate_;
  std::vector<float> voiceLeft_, voiceRight_, mixLeft_, mixRight_;
  double panLeft_ = 1.0, panRight_ = 1.0;
  int fadeSamples_ = 1, fadeLeft_ = 0;
  double pendingVelocity_ = -1.0;  // < 0: none
  long pendingOrder_ = 0, order_ = 0;
  double lastPeak_ = 0.0;
};

}  // namespace hamiltone
