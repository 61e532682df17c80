// One key of the synthesizer: its instrument's voice (the key's unison strings, or its plate), its
// place in the stereo image, and the key's state — held, sustained by the pedal, released, or
// fading out when stolen.
#pragma once

#include <algorithm>
#include <cmath>
#include <span>
#include <variant>
#include <vector>

#include "synth/instrument.h"
#include "synth/unison_strings.h"
#include "voices/plate_voice.h"

namespace hamiltone {

class KeyVoice {
 public:
  static constexpr double kFadeS = 0.005;      // a stolen or silenced voice fades over 5 ms
  static int fadeSamples(double sampleRate) {  // kFadeS in samples, at least one
    return std::max(1, static_cast<int>(std::lround(kFadeS * sampleRate)));
  }
  static constexpr double kEnvelopeS = 0.05;  // the loudness follower's release time constant

  // May allocate; throws std::invalid_argument naming the patch field (from the voices). With
  // freeQuiet false no voice frees itself when it falls silent (QuietDetector): it sounds until
  // stolen or silenced, the reference the tests of that culling compare against.
  void prepare(const Instrument& instrument, int note, double sampleRate, int maxBlock,
               bool freeQuiet);

  // 0 … 1. A sounding key is struck again where it is; a fading one is struck once its fade
  // ends, from rest (the note-on is pending until then).
  // unaCorda: the soft pedal is down (UnisonStrings::noteOn; a plate ignores it).
  void strike(double velocity, long order, bool unaCorda = false) noexcept;
  // The damper falls (on a pending strike: right after it), its T60 the patch's times
  // `damperScale`, touching the strings with `contact` of its loss (0 … 1: the half-pedal).
  void release(double damperScale = 1.0, double contact = 1.0) noexcept;
  void fadeOut() noexcept;  // stolen or silenced: fades over kFadeS, then frees itself
  void setBend(double semitones) noexcept;
  void setLiveTail(bool on) noexcept;  // a string key's (UnisonStrings::setLiveTail); a plate: none
  bool takesLiveTail() const;
  int stringsInModes() const;  // UnisonStrings'; a plate: 0

  // Writes the key's next `frames` samples, times `gain`, into its own output (left(), right()) at
  // [from, from + frames) of a piece of at most maxBlock: from = 0 starts a piece, and a piece
  // written in parts is the same, to the bit, as written at once. The synthesizer sums the keys'
  // outputs in a fixed order, so the mix does not depend on which thread rendered which key.
  // Touches nothing outside the key. Never allocates.
  void process(size_t from, size_t frames, double gain) noexcept;
  void process(size_t frames, double gain) noexcept { process(0, frames, gain); }
  std::span<const float> left() const { return {outLeft_.data(), frames_}; }  // the last process()
  std::span<const float> right() const { return {outRight_.data(), frames_}; }
  // What the key's bridge passed to the soundboard over the last process(), N per sample (faded
  // with the output); zeros for a key without a bridge.
  std::span<const float> boardForce() const { return {boardForce_.data(), frames_}; }
  // The sample of the last process() from which the key's bridged strings are silent and drive
  // the board no more — they fell quiet or the guard silenced them, or, in a fade, where the fade
  // ended — with no strike after it in that piece; −1 otherwise. The same sample whatever the
  // block size.
  long freedAt() const { return freedAt_; }

  bool sounding() const;  // a voice of the key is active
  bool fading() const { return fadeLeft_ > 0; }
  bool pending() const { return pendingVelocity_ >= 0.0; }
  bool busy() const { return sounding() || fading() || pending(); }  // needs process()
  // How far into its decay the key is, for stealing: the peak of its output followed sample by
  // sample with a 50 ms release (so the choice does not depend on the block size), over the
  // largest it has been since the last strike — 1 at its peak, 1e-3 at −60 dB. 1 for 50 ms after
  // a strike, so a key just struck — its hammer still on the way — is not taken for a decayed one.
  double level() const;
  long order() const { return order_; }  // when it was struck: higher is newer
  int guardEvents() const;
  double fundamentalHz() const;

  bool down = false;  // the key is held
  // Released while the pedal (CC64) held its damper off the strings, wholly or partly: its damper
  // follows the pedal until the pedal is fully up.
  bool sustained = false;
  // Held when the sostenuto pedal (CC66) went down: its damper stays off the strings, whatever
  // the sustain pedal does, until the sostenuto pedal lifts.
  bool caught = false;
  // Its damper's T60 as a multiple of the preset's, from its last note-off's release velocity
  // (Synth::releaseScale): kept while the pedal moves that damper.
  double releaseScale = 1.0;

 private:
  void render(size_t offset, size_t frames, double gain) noexcept;  // into the outputs there
  void strikeNow(double velocity, bool unaCorda) noexcept;

  std::variant<UnisonStrings, PlateVoice> voice_;  // one voice type per instrument model
  std::vector<float> mixLeft_, mixRight_, outLeft_, outRight_, boardForce_;
  size_t frames_ = 0;  // written to the outputs by the last process()
  long freedAt_ = -1;
  // Its fade ended in this piece with no strike after it: silent to the piece's end.
  bool fadedOut_ = false;
  double panLeft_ = 1.0, panRight_ = 1.0;
  int fadeSamples_ = 1, fadeLeft_ = 0;
  double pendingVelocity_ = -1.0;  // < 0: none
  bool releasePending_ = false;    // released before its pending strike
  bool pendingUnaCorda_ = false;
  double damperScale_ = 1.0, contact_ = 1.0;  // the pending release's
  long order_ = 0;
  double envelope_ = 0.0, loudest_ = 0.0, envelopeDecay_ = 0.0;  // loudest_: since the strike
  long sinceStrike_ = 0, attackSamples_ = 0;
};

}  // namespace hamiltone
