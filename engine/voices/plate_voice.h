// A plate voice (gong, cymbal, thunder sheet): the von Kármán plate on the split scheme (38),
// sized to its note, struck by a raised-cosine force pulse, heard at two pickups.
#pragma once

#include <memory>
#include <span>
#include <vector>

#include "instruments/plate.h"
#include "schemes/sav.h"
#include "voices/decimator.h"
#include "voices/pickup.h"
#include "voices/voice_block.h"

namespace hamiltone {

// The sound: everything a preset sets for one plate voice.
struct PlatePatch {
  PlatePhysics plate;  // its size at referenceNote
  int referenceNote = 48;
  int lowestNote = 24, highestNote = 96;                   // the notes the size scaling covers
  double gridFactor = 1.0;                                 // times the minimal h of (84)
  int oversampling = 1;                                    // 1, 2, 4, 8 or 16
  double t60Low = 8.0, t60High = 2.0, t60HighHz = 4000.0;  // s at 0 Hz, s at t60HighHz
  double damperT60 = 1.0;                                  // s, once released
  double strike[2] = {0.37, 0.41};                         // fractions of Lx, Ly
  double strikeWidth = 0.02;                               // m, diameter of the felt
  double forceMax = 300.0;                                 // N, peak force at velocity 1
  double durationMin = 0.5e-3, durationMax = 3e-3;         // s, pulse at velocity 1 and 0
  double velocityCurve = 1.5;                              // force = max · v^curve
  // The note can instead move the strike point: from strike to strikeHigh across the notes.
  bool noteMovesStrike = false;
  double strikeHigh[2] = {0.5, 0.5};
  double pickups[2][2] = {{0.23, 0.31}, {0.71, 0.62}};  // (x, y) fractions, left and right
  PickupSignal signal = PickupSignal::velocity;         // displacement is DC-blocked at 5 Hz
  double gain = 0.5;                                    // output units per m/s (or per m)
  double guardEnergyMultiple = 4.0;
};

// σ(ξ) = σ0 + σ1 ξ with ξ = ω / sqrt(D/ρξ) the plate's wavenumber² at angular frequency ω.
struct PlateLoss {
  double sigma0 = 0.0, sigma1 = 0.0;
};
PlateLoss plateLossFromT60(const PlatePhysics& plate, double t60Low, double t60High, double highHz);

class PlateVoice {
 public:
  // May allocate; throws std::invalid_argument naming the patch field. Leaves the voice as it
  // was when it throws.
  void prepare(const PlatePatch& patch, int midiNote, double sampleRate);
  void reset() noexcept;

  void noteOn(double velocity) noexcept;  // 0 … 1: a harder strike is louder and shorter
  // The damper falls, its T60 damper_t60_s times `damperScale` (releasedSigma0), touching the
  // string with `contact` 0 … 1 of its loss (the half-pedal; 0: lifted, the voice's own loss).
  // May be called again at any time to move the damper: the loss changes between two steps.
  void release(double damperScale = 1.0, double contact = 1.0) noexcept;
  // Where the voice counts as silent and frees itself, as StringVoice::setQuietFloor.
  void setQuietFloor(double floor) noexcept { quiet_.setFloor(floor); }

  // Writes the next left.size() samples (and min(left, right) of right). Never allocates.
  void process(std::span<float> left, std::span<float> right) noexcept;

  bool active() const { return active_; }
  double energy() const;          // H^{n+½}, J
  double suppliedEnergy() const;  // the strikes' work
  int guardEvents() const { return guardEvents_; }
  double lowestModeHz() const { return lowestMode_; }
  const SplitSav<VonKarmanPlate>& scheme() const { return *scheme_; }

 private:
  double pickup(const Vector& q, const Vector& qNext, const double* at) const;

  PlatePatch patch_;
  std::unique_ptr<SplitSav<VonKarmanPlate>> scheme_, atRest_;
  Decimator decimators_[2];
  QuietDetector quiet_;
  DcBlocker dcBlockers_[2];
  std::vector<Eigen::Index> strikeIndex_;
  std::vector<double> strikeWeight_;
  PlateLoss loss_;
  double sampleRate_ = 0.0, k_ = 0.0, lowestMode_ = 0.0;
  double pulseOverStep() const noexcept;

  double pulseTime_ = 0.0, pulseDuration_ = 0.0, pulseForce_ = 0.0;
  int guardEvents_ = 0;
  bool active_ = false, pulsing_ = false;
};

}  // namespace hamiltone
