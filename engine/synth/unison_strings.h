// The voice of one key of a string instrument: its 1 to 3 unison strings, a few cents apart,
// played as one.
#pragma once

#include <span>
#include <vector>

#include "synth/instrument.h"
#include "voices/string_voice.h"

namespace hamiltone {

class UnisonStrings {
 public:
  // The key's unison strings, each on its unisonPatch(). May allocate; throws
  // std::invalid_argument naming the patch field (from the voices).
  void prepare(const Instrument& instrument, int note, double sampleRate);
  void reset() noexcept;

  // unaCorda (the soft pedal, CC67): the action shifted, the hammer misses the first string of a
  // three-string unison and strikes the other two; keys of one or two strings are struck as ever.
  void noteOn(double velocity, bool unaCorda = false) noexcept;
  void release(double damperScale, double contact) noexcept;
  void setBend(double semitones) noexcept;
  void setQuietFloor(double floor) noexcept;  // each string's: the caller shares it among them

  bool active() const;  // a string sounds
  int guardEvents() const;
  double fundamentalHz() const { return strings_.front().fundamentalHz(); }  // the first string's
  size_t size() const { return strings_.size(); }
  std::span<StringVoice> strings() { return strings_; }  // in order, for the key's mix

 private:
  std::vector<StringVoice> strings_;
};

}  // namespace hamiltone
