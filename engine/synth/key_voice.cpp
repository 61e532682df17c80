// The key's voices and their mix: each unison string is a StringVoice a few cents apart, or one
// PlateVoice; the key's pan places it in the stereo image; a linear fade frees a stolen key.
#include "synth/key_voice.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace hamiltone {

void KeyVoice::prepare(const Instrument& instrument, int note, double sampleRate, int maxBlock) {
  std::vector<StringVoice> strings;
  std::unique_ptr<PlateVoice> plate;
  if (instrument.model == InstrumentModel::string) {
    const StringKey& key = instrument.keys.at(note - instrument.lowestNote);
    strings.resize(key.unisons);
    for (int s = 0; s < key.unisons; ++s) {
      // Spread evenly across ±detune/2: one string at 0, two at ±d/2, three at −d/2, 0, +d/2.
      const double cents =
          key.unisons == 1 ? 0.0 : key.detuneCents * (s / (key.unisons - 1.0) - 0.5);
      StringPatch patch = key.patch;
      patch.a4Hz *= std::pow(2.0, cents / 1200.0);
      // One hammer strikes all the unisons: each string gets a share of its mass and felt
      // stiffness, which is the same hammer exactly while the strings move alike (F = K δ^p).
      patch.hammer.mass /= key.unisons;
      patch.hammer.stiffness /= key.unisons;
      patch.bendRange = instrument.bendRange;
      strings[s].prepare(patch, note, sampleRate);
    }
  } else {
    plate = std::make_unique<PlateVoice>();
    plate->prepare(instrument.plate, note, sampleRate);
  }
  // Constant-power pan across the keyboard, scaled so a centred key keeps unit gain per channel.
  const int span = std::max(1, instrument.highestNote - instrument.lowestNote);
  const double position =
      instrument.panSpread * (2.0 * (note - instrument.lowestNote) / span - 1.0);  // −1 … 1
  const double angle = (position + 1.0) * std::numbers::pi / 4.0;
  strings_ = std::move(strings);
  plate_ = std::move(plate);
  panLeft_ = std::numbers::sqrt2 * std::cos(angle);
  panRight_ = std::numbers::sqrt2 * std::sin(angle);
  for (auto* buffer : {&voiceLeft_, &voiceRight_, &mixLeft_, &mixRight_})
    buffer->assign(maxBlock, 0.0f);
  fadeSamples_ = std::max(1, static_cast<int>(std::lround(kFadeS * sampleRate)));
  fadeLeft_ = 0;
  pendingVelocity_ = -1.0;
  down = sustained = false;
}

void KeyVoice::strike(double velocity, long order) noexcept {
  for (StringVoice& s : strings_) s.noteOn(velocity);
  if (plate_) plate_->noteOn(velocity);
  order_ = order;
}

void KeyVoice::strikeAfterFade(double velocity, long order) noexcept {
  pendingVelocity_ = velocity;
  pendingOrder_ = order;
}

void KeyVoice::release() noexcept {
  for (StringVoice& s : strings_) s.release();
  if (plate_) plate_->release();
  pendingVelocity_ = -1.0;
}

void KeyVoice::fadeOut() noexcept {
  if (sounding() && !fading()) fadeLeft_ = fadeSamples_;
  pendingVelocity_ = -1.0;
  down = sustained = false;
}

void KeyVoice::setBend(double semitones) noexcept {
  for (StringVoice& s : strings_) s.setBend(semitones);
}

bool KeyVoice::sounding() const {
  for (const StringVoice& s : strings_)
    if (s.active()) return true;
  return plate_ && plate_->active();
}

int KeyVoice::guardEvents() const {
  int events = plate_ ? plate_->guardEvents() : 0;
  for (const StringVoice& s : strings_) events += s.guardEvents();
  return events;
}

double KeyVoice::fundamentalHz() const {
  return plate_ ? plate_->lowestModeHz() : strings_.front().fundamentalHz();
}

void KeyVoice::process(std::span<float> left, std::span<float> right, double gain) noexcept {
  lastPeak_ = 0.0;
  size_t done = 0;
  while (done < left.size()) {
    const bool wasFading = fading();
    size_t length = left.size() - done;
    if (wasFading) length = std::min(length, static_cast<size_t>(fadeLeft_));
    render(left.subspan(done, length), right.subspan(done, length), gain);
    done += length;
    if (!wasFading || fading()) continue;
    // The fade is over: free the voices, and strike what waited for it from this sample on.
    for (StringVoice& s : strings_) s.reset();
    if (plate_) plate_->reset();
    if (pendingVelocity_ < 0.0) return;
    strike(pendingVelocity_, pendingOrder_);
    pendingVelocity_ = -1.0;
    down = true;
  }
}

void KeyVoice::render(std::span<float> left, std::span<float> right, double gain) noexcept {
  const size_t n = left.size();
  std::span<float> mixL(mixLeft_.data(), n), mixR(mixRight_.data(), n);
  std::span<float> voiceL(voiceLeft_.data(), n), voiceR(voiceRight_.data(), n);
  std::fill(mixL.begin(), mixL.end(), 0.0f);
  std::fill(mixR.begin(), mixR.end(), 0.0f);
  auto add = [&](bool stereo) {
    for (size_t i = 0; i < n; ++i) {
      mixL[i] += voiceL[i];
      mixR[i] += stereo ? voiceR[i] : voiceL[i];  // a mono voice feeds both channels
    }
  };
  for (StringVoice& s : strings_) {
    if (!s.active()) continue;
    s.process(voiceL, voiceR);
    add(s.channels() == 2);
  }
  if (plate_ && plate_->active()) {
    plate_->process(voiceL, voiceR);
    add(true);
  }
  float peak = 0.0f;
  for (size_t i = 0; i < n; ++i) peak = std::max({peak, std::abs(mixL[i]), std::abs(mixR[i])});
  lastPeak_ = std::max(lastPeak_, static_cast<double>(peak));

  const double gl = gain * panLeft_, gr = gain * panRight_;
  for (size_t i = 0; i < n; ++i) {
    // Linear to zero: the last faded sample is 0, and each step is at most peak / 240 at 48 kHz.
    const double fade = fadeLeft_ > 0 ? static_cast<double>(--fadeLeft_) / fadeSamples_ : 1.0;
    left[i] += static_cast<float>(gl * fade * mixL[i]);
    right[i] += static_cast<float>(gr * fade * mixR[i]);
  }
}

}  // namespace hamiltone
