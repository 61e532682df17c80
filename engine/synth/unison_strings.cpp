// A key's unison strings: each prepared on its own patch, and struck, released, bent and reset
// together.
#include "synth/unison_strings.h"

namespace hamiltone {

void UnisonStrings::prepare(const Instrument& instrument, int note, double sampleRate) {
  std::vector<StringVoice> strings(instrument.keys.at(note - instrument.lowestNote).unisons);
  for (size_t s = 0; s < strings.size(); ++s)
    strings[s].prepare(unisonPatch(instrument, note, static_cast<int>(s)), note, sampleRate);
  strings_ = std::move(strings);
}

void UnisonStrings::reset() noexcept {
  for (StringVoice& s : strings_) s.reset();
}

void UnisonStrings::noteOn(double velocity, bool unaCorda) noexcept {
  const size_t missed = unaCorda && strings_.size() == 3 ? 1 : 0;
  for (size_t s = missed; s < strings_.size(); ++s) strings_[s].noteOn(velocity);
}

void UnisonStrings::release(double damperScale, double contact) noexcept {
  for (StringVoice& s : strings_) s.release(damperScale, contact);
}

void UnisonStrings::setBend(double semitones) noexcept {
  for (StringVoice& s : strings_) s.setBend(semitones);
}

void UnisonStrings::setQuietFloor(double floor) noexcept {
  for (StringVoice& s : strings_) s.setQuietFloor(floor);
}

bool UnisonStrings::active() const {
  for (const StringVoice& s : strings_)
    if (s.active()) return true;
  return false;
}

int UnisonStrings::guardEvents() const {
  int events = 0;
  for (const StringVoice& s : strings_) events += s.guardEvents();
  return events;
}

}  // namespace hamiltone
