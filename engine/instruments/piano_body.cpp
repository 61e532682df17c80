// The piano's body: one step of the soundboard and the sympathetic strings together.
#include "instruments/piano_body.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace hamiltone {

namespace {
constexpr int kCheckEvery = 256;     // steps between looks for quiet damped keys
constexpr double kWakeFloors = 4.0;  // a sleeping key wakes at this many floors (below)
// After a strike no key sleeps for this long (s): the struck string's wave reaches the board only
// after its travel along the string (A0's: 16 ms, from the hammer to the bridge at c_T), and keys
// that slept before it came would wake only at the next look after it.
constexpr double kAwakeAfterStrikeS = 0.05;
}  // namespace

void PianoBody::prepare(const PianoBodySpec& spec, std::span<const BoardPoint> bridgePoints,
                        std::span<const SympatheticKey> keys) {
  board_.prepare(spec.board, spec.sampleRate, bridgePoints, spec.pickups);
  strings_.prepare(keys, board_, spec.sampleRate, spec.sympatheticMaxHz,
                   spec.sympatheticMaxPartials);
  forces_.setZero(board_.points());
  active_.reserve(board_.points());
  awakeSteps_ = static_cast<int>(std::lround(kAwakeAfterStrikeS * spec.sampleRate));
  reset();
}

void PianoBody::reset() noexcept {
  board_.reset();
  strings_.reset();
  updateActivePoints();
  supplied_ = switched_ = 0.0;
  sinceCheck_ = 0;
  awakeLeft_ = 0;
}

void PianoBody::step(std::span<const double> bridgeForces) noexcept {
  const int n = board_.points();
  const Eigen::VectorXd& w = board_.displacements();  // w^n; after board_.step(), w^{n+1}
  forces_.setZero();
  strings_.step(w, {forces_.data(), static_cast<std::size_t>(n)});  // (Y3), (Y4) with w^n
  // The voices' work, Σ_k F_k (w_k^{n+1} − w_k^{n−1})/2, is the board's (S3) — every force's,
  // from its modes, so w is needed at no driven point — less the strings' (Y4) forces', which
  // are zero but at coupled keys, the points in use.
  double before = 0.0;  // Σ F_strings,k w_k^{n−1}
  const double* wPrev = board_.previousDisplacements().data();
  const double* fs = forces_.data();
#pragma omp simd reduction(+ : before)
  for (int k = 0; k < n; ++k) before += fs[k] * wPrev[k];
  board_.addForces({forces_.data(), static_cast<std::size_t>(n)});
  board_.addForces(bridgeForces);
  board_.step();
  double after = 0.0;  // Σ F_strings,k w_k^{n+1}
  const double* wNext = board_.displacements().data();
#pragma omp simd reduction(+ : after)
  for (int k = 0; k < n; ++k) after += fs[k] * wNext[k];
  supplied_ += board_.lastWork() - 0.5 * (after - before);
  if (awakeLeft_ > 0) --awakeLeft_;
  if (++sinceCheck_ == kCheckEvery) sleepAndWakeKeys();
}

// A damped key is quiet when its strings ring with less than the floor and would hold less than
// the floor following the board at its point in their static shape (½ U T0/L w²): then its
// coupling does nothing the floor would notice, and it sleeps — but not within
// kAwakeAfterStrikeS of a strike. A sleeping damped key's w is read again (two gathers of Φ) and
// the key wakes, at rest on the board, once that energy passes kWakeFloors floors (twice the w
// of the sleep threshold: keys at the threshold do not flip at every look). Without the wake, keys
// asleep before a note's wave reached the bridge stayed out for good, and the board missed their
// load.
void PianoBody::sleepAndWakeKeys() noexcept {
  sinceCheck_ = 0;
  const Eigen::VectorXd& w = board_.displacements();
  const Eigen::VectorXd& wPrev = board_.previousDisplacements();
  const double floor = std::max(quietFloor_, quietRelative_ * energy());
  bool changed = false;
  for (int key = 0; key < keys(); ++key) {
    if (!strings_.damped(key) || strings_.excluded(key)) continue;
    if (strings_.asleep(key)) {
      board_.refreshPoint(key);
      if (strings_.followingEnergy(key, w[key]) < kWakeFloors * floor) continue;
      switched_ -= strings_.wake(key, w[key], wPrev[key]);
      changed = true;
    } else if (awakeLeft_ == 0 && strings_.ringingEnergy(key, w[key], wPrev[key]) < floor &&
               strings_.followingEnergy(key, w[key]) < floor) {
      switched_ -= strings_.sleep(key, w[key], wPrev[key]);
      changed = true;
    }
  }
  if (changed) updateActivePoints();
}

void PianoBody::updateActivePoints() noexcept {
  active_.clear();  // within the capacity reserved in prepare
  for (int key = 0; key < keys(); ++key)
    if (strings_.coupled(key)) active_.push_back(key);
  board_.setActivePoints(active_);
}

void PianoBody::setDamper(int key, double contact) noexcept {
  strings_.setDamper(key, contact);
  if (strings_.asleep(key) && !strings_.damped(key)) {
    wakeAtRest(key);
    updateActivePoints();
  }
}

// A sleeping key back in the coupling, at rest on the board where it is now: its point, out of
// use while it slept, is read again first; the jump in energy is booked.
void PianoBody::wakeAtRest(int key) noexcept {
  board_.refreshPoint(key);
  switched_ -= strings_.wake(key, board_.displacement(key), board_.previousDisplacements()[key]);
}

// A voice taking a key is about to drive the board: every sleeping damped key wakes, at rest on
// it, and none sleeps for kAwakeAfterStrikeS — time for the struck string's wave to arrive.
void PianoBody::setExcluded(int key, bool excluded) noexcept {
  board_.refreshPoint(key);  // it may have been asleep, out of use
  switched_ -= strings_.setExcluded(key, excluded, board_.displacement(key),
                                    board_.previousDisplacements()[key]);
  for (int other = 0; excluded && other < keys(); ++other)
    if (strings_.asleep(other) && !strings_.excluded(other)) wakeAtRest(other);
  if (excluded) awakeLeft_ = awakeSteps_;
  updateActivePoints();
}

double PianoBody::energy() const noexcept {
  return board_.energy() + strings_.energy(board_.displacements(), board_.previousDisplacements());
}

}  // namespace hamiltone
