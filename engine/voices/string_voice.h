// A piano string voice: the struck string (HammeredString) on the split scheme (38), tuned to its
// note, oversampled and decimated to the audio rate, with damper, pickups and a guard.
#pragma once

#include <algorithm>
#include <array>
#include <memory>
#include <optional>
#include <span>
#include <utility>

#include "instruments/bridge.h"
#include "instruments/hammer.h"
#include "instruments/string_tuning.h"
#include "schemes/sav.h"
#include "voices/decimator.h"
#include "voices/modal_tail.h"
#include "voices/pickup.h"
#include "voices/voice_block.h"

namespace hamiltone {

// The sound: everything a preset sets for one string voice.
struct StringPatch {
  StringPhysics string;  // before tuning; the tuned quantity is replaced
  HammerFelt hammer;
  TuneBy tuneBy = TuneBy::tension;
  double a4Hz = 440.0;
  double detuneCents = 0.0;  // from the note's equal-tempered pitch (a unison string's offset)
  GridRule grid = GridRule::twoGrid;
  double gridFactor = 1.0;
  double tensionMargin = 1.5;  // two grids: u's grid sized for this multiple of T0 (SCHEMES §3b)
  int oversampling = 1;        // 1, 2, 4, 8, 16, 32 or 64
  // The linear tail: once the hammer is parked and the tension modulation's bound from the energy
  // (StringVoice::checkLinear) is under this, the string goes linear (V' dropped, its quadratic
  // part kept); back over twice this, or at a strike, it is geometric again. 0: never. Only where
  // v's grid resolves the longitudinal wave (the linear v must be stable).
  double linearBelow = 5e-5;
  // Gauge shift ε, J; none: kEpsilonShare of the hardest strike's energy ½ M_H v_max² where v's
  // grid resolves the longitudinal wave, 0 where it does not (docs/string-grids.md).
  std::optional<double> epsilon;
  double t60Low = 20.0;  // s, decay time at 0 Hz (infinite: no loss)
  double t60High = 4.0;  // s, decay time at t60HighHz
  double t60HighHz = 2000.0;
  // The longitudinal wave's own decay times at 0 Hz and at t60HighHz (StringLoss); none: v shares
  // the transverse law by wavenumber, as in the paper's (49). One alone: both take its value.
  std::optional<double> longitudinalT60Low, longitudinalT60High;
  double damperT60 = 0.25;  // s, the fundamental's T60 added once released (the felt's share)
  // false: the damper adds ln(1000)/damperT60 to σ0, every partial alike (releasedSigma0); true:
  // its felt, from damperPosition·L and damperWidth long, damps each by its shape there (D2).
  bool feltDamper = false;
  double damperPosition = 0.135;     // fraction of L
  double damperWidth = 0.02;         // m
  double pickups[2] = {0.31, 0.73};  // fractions of L
  int channels = 2;                  // 1: mono from pickups[0]; 2: one pickup per channel
  PickupSignal signal = PickupSignal::velocity;
  double gain = 0.25;  // output units per m/s (or per m)
  double velocityMin = 0.5, velocityMax = 6.0,
         velocityCurve = 1.0;        // m/s = min + (max−min)·v^curve
  double guardEnergyMultiple = 4.0;  // silence when H exceeds this multiple of the injected energy
  double bendRange = 2.0;  // semitones each way that setBend() reaches; 0 keeps the finest grid
};

// loss.damper_t60_s's largest value: the preset's "no damper" (the keys from F6 up).
constexpr double kNoDamperT60 = 1000.0;  // s
// linear_below's largest value: a relative tension change that puts the pitch off by at most
// 866 × it cents, 0.87.
constexpr double kMaxLinearBelow = 1e-3;
// The modal tail's floor: the highest modes of a linear string are dropped while together they hold
// under this share of its energy (−100 dB), checked every kLinearCheckSteps steps.
constexpr double kModalFloor = 1e-10;
// The linear tail's check, every this many steps.
constexpr long kLinearCheckSteps = 256;
// The floor under the live tail (the player under load): −80 dB, the dropped modes a part in 1e4 of
// the string's output under its own partials, where the alternative is dropping a whole key.
constexpr double kLiveModalFloor = 1e-8;
// The most a string is detuned from its note, cents: its unison spread and its bridge's load.
constexpr double kMaxDetuneCents = 50.0;

constexpr double kEpsilonShare = 0.1;
// On a grid that does not resolve the longitudinal wave, the largest ε as a share of that energy.
constexpr double kUnresolvedEpsilonShare = 0.01;
// ½ M_H v_max²: the energy the hardest strike gives the hammer, the voice's energy scale.
double strikeEnergyScale(const StringPatch& patch);

// σ(ξ) = σ0 + σ1 ξ is the decay rate of a mode of wavenumber² ξ; two T60s fix it
// (docs/instrument-data.md §3.4): σ0 = 6.908 / T60(0 Hz), σ1 = (6.908 / T60(f) − σ0) / ξ(f), ξ(ω)
// from c²ξ + κ²ξ² = ω². The longitudinal wave may have its own pair, fitted alike with its own ξ(ω)
// = ω² ρ/E (v's linear stiffness is EA: K's T0 and V''s EA − T0), so that at a given frequency
// the law is the same function of ω as RT-425's σ = R + η ω² (docs/instrument-data.md §3.1).
struct StringLoss {
  double sigma0 = 0.0;
  double sigma1 = 0.0;
  bool ownLongitudinal = false;  // false: v takes σ0 and σ1 too (BDZ (49))
  double longitudinalSigma0 = 0.0, longitudinalSigma1 = 0.0;
  // What v's law asks beyond the shared σ0 at 0 Hz: max(0, σ0_v − σ0).
  double longitudinalExcess() const { return std::max(0.0, longitudinalSigma0 - sigma0); }
};
StringLoss stringLossFromT60(const StringPhysics& string, double t60Low, double t60High,
                             double highHz);
// `loss` with v's own law from its two T60s (field names longitudinal_t60_low_s / _high_s).
StringLoss withLongitudinalLoss(StringLoss loss, const StringPhysics& string, double t60Low,
                                double t60High, double highHz);
// The scheme's σ1 and the string's loss weights (NonlinearString::LossWeights) that give u and v
// their laws. The scheme's σ0 is common to both waves, so v decays at least at the transverse σ0:
// its weight w_v0 carries max(0, σ0_v − σ0) / σ1. σ1 is the largest of σ1_u, σ1_v and that excess
// over the first mode's wavenumber² (π/L)²: any positive scale would do (the weights carry the
// laws); this one is zero only where there is no such loss at all, which lets the scheme skip it.
struct SchemeLoss {
  double sigma1 = 0.0;
  NonlinearString::LossWeights weights;
};
SchemeLoss schemeLoss(const StringLoss& loss, const StringPhysics& string);

class StringVoice {
 public:
  // May allocate; throws std::invalid_argument naming the patch field for an invalid patch.
  void prepare(const StringPatch& patch, int midiNote, double sampleRate);
  void reset() noexcept;  // the string at rest, the hammer parked, the damper up

  void noteOn(double velocity) noexcept;  // velocity 0 … 1
  // The key is down: the damper leaves the string, struck or not (una corda's missed string).
  void liftDamper() noexcept;
  // The damper falls, the fundamental's T60 damper_t60_s times `damperScale` added: uniform, every
  // partial alike (releasedSigma0); felt, its felt presses on the string along its width (dashpots
  // on the nodes under it, SavScheme::setPointDamper), each mode damped by its shape there — a
  // mode with a node near the felt less (D2). `contact` 0 … 1 scales the loss added (the
  // half-pedal; 0: lifted, the voice's own loss). May be called again at any time to move the
  // damper: the loss changes between two steps.
  void release(double damperScale = 1.0, double contact = 1.0) noexcept;
  // Bends the pitch by `semitones` (clamped to ±bendRange) by retensioning the transverse wave:
  // β T0 is solved in closed form so the scheme's fundamental moves by exactly that interval.
  void setBend(double semitones) noexcept;
  // The live tail (the player under load, Synth::setLiveTail): the linear tail taken from a
  // tension modulation of kMaxLinearBelow (the pitch then off by at most 0.87 cents) where the
  // preset sets less, so that decaying strings step the linear string sooner, in their modes at
  // a tenth to a fifth of the cost, and the modes' floor kLiveModalFloor where the string's is
  // lower (not 0: every mode kept stays so). A preset without the tail (linear_below 0) keeps
  // none. A string gone linear stays so when it ends (until struck, or over twice the threshold it
  // went linear at).
  void setLiveTail(bool on) noexcept { liveTail_ = on; }
  // The linear tail in the string's modes (modal_tail.h): on (the default), a linear string with no
  // felt damper on it steps its modes, the highest dropped while together they hold under `floor`
  // of its energy (0: none); off, it steps its nodes. The same linear string either way, to
  // roundoff and the dropped modes. Off leaves the modes at once.
  void setModalTail(bool on, double floor = kModalFloor) noexcept;
  bool inModes() const { return inModes_; }  // stepping its modes now
  const ModalTail& modalTail() const { return modal_; }
  // The live tail changes something: the string takes the linear tail, below kMaxLinearBelow, or
  // drops its modes under a floor lower than kLiveModalFloor (not 0).
  bool takesLiveTail() const {
    return linearisable_ && (patch_.linearBelow < kMaxLinearBelow ||
                             (modalTail_ && modalFloor_ > 0.0 && modalFloor_ < kLiveModalFloor));
  }
  // Where the voice counts as silent and frees itself (QuietDetector::setFloor): in its output
  // units, negative for never. The default, QuietDetector::kFloor, is −100 dB under unit output.
  void setQuietFloor(double floor) noexcept { quiet_.setFloor(floor); }

  // Writes (not adds) the next left.size() samples; a stereo patch also writes the first
  // min(left, right) samples of right, a mono one leaves right alone. Never allocates.
  void process(std::span<float> left, std::span<float> right) noexcept;

  // On a bridge (UnisonStrings): the key steps its strings and its bridge in turn, one scheme step
  // at a time. wake() sets a string that was not struck going from rest (una corda's missed
  // string, which the bridge excites); stepOnBridge() takes one step with the bridge at w — its
  // pull on the last two nodes — and pushes the pickups, returning true when `out` holds the next
  // output sample (gain applied); pullOnBridge() is the string's force on the bridge at q^n.
  void wake() noexcept;
  bool stepOnBridge(double w, double out[2]) noexcept {
    if (!steadyInModes()) return stepOnBridgeAndScheme(w, out);
    stepModesOnBridge(w, out);
    return true;
  }
  double pullOnBridge(double w) const noexcept {
    using enum ModalTail::Probe;
    return inModes_ ? coupling_.forceFromPull(modal_.at(kPull), w, modal_.residual())
                    : coupling_.forceOnBridge(scheme_->q(), w);
  }
  // The string's tension change at its bridge end at q^n, N (NonlinearString::endTension()).
  // That of the linear string where the last step was linear (the switch back comes after it).
  double endTension() const noexcept {
    const NonlinearString& s = scheme_->system().string();
    if (!steppedLinear_) return s.endTension();
    return inModes_ ? modal_.endTension() : s.linearEndTension(scheme_->q());
  }
  // The coupling's E_c^{n+½} (BridgeCoupling::energy) with the bridge at w^n, w^{n+1}.
  double couplingEnergy(double w, double wNext) const noexcept;
  const BridgeCoupling& coupling() const { return coupling_; }
  const StringPatch& patch() const { return patch_; }
  // The nodes of u (coordinates of q) under a felt damper; none with the uniform one or none.
  std::span<const Eigen::Index> feltNodes() const {
    return {feltNode_.data(), static_cast<size_t>(feltNodes_)};
  }

  bool active() const { return active_; }
  bool linear() const { return linear_; }  // in its linear tail (linearBelow, or the live tail's)
  double energy() const;                   // the scheme's H^{n+½} (ε excluded), J
  // By the strikes, the bend's retensioning and the linear tail's switches (what ψ held against
  // V''s quadratic part at rest, either sign).
  double injectedEnergy() const { return injected_; }
  // Taken out by the back-check (the hammer's kinetic energy and its ψ residual) and by the modal
  // tail's dropped modes. The string's losses are not tallied on the audio path; with them off,
  // energy() + removedEnergy() stays injectedEnergy().
  double removedEnergy() const { return caught_; }
  int guardEvents() const { return guardEvents_; }
  double fundamentalHz() const { return fundamental_; }
  int channels() const { return patch_.channels; }
  int segments() const;
  // The scheme; while the string steps its modes (inModes()), its levels are those it left.
  const SplitSav<HammeredString>& scheme() const { return *scheme_; }
  // q^n and q^{n+1} as the string steps them: the scheme's, or the modes written back. Allocates
  // (for tests and tools).
  std::pair<Vector, Vector> levels() const;

 private:
  // A pickup at a fraction of L: the two nodes of u around it and their linear weights, fixed
  // when the voice is prepared (the grid does not change with the bend).
  struct PickupTap {
    int node, next;
    double weight, nextWeight;
  };
  static PickupTap pickupTap(double position, int segments);
  double pickup(const Vector& q, const Vector& qNext, const PickupTap& tap) const;
  void catchHammer() noexcept;
  void applyBend() noexcept;
  bool stepAndPick(double out[2]) noexcept;  // one scheme step; true when a sample is out
  bool stepOnBridgeAndScheme(double w, double out[2]) noexcept;
  // In its modes with nothing to do first — no residual to count, no change of the modes due, the
  // hammer parked clear of the string, the pickups undecimated — a step on the bridge is the
  // modes' step and their pickups: stepModesOnBridge(), the operations of stepOnBridgeAndScheme()
  // and stepAndPick() that such a step takes, in their order, inline (the commonest step of a
  // pedalled texture). The scheme's point forces are left: only its own steps read them, and
  // stepOnBridgeAndScheme() sets them before each.
  bool steadyInModes() const noexcept {
    return inModes_ && residualLeft_ == 0.0 && modesDue_ == ModesDue::none &&
           decimators_[0].factor() == 1 && !hammerMeetsModes();
  }
  // The hammer parked below a string in its modes: should the string swing down onto it, the step
  // is the scheme's, with the felt's force, and the back-check meets the hammer as on the nodes.
  bool hammerMeetsModes() const noexcept {
    return scheme_->q()[scheme_->system().hammerIndex()] - modal_.atNext(ModalTail::kContact) > 0.0;
  }
  void stepModesOnBridge(double w, double out[2]) noexcept {
    bridgeBefore_ = bridgeAt_;
    bridgeAt_ = w;
    steppedLinear_ = linear_;
    modal_.step(w);
    ++stepsInModes_;
    for (int c = 0; c < patch_.channels; ++c)
      out[c] = modalPickup(c) + 0.0;  // Decimator::push at one tap
    if (linearisable_ && (scheme_->stepIndex() + stepsInModes_) % kLinearCheckSteps == 0)
      checkLinear();
    out[0] *= patch_.gain;
    out[1] *= patch_.gain;
  }
  // Pickup c's signal read from the modes' probes.
  double modalPickup(int c) const noexcept {
    const auto p = static_cast<ModalTail::Probe>(ModalTail::kPickup0 + c);
    return patch_.signal == PickupSignal::displacement ? modal_.at(p)
                                                       : (modal_.atNext(p) - modal_.at(p)) * rate_;
  }
  void changeModes() noexcept;  // the modes kept: dropped or restored, as modesDue_ says
  void checkLinear() noexcept;  // every kLinearCheckSteps steps
  void setLinear(bool on) noexcept;
  void releaseStretch() noexcept;
  void prepareModes();
  void retuneModes() noexcept;
  void enterModes() noexcept;  // where it may: linear, no felt on it, the hammer parked, tail on
  void leaveModes() noexcept;

  StringPatch patch_;
  std::unique_ptr<SplitSav<HammeredString>> scheme_;
  std::unique_ptr<SplitSav<HammeredString>> atRest_;  // the reset state, copied in reset()
  Decimator decimators_[2];
  PickupTap taps_[2] = {};
  QuietDetector quiet_;
  StringLoss loss_;
  BridgeCoupling coupling_;  // of the string as bent now
  // The felt's nodes (u's coordinates) and its resistance at each at full contact, kg/s (D2).
  std::array<Eigen::Index, SplitSav<HammeredString>::kPointDampers> feltNode_{};
  int feltNodes_ = 0;
  double feltR_ = 0.0;
  double sampleRate_ = 0.0, k_ = 0.0, fundamental_ = 0.0;
  double rate_ = 0.0;  // 1/k: the pickups' velocity, a product on every step, not a division
  double bend_ = 0.0, bendSlope_ = 0.0, bendOffset_ = 0.0;  // λ1(β) = bendSlope_·β + bendOffset_
  double injected_ = 0.0, caught_ = 0.0;
  int guardEvents_ = 0;
  int separatedSteps_ = 0;
  bool active_ = false, struck_ = false;
  bool parked_ = true;  // the back-check holds the hammer (until the next strike)
  bool linearisable_ = false, linear_ = false, steppedLinear_ = false;
  bool liveTail_ = false;
  double linearAt_ = 0.0;  // the threshold in effect when the string last went linear
  // The modal tail: the modes, whether they step, the energy the scheme holds beside them (the ψ
  // of its parts, the parked hammer), the steps taken since the scheme's own, and the two levels
  // the modes are written back into.
  ModalTail modal_;
  bool modalTail_ = true, inModes_ = false;
  double modalFloor_ = kModalFloor;
  double besideModes_ = 0.0;
  long stepsInModes_ = 0;  // since entering: the scheme's own steps and these count the checks
  Vector levelN_, levelNext_;
  Vector stretch_;  // v's quasi-static stretch at the switch to linear (releaseStretch)
  // The bridge's w of the last step and of the one before (stepOnBridge); 0 off a bridge: the
  // levels of the coupling's energy between two steps.
  double bridgeAt_ = 0.0, bridgeBefore_ = 0.0;
  double residualLeft_ = 0.0;  // the modes' residual when they were left, until the next step
  // A change of the modes kept, made at the start of the next step, where the bridge's two levels
  // are known, so that the coupling energy it changes is counted.
  enum class ModesDue { none, truncate, restore } modesDue_ = ModesDue::none;
};

}  // namespace hamiltone
