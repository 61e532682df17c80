// The key's voice and its mix: the unison strings (UnisonStrings, each a StringVoice a few cents
// apart) or one PlateVoice; the key's pan places it in the stereo image; a linear fade frees a
// stolen key.
#include "synth/key_voice.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "voices/voice_block.h"

namespace hamiltone {

void KeyVoice::prepare(const Instrument& instrument, int note, double sampleRate, int maxBlock,
                       bool freeQuiet) {
  std::variant<UnisonStrings, PlateVoice> voice;
  if (instrument.model == InstrumentModel::string)
    voice.emplace<UnisonStrings>().prepare(instrument, note, sampleRate, maxBlock);
  else
    voice.emplace<PlateVoice>().prepare(instrument.plate, note, sampleRate);
  // Constant-power pan across the keyboard, scaled so a centred key keeps unit gain per channel.
  const int span = std::max(1, instrument.highestNote - instrument.lowestNote);
  const double position =
      instrument.panSpread * (2.0 * (note - instrument.lowestNote) / span - 1.0);  // −1 … 1
  const double angle = (position + 1.0) * std::numbers::pi / 4.0;
  voice_ = std::move(voice);
  panLeft_ = std::numbers::sqrt2 * std::cos(angle);
  panRight_ = std::numbers::sqrt2 * std::sin(angle);
  // A voice is silent under QuietDetector::kFloor of full scale at the instrument's output: in
  // its own units, divided by the instrument's gain and the louder side's pan, and shared among
  // the key's strings so that all of them together stay under it.
  const UnisonStrings* strings = std::get_if<UnisonStrings>(&voice_);
  const double heard = std::pow(10.0, instrument.gainDb / 20.0) * std::max(panLeft_, panRight_) *
                       static_cast<double>(std::max<size_t>(strings ? strings->size() : 0, 1));
  const double floor = freeQuiet ? QuietDetector::kFloor / heard : -1.0;
  std::visit([floor](auto& v) { v.setQuietFloor(floor); }, voice_);
  for (auto* buffer : {&mixLeft_, &mixRight_, &outLeft_, &outRight_, &boardForce_})
    buffer->assign(maxBlock, 0.0f);
  frames_ = 0;
  fadeSamples_ = fadeSamples(sampleRate);
  envelopeDecay_ = std::exp(-1.0 / (kEnvelopeS * sampleRate));
  attackSamples_ = std::lround(kEnvelopeS * sampleRate);
  sinceStrike_ = attackSamples_;
  fadeLeft_ = 0;
  pendingVelocity_ = -1.0;
  releasePending_ = false;
  envelope_ = loudest_ = 0.0;
  down = sustained = caught = false;
}

void KeyVoice::strike(double velocity, long order, bool unaCorda) noexcept {
  order_ = order;
  sinceStrike_ = 0;
  if (fading() || pending()) {
    pendingVelocity_ = velocity;
    pendingUnaCorda_ = unaCorda;
    releasePending_ = false;
    return;
  }
  strikeNow(velocity, unaCorda);
}

void KeyVoice::strikeNow(double velocity, bool unaCorda) noexcept {
  loudest_ = envelope_;
  if (UnisonStrings* strings = std::get_if<UnisonStrings>(&voice_))
    strings->noteOn(velocity, unaCorda);
  else
    std::get<PlateVoice>(voice_).noteOn(velocity);
}

void KeyVoice::release(double damperScale, double contact) noexcept {
  if (pending()) {
    releasePending_ = true;
    damperScale_ = damperScale;
    contact_ = contact;
    return;
  }
  std::visit([damperScale, contact](auto& v) { v.release(damperScale, contact); }, voice_);
}

void KeyVoice::fadeOut() noexcept {
  if (sounding() && !fading()) fadeLeft_ = fadeSamples_;
  pendingVelocity_ = -1.0;
  releasePending_ = false;
  down = sustained = caught = false;
}

void KeyVoice::setBend(double semitones) noexcept {
  if (UnisonStrings* strings = std::get_if<UnisonStrings>(&voice_)) strings->setBend(semitones);
}

void KeyVoice::setLiveTail(bool on) noexcept {
  if (UnisonStrings* strings = std::get_if<UnisonStrings>(&voice_)) strings->setLiveTail(on);
}

bool KeyVoice::takesLiveTail() const {
  const UnisonStrings* strings = std::get_if<UnisonStrings>(&voice_);
  return strings && strings->takesLiveTail();
}

int KeyVoice::stringsInModes() const {
  const UnisonStrings* strings = std::get_if<UnisonStrings>(&voice_);
  return strings ? strings->stringsInModes() : 0;
}

double KeyVoice::level() const {
  if (sinceStrike_ < attackSamples_) return 1.0;
  return loudest_ > 0.0 ? envelope_ / loudest_ : 0.0;
}

bool KeyVoice::sounding() const {
  return std::visit([](const auto& v) { return v.active(); }, voice_);
}

int KeyVoice::guardEvents() const {
  return std::visit([](const auto& v) { return v.guardEvents(); }, voice_);
}

double KeyVoice::fundamentalHz() const {
  const PlateVoice* plate = std::get_if<PlateVoice>(&voice_);
  return plate ? plate->lowestModeHz() : std::get_if<UnisonStrings>(&voice_)->fundamentalHz();
}

void KeyVoice::process(size_t from, size_t frames, double gain) noexcept {
  if (from == 0) {
    freedAt_ = -1;
    fadedOut_ = false;
  }
  const size_t end = from + frames;
  frames_ = end;
  size_t done = from;
  while (!fadedOut_ && done < end) {
    if (!fading() && pending()) {  // the fade is over (or its voices fell silent): strike
      strikeNow(pendingVelocity_, pendingUnaCorda_);
      freedAt_ = -1;
      pendingVelocity_ = -1.0;
      if (releasePending_) release(damperScale_, contact_);
      releasePending_ = false;
    }
    const bool wasFading = fading();
    size_t length = end - done;
    if (wasFading) length = std::min(length, static_cast<size_t>(fadeLeft_));
    render(done, length, gain);
    done += length;
    if (wasFading && !fading()) {          // free the voices; a pending strike starts next round
      freedAt_ = static_cast<long>(done);  // whether or not its strings fell quiet in the fade
      std::visit([](auto& v) { v.reset(); }, voice_);
      fadedOut_ = !pending();
    }
  }
  // A key whose fade ended inside the piece is silent for the rest of it.
  std::fill(outLeft_.begin() + done, outLeft_.begin() + end, 0.0f);
  std::fill(outRight_.begin() + done, outRight_.begin() + end, 0.0f);
  std::fill(boardForce_.begin() + done, boardForce_.begin() + end, 0.0f);
}

void KeyVoice::render(size_t offset, size_t n, double gain) noexcept {
  float* left = outLeft_.data() + offset;
  float* right = outRight_.data() + offset;
  float* force = boardForce_.data() + offset;
  // In a fade the key is freed where the fade ends (process): a quiet hold ending inside it would
  // be seen in one piece and not in the next, as the blocks fall.
  const bool inFade = fadeLeft_ > 0;
  std::span<float> mixL(mixLeft_.data(), n), mixR(mixRight_.data(), n);
  const float* bridge = nullptr;
  if (UnisonStrings* strings = std::get_if<UnisonStrings>(&voice_)) {
    strings->process(mixL, mixR);  // silence when no string sounds
    bridge = strings->boardForce().data();
    if (!inFade && strings->freedAt() >= 0 && freedAt_ < 0)
      freedAt_ = static_cast<long>(offset) + strings->freedAt();
  } else if (PlateVoice& plate = std::get<PlateVoice>(voice_); plate.active()) {
    plate.process(mixL, mixR);
  } else {
    std::fill(mixL.begin(), mixL.end(), 0.0f);
    std::fill(mixR.begin(), mixR.end(), 0.0f);
  }
  const double gl = gain * panLeft_, gr = gain * panRight_;
  sinceStrike_ += static_cast<long>(n);
  for (size_t i = 0; i < n; ++i) {
    envelope_ = std::max({static_cast<double>(std::abs(mixL[i])),
                          static_cast<double>(std::abs(mixR[i])), envelope_ * envelopeDecay_});
    loudest_ = std::max(loudest_, envelope_);
    // Linear to zero: the last faded sample is 0, and each step is at most peak / 240 at 48 kHz.
    const double fade = fadeLeft_ > 0 ? static_cast<double>(--fadeLeft_) / fadeSamples_ : 1.0;
    left[i] = static_cast<float>(gl * fade * mixL[i]);
    right[i] = static_cast<float>(gr * fade * mixR[i]);
    force[i] = bridge ? static_cast<float>(fade * bridge[i]) : 0.0f;
  }
}

}  // namespace hamiltone
