// How the synthesizer renders a piece (the samples between two events): its busy keys on the
// pool, summed in a fixed order, then each instrument's body over the piece, sample by sample.
// With a body to step and threads to share (no more than the cores), the piece goes in parts of
// kPart samples, so that a body steps one part while the keys render the next: the same operations
// on the same values, in the same order for each sample, as at once — the same bits.
#include <algorithm>
#include <cmath>

#include "synth/synth.h"

namespace hamiltone {

void Synth::render(std::span<float> left, std::span<float> right) noexcept {
  int count = 0;
  for (size_t p = 0; p < voices_.size(); ++p) {
    Body* body = bodies_[p].get();
    if (body) body->driverCount = 0;
    for (size_t key = 0; key < voices_[p].size(); ++key) {
      KeyVoice& v = voices_[p][key];
      if (!v.busy()) continue;
      // The keys rendered in this piece drive the body over all of it (one may fall silent and
      // free itself inside it: its force is zero from then on).
      if (body) {
        body->drivers[body->driverCount] = static_cast<int>(key);
        body->slots[body->driverCount++] = count;
      }
      busy_[count++] = {&v, gains_[p], v.left().data(), v.right().data()};
    }
  }
  bool stepping = false;
  for (size_t p = 0; p < bodies_.size(); ++p) {
    if (!bodies_[p]) continue;
    beginBody(p, left.size());
    stepping = stepping || !bodies_[p]->idle;
  }
  if (stepping && count > 0 && inParts_ && left.size() >= 2 * kPart)
    renderInParts(count, left, right);
  else
    renderAtOnce(count, left, right);
}

void Synth::renderAtOnce(int count, std::span<float> left, std::span<float> right) noexcept {
  const size_t frames = left.size();
  auto renderKey = [this, frames](int k) noexcept {
    busy_[k].voice->process(frames, busy_[k].gain);
  };
  pool_->run(count, renderKey);
  for (int k = 0; k < count; ++k) {
    const KeyVoice& v = *busy_[k].voice;
    keyFreedAt_[k].store(v.busy() ? -1 : v.freedAt(), std::memory_order_relaxed);
  }
  mixKeys(count, 0, frames, left, right);
  for (size_t p = 0; p < bodies_.size(); ++p)
    if (bodies_[p]) stepBody(p, 0, frames, frames, left, right);
}

// The keys' outputs summed in (instrument, note) order: the same float additions, in the same
// order, whichever thread rendered which key.
void Synth::mixKeys(int count, size_t from, size_t to, std::span<float> left,
                    std::span<float> right) noexcept {
  for (int k = 0; k < count; ++k) {
    const float* keyLeft = busy_[k].left;
    const float* keyRight = busy_[k].right;
    for (size_t i = from; i < to; ++i) {
      left[i] += keyLeft[i];
      right[i] += keyRight[i];
    }
  }
}

// The jobs, in the order they are claimed: the keys' part 0, then for each part c ≥ 1 the keys'
// part c and the mix of part c − 1 (its keys summed, then the bodies stepped over it), and last
// the mix of the last part. A key's part waits for its part before (on another thread only when
// that key's part before is still running there); a mix waits for every key's part and for the
// mix before. Each waits only for jobs claimed before it, so every wait ends.
void Synth::renderInParts(int count, std::span<float> left, std::span<float> right) noexcept {
  const size_t frames = left.size();
  const int parts = static_cast<int>((frames + kPart - 1) / kPart);
  for (int k = 0; k < count; ++k) {
    keyParts_[k].store(0, std::memory_order_relaxed);
    keyFreedAt_[k].store(-1, std::memory_order_relaxed);
  }
  for (int c = 0; c < parts; ++c) partKeys_[c].store(0, std::memory_order_relaxed);
  mixedParts_->store(0, std::memory_order_relaxed);
  auto span = [frames](int c) { return std::pair{c * kPart, std::min(frames, (c + 1) * kPart)}; };
  auto renderPart = [&](int c, int k) noexcept {
    while (keyParts_[k].load(std::memory_order_acquire) != c) spinPause();
    const auto [from, to] = span(c);
    KeyVoice& v = *busy_[k].voice;
    v.process(from, to - from, busy_[k].gain);
    // Fallen silent in this part, and not struck again: it stays so to the piece's end.
    if (!v.busy() && v.freedAt() >= static_cast<long>(from))
      keyFreedAt_[k].store(v.freedAt(), std::memory_order_relaxed);
    keyParts_[k].store(c + 1, std::memory_order_release);
    partKeys_[c].fetch_add(1, std::memory_order_release);
  };
  auto mixPart = [&](int c) noexcept {
    while (partKeys_[c].load(std::memory_order_acquire) != count) spinPause();
    while (mixedParts_->load(std::memory_order_acquire) != c) spinPause();
    const auto [from, to] = span(c);
    mixKeys(count, from, to, left, right);
    for (size_t p = 0; p < bodies_.size(); ++p)
      if (bodies_[p]) stepBody(p, from, to, frames, left, right);
    mixedParts_->store(c + 1, std::memory_order_release);
  };
  auto job = [&](int j) noexcept {
    if (j < count) return renderPart(0, j);
    const int c = (j - count) / (count + 1) + 1, r = (j - count) % (count + 1);
    if (c == parts) return mixPart(parts - 1);
    if (r < count) return renderPart(c, r);
    mixPart(c - 1);
  };
  pool_->run(parts * (count + 1), job);
}

// What the body does never depends on how the audio is cut into pieces or parts: a key leaves
// the sympathetic coupling when it is struck (an event, at its sample) and comes back at the
// sample its voice ends (KeyVoice::freedAt), or when the body rests; the dampers move at events;
// and the body goes to rest — exactly zero, so that stepping it or not is the same — only at
// multiples of kBodyRestCheck samples, once undriven and under the voices' quiet floor
// (−100 dBFS at the output) for that long — or at once when the 5 ms fade of a CC120 ends, which
// is an event's sample plus a fixed count. beginBody() takes what is known at the piece's start.
void Synth::beginBody(size_t program, size_t frames) noexcept {
  Body& b = *bodies_[program];
  const int drivers = b.driverCount;
  for (int d = 0; d < drivers; ++d) {
    const int key = b.drivers[d];
    const KeyVoice& v = voices_[program][key];
    b.driving[d] = v.boardForce().data();
    if (v.order() != b.struck[key]) {  // struck since: its strings are the voice's now
      b.struck[key] = v.order();
      b.excludedAt[key] = b.clock;
      b.body.setExcluded(key, true);
    }
  }
  for (size_t key = 0; key < b.forces.size(); ++key) {
    const KeyVoice& v = voices_[program][key];
    const int k = static_cast<int>(key);
    const double contact = (v.down || v.caught) ? 0.0 : contact_;  // the pedal lifts every damper
    if (contact != b.contact[key]) {
      b.body.setDamper(k, contact);
      b.contact[key] = contact;
    }
  }
  b.idle = b.resting && drivers == 0;  // none to rejoin: a driver is a key busy at the start
  if (b.idle) {
    b.clock += static_cast<long>(frames);
    b.fadeLeft = static_cast<int>(std::max(0L, b.fadeLeft - static_cast<long>(frames)));
  }
}

// The body over samples [from, to) of a piece of `frames`, its keys rendered there.
void Synth::stepBody(size_t program, size_t from, size_t to, size_t frames, std::span<float> left,
                     std::span<float> right) noexcept {
  Body& b = *bodies_[program];
  if (b.idle) return;
  const int drivers = b.driverCount;
  // A key fallen silent in these samples (or at the piece's end, with the last of them): from
  // that sample its strings are the body's again, at rest on the board, to ring in sympathy with
  // the keys played after it.
  b.rejoinCount = 0;
  for (int d = 0; d < drivers; ++d) {
    const long at = keyFreedAt_[b.slots[d]].load(std::memory_order_relaxed);
    if (at >= static_cast<long>(from) &&
        (at < static_cast<long>(to) || at == static_cast<long>(frames)))
      b.rejoins[b.rejoinCount++] = {at, b.drivers[d]};
  }
  auto rejoin = [&](long sample) {
    for (int r = 0; r < b.rejoinCount; ++r)
      if (b.rejoins[r].first == sample) b.body.setExcluded(b.rejoins[r].second, false);
  };
  for (size_t i = from; i < to; ++i) {
    if (b.rejoinCount > 0) rejoin(static_cast<long>(i));
    bool pushed = false;
    for (int d = 0; d < drivers; ++d) {
      const double f = b.driving[d][i];
      b.forces[b.drivers[d]] = f;
      pushed = pushed || f != 0.0;
    }
    if (pushed) {
      b.resting = false;
      b.lastPush = b.clock;
    }
    ++b.clock;
    // Linear to zero, as a voice fades (KeyVoice::render).
    double gain = b.gain;
    bool silenced = false;
    if (b.fadeLeft > 0) {
      gain *= static_cast<double>(--b.fadeLeft) / b.fadeSamples;
      silenced = b.fadeLeft == 0;
    }
    if (b.resting) continue;
    b.body.step(b.forces);
    double l, r;
    b.body.output(l, r);
    left[i] += static_cast<float>(gain * l);
    right[i] += static_cast<float>(gain * r);
    if (std::max(std::abs(b.gain * l), std::abs(b.gain * r)) > QuietDetector::kFloor)
      b.lastLoud = b.clock;
    if (silenced || (b.clock % kBodyRestCheck == 0 && b.clock - b.lastPush >= kBodyRestCheck &&
                     b.clock - b.lastLoud >= kBodyRestCheck))
      rest(b);
  }
  if (to == frames && b.rejoinCount > 0) rejoin(static_cast<long>(frames));  // silent from the end
}

// At rest, exactly; every key's strings back on the board — but those of a key struck in the
// last kBodyRestCheck samples, whose voice may not have pushed yet (its hammer in flight) or was
// struck during a CC120's fade: they are the voice's until the next rest.
void Synth::rest(Body& b) noexcept {
  b.body.reset();
  for (size_t key = 0; key < b.forces.size(); ++key) {
    b.body.setExcluded(static_cast<int>(key), b.clock - b.excludedAt[key] < kBodyRestCheck);
    b.forces[key] = 0.0;
  }
  b.fadeLeft = 0;
  b.resting = true;
}

}  // namespace hamiltone
