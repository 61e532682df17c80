// A key's unison strings: each prepared on its own patch, and struck, released, bent and reset
// together; on a bridge, stepped in turn with it one scheme step at a time.
#include "synth/unison_strings.h"

#include <algorithm>
#include <cmath>

namespace hamiltone {

void UnisonStrings::prepare(const Instrument& instrument, int note, double sampleRate,
                            int maxBlock) {
  const StringKey& key = instrument.keys.at(note - instrument.lowestNote);
  std::vector<StringVoice> strings(key.unisons);
  double added = 0.0;
  for (size_t s = 0; s < strings.size(); ++s) {
    strings[s].prepare(unisonPatch(instrument, note, static_cast<int>(s)), note, sampleRate);
    added += strings[s].coupling().selfStiffness();
  }
  const bool bridged = key.bridge.mass > 0.0;
  Bridge bridge;
  if (bridged) {
    const double k = 1.0 / (sampleRate * key.patch.oversampling);
    // The largest bend raises βT0/h, and with it K_s, by at most the tension range.
    bridge.prepare(key.bridge, k, added * std::pow(2.0, 2.0 * instrument.bendRange / 12.0));
  }
  strings_ = std::move(strings);
  bridge_ = bridge;
  sinAngle_ = std::sin(key.bridge.angle);
  bridged_ = bridged;
  for (auto* buffer : {&boardForce_, &scratchLeft_, &scratchRight_})
    buffer->assign(std::max(maxBlock, 1), 0.0f);
  quiet_.prepare(sampleRate);
  reset();
}

void UnisonStrings::reset() noexcept {
  for (StringVoice& s : strings_) s.reset();
  bridge_.reset();
  quiet_.reset();
  active_ = false;
  wBefore_ = 0.0;
  sinceGuard_ = 0;
}

void UnisonStrings::noteOn(double velocity, bool unaCorda) noexcept {
  const size_t missed = unaCorda && strings_.size() == 3 ? 1 : 0;
  if (bridged_ && !active_) reset();  // a freed key starts from rest, its bridge too
  for (size_t s = missed; s < strings_.size(); ++s) strings_[s].noteOn(velocity);
  for (size_t s = 0; s < missed; ++s) strings_[s].liftDamper();  // the key lifts all its dampers
  if (!bridged_) return;
  for (StringVoice& s : strings_) s.wake();
  quiet_.strike();
  active_ = true;
}

void UnisonStrings::release(double damperScale, double contact) noexcept {
  for (StringVoice& s : strings_) s.release(damperScale, contact);
}

void UnisonStrings::setBend(double semitones) noexcept {
  for (StringVoice& s : strings_) s.setBend(semitones);
}

void UnisonStrings::setLiveTail(bool on) noexcept {
  for (StringVoice& s : strings_) s.setLiveTail(on);
}

bool UnisonStrings::takesLiveTail() const {
  for (const StringVoice& s : strings_)
    if (s.takesLiveTail()) return true;
  return false;
}

int UnisonStrings::stringsInModes() const {
  if (!active()) return 0;  // a bridged key's strings stay active() after the key falls silent
  int count = 0;
  for (const StringVoice& s : strings_) count += s.active() && s.inModes();
  return count;
}

void UnisonStrings::setQuietFloor(double floor) noexcept {
  for (StringVoice& s : strings_) s.setQuietFloor(floor);
  quiet_.setFloor(floor < 0.0 ? floor : floor * static_cast<double>(strings_.size()));
}

bool UnisonStrings::active() const {
  if (bridged_) return active_;
  for (const StringVoice& s : strings_)
    if (s.active()) return true;
  return false;
}

int UnisonStrings::guardEvents() const {
  int events = guardEvents_;
  for (const StringVoice& s : strings_) events += s.guardEvents();
  return events;
}

double UnisonStrings::energy() const {
  double e = 0.0;
  for (const StringVoice& s : strings_) {
    e += s.energy();
    if (bridged_) e += s.couplingEnergy(wBefore_, bridge_.current());
  }
  return bridged_ ? e + bridge_.energy() : e;
}

double UnisonStrings::injectedEnergy() const {
  double e = 0.0;
  for (const StringVoice& s : strings_) e += s.injectedEnergy();
  return e;
}

void UnisonStrings::process(std::span<float> left, std::span<float> right) noexcept {
  const size_t n = left.size();
  frames_ = n;
  if (bridged_) {
    processBridged(left, right.subspan(0, n));
    return;
  }
  std::fill(boardForce_.begin(), boardForce_.begin() + n, 0.0f);
  std::fill(left.begin(), left.end(), 0.0f);
  std::fill(right.begin(), right.begin() + n, 0.0f);
  const std::span<float> oneL(scratchLeft_.data(), n), oneR(scratchRight_.data(), n);
  for (StringVoice& s : strings_) {
    if (!s.active()) continue;
    s.process(oneL, oneR);
    const bool stereo = s.channels() == 2;
    for (size_t i = 0; i < n; ++i) {
      left[i] += oneL[i];
      right[i] += stereo ? oneR[i] : oneL[i];  // a mono string feeds both channels
    }
  }
}

// Per output sample, R scheme steps; each step: every string takes the bridge's w^n, then the
// bridge takes their pull at q^n and, through sin α, their tension change there (bridge.h). w and
// u are positive away from the board (the hammer's way), so a tighter string presses the bridge
// down: the drive is −ΔT sin α. The guard and the quiet check act on the key, at its own samples
// (not where a call ends), so that they do not depend on how the audio is cut.
void UnisonStrings::processBridged(std::span<float> left, std::span<float> right) noexcept {
  const size_t n = left.size();
  const bool stereo = channels() == 2;
  auto silenceFrom = [&](size_t from) {
    std::fill(left.begin() + from, left.end(), 0.0f);
    std::fill(right.begin() + from, right.end(), 0.0f);
    std::fill(boardForce_.begin() + from, boardForce_.begin() + n, 0.0f);
  };
  freedAt_ = -1;
  if (!active_) {
    silenceFrom(0);
    return;
  }
  const double multiple = strings_.front().patch().guardEnergyMultiple;
  for (size_t i = 0; i < n; ++i) {
    double sum[2] = {0.0, 0.0}, force = 0.0;  // a mono patch leaves sum[1] at 0
    int steps = 0;
    for (bool ready = false; !ready;) {
      const double w = bridge_.current();
      double pull = 0.0, tension = 0.0;
      for (StringVoice& s : strings_) {
        double out[2] = {0.0, 0.0};
        ready = s.stepOnBridge(w, out);
        sum[0] += out[0];
        sum[1] += out[1];
        pull += s.pullOnBridge(w);
        tension += s.endTension();
      }
      wBefore_ = w;
      bridge_.step(pull, -sinAngle_ * tension);
      force += bridge_.forceOnBoard();
      ++steps;
    }
    left[i] = static_cast<float>(sum[0]);
    right[i] = static_cast<float>(stereo ? sum[1] : sum[0]);
    boardForce_[i] = static_cast<float>(force / steps);
    // The guard: a non-finite sample never leaves the key, nor does runaway energy, looked at
    // every kGuardEvery samples of the key's own. The samples as they leave, in float: a finite
    // sum beyond float's range (a gain too large) would leave as an infinity.
    bool runaway =
        !std::isfinite(left[i]) || !std::isfinite(right[i]) || !std::isfinite(boardForce_[i]);
    if (!runaway && ++sinceGuard_ == kGuardEvery) {
      sinceGuard_ = 0;
      const double h = energy();
      runaway = !std::isfinite(h) || h > multiple * injectedEnergy();
    }
    if (runaway) {
      silenceFrom(i);
      ++guardEvents_;
      freedAt_ = static_cast<long>(i);  // silenced from this sample
      reset();
      return;
    }
  }
  // The board's force falls silent with the sound, at the same sample whatever the block size.
  if (quiet_.update(left, right, n, std::span(boardForce_).first(n))) {
    active_ = false;
    freedAt_ = quiet_.freedAt();
  }
}

}  // namespace hamiltone
