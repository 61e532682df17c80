// The string voice's setup (tuning, losses, grid), its strike, damper and hammer check, and the
// audio loop: R scheme steps per output sample, pickups, decimation, and the guard.
#include "voices/string_voice.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "instruments/piano_scale.h"
#include "util/format_number.h"
#include "voices/voice_block.h"

namespace hamiltone {

namespace {

constexpr double kLn1000 = 6.907755278982137;  // T60 = ln(1000) / σ
constexpr double kStrikeGap = 1e-4;            // m: the hammer starts 0.1 mm below the string
constexpr double kParkedAt = -0.02;            // m: where the back-check holds it
constexpr double kCheckDelay = 1e-3;           // s out of contact, moving away, before the catch
constexpr double kCheckGap = 1e-3;             // m below the string, at least, when caught

void require(bool ok, const char* field, double value, const std::string& valid) {
  if (!ok)
    throw std::invalid_argument(std::string(field) + " = " + formatNumber(value) + ": must be " +
                                valid);
}

// ξ with c² ξ + κ² ξ² = ω²: the wavenumber² of a partial of angular frequency ω.
double wavenumberSquared(const StringPhysics& p, double omega) {
  const double c2 = p.tension / p.linearDensity();
  const double kappa2 = p.young * p.inertia / p.linearDensity();
  if (kappa2 == 0.0) return omega * omega / c2;
  return (-c2 + std::sqrt(c2 * c2 + 4.0 * kappa2 * omega * omega)) / (2.0 * kappa2);
}

// The tension scale β that puts the scheme's fundamental on `hz` (the inverse of schemePartial).
double bendScale(const NonlinearString& s, double k, double hz) {
  const double root = 2.0 / k * std::sin(std::numbers::pi * k * hz);
  const double offset = s.transverseEigenvalue(1, 0.0);
  return (root * root - offset) / (s.transverseEigenvalue(1, 1.0) - offset);
}

}  // namespace

double strikeEnergyScale(const StringPatch& patch) {
  return 0.5 * patch.hammer.mass * patch.velocityMax * patch.velocityMax;
}

namespace {

// The gauge shift ε (docs/string-grids.md, "The gauge shift"). Where v's grid resolves the
// longitudinal wave (c_L k / h_v <= 1) any ε > 0 gives the converged glide, and ε = 0 does not
// (g is direction-dependent at rest: a first-mode start glides at 0.4 of the converged rate), so
// the default is a share of the hardest strike's energy. Where it does not (the transverse grid,
// c_L k / h ≈ 15, and the two grids' single cell on the top keys, shorter than c_L k), ψ drifts
// from sqrt(2 (V' + ε)) by an amount that grows with ε: the output turns into noise from about the
// strike's energy on, so ε is kept to a hundredth of it, 0 by default.
double gaugeShift(const StringPatch& patch, const NonlinearString& string, double k) {
  const StringPhysics& p = string.physics();
  const double cLk = std::sqrt(p.young / p.density) * k;
  const double courant = cLk / string.longitudinalSpacing();
  const double strike = strikeEnergyScale(patch);
  if (courant <= 1.0) {
    const double epsilon = patch.epsilon.value_or(kEpsilonShare * strike);
    require(std::isfinite(epsilon) && epsilon >= 0.0, "epsilon_j", epsilon,
            "a finite number >= 0 J");
    return epsilon;
  }
  const double epsilon = patch.epsilon.value_or(0.0);
  const double most = kUnresolvedEpsilonShare * strike;
  // A string shorter than c_L k (the top keys at 48 kHz) is unresolved on the two grids too: their
  // one coarse cell is the whole string, and the mean stretch of this Kirchhoff–Carrier limit moves
  // faster than a step, so ψ drifts as on the transverse grid (measured, C7–C8: ε = 1 J is noise).
  // Only a shorter step resolves it.
  const double shortness = cLk / p.length;
  std::string remedy = "grid_rule \"two-grid\" accepts any ε";
  if (shortness > 1.0) {
    int enough = patch.oversampling;
    while (enough < 64 && enough < patch.oversampling * shortness) enough *= 2;
    const bool two = string.grid().longitudinal < string.grid().transverse;  // Mv = 1 < Mu
    remedy = std::string("the string is shorter than c_L k, so ") +
             (two ? "the two grids' one coarse cell does not resolve it either; "
                  : "even the two grids' one coarse cell would not resolve it; ") +
             (enough >= patch.oversampling * shortness
                  ? std::string(two ? "" : "grid_rule \"two-grid\" at ") + "oversampling " +
                        std::to_string(enough) + " does, and accepts any ε"
                  : std::string("no oversampling up to 64 does"));
  }
  require(epsilon >= 0.0 && epsilon <= most, "epsilon_j", epsilon,
          "between 0 and " + formatApprox(most, 3) +
              " J on this grid: its longitudinal Courant number c_L k/h = " +
              formatApprox(courant, courant < 1.01 ? 6 : 3) +
              " exceeds 1, and a larger gauge shift lets ψ drift from sqrt(2(V'+ε)) until the "
              "output is noise (at most a hundredth of the hardest strike's energy ½ M_H v_max² "
              "= " +
              formatApprox(strike, 3) + " J; " + remedy + ")");
  return epsilon;
}

// The damper's felt on u's grid: the nodes under it (at least the nearest, at most kPointDampers
// spread evenly over it), and the resistance each needs for the fundamental to gain
// ln(1000)/damper_t60_s of decay rate:
//   r = σ ρA L / Σ_m sin²(π x_m/L)                                                     (D2)
struct Felt {
  std::array<Eigen::Index, SplitSav<HammeredString>::kPointDampers> nodes{};
  int count = 0;
  double resistance = 0.0;  // kg/s at each node, full contact
};

Felt feltUnder(const StringPatch& patch, const NonlinearString& string) {
  const int segments = string.segments();
  const double length = string.physics().length;
  auto node = [&](double x) {
    return std::clamp<Eigen::Index>(std::lround(x / length * segments) - 1, 0, segments - 2);
  };
  const Eigen::Index first = node(patch.damperPosition * length),
                     last = node(patch.damperPosition * length + patch.damperWidth);
  Felt felt;
  felt.count = static_cast<int>(
      std::min<Eigen::Index>(last - first + 1, static_cast<Eigen::Index>(felt.nodes.size())));
  double shape = 0.0;
  for (int m = 0; m < felt.count; ++m) {
    felt.nodes[m] = felt.count == 1 ? first : first + (last - first) * m / (felt.count - 1);
    shape += std::pow(std::sin(std::numbers::pi * (felt.nodes[m] + 1) / segments), 2);
  }
  felt.resistance = kLn1000 / patch.damperT60 * string.physics().linearDensity() * length / shape;
  return felt;
}

// The σ1 that sizes a single grid (transverse, longitudinal rules), where v shares u's spacing h.
// v's block of (44) asks h² >= H = c²k² + 4 (σ1_v + Δσ0 H/4) k (K holds T0 on v, Δσ0 the law's
// σ0 above the shared one: schemeLoss), i.e. H = (c²k² + 4σ1_v k)/(1 − Δσ0 k); u's asks
// h² >= (a + sqrt(a² + 16κ²k²))/2, a = c²k² + 4σ1 k (minimalSpacing), which reaches H at σ1 =
// (H − 4κ²k²/H − c²k²)/(4k). Stiffness makes u's the larger on the bundled strings, so the grid
// changes only where v's law binds (no stiffness, or a law of milliseconds). The two grids put v on
// its own coarse grid, which the voice then checks.
double gridSigma1(const StringLoss& loss, const StringPhysics& string, GridRule rule, double k) {
  if (!loss.ownLongitudinal || rule == GridRule::twoGrid) return loss.sigma1;
  const double excess = loss.longitudinalExcess();
  const double c2k2 = string.tension / string.linearDensity() * k * k;
  const double kappa2k2 = string.young * string.inertia / string.linearDensity() * k * k;
  const double h2 = (c2k2 + 4.0 * loss.longitudinalSigma1 * k) / std::max(1.0 - excess * k, 1e-3);
  return std::max(loss.sigma1, (h2 - 4.0 * kappa2k2 / h2 - c2k2) / (4.0 * k));
}

// x rounded up to four significant digits: a bound that, as printed, is itself valid.
double roundedUp(double x) {
  const double unit = std::pow(10.0, std::floor(std::log10(x)) - 3.0);
  return std::ceil(x / unit) * unit;
}

}  // namespace

StringLoss stringLossFromT60(const StringPhysics& string, double t60Low, double t60High,
                             double highHz) {
  require(t60Low > 0.0, "t60_low_s", t60Low, "> 0 seconds (inf for no loss)");
  require(
      t60High > 0.0 && t60High <= t60Low, "t60_high_s", t60High,
      "> 0 and at most t60_low_s = " + formatNumber(t60Low) + " (higher partials decay faster)");
  require(std::isfinite(highHz) && highHz > 0.0, "t60_high_hz", highHz, "a frequency > 0 Hz");
  StringLoss loss;
  loss.sigma0 = std::isfinite(t60Low) ? kLn1000 / t60Low : 0.0;
  const double high = std::isfinite(t60High) ? kLn1000 / t60High : 0.0;
  loss.sigma1 = (high - loss.sigma0) / wavenumberSquared(string, 2.0 * std::numbers::pi * highHz);
  return loss;
}

StringLoss withLongitudinalLoss(StringLoss loss, const StringPhysics& string, double t60Low,
                                double t60High, double highHz) {
  require(t60Low > 0.0, "longitudinal_t60_low_s", t60Low, "> 0 seconds (inf for no loss)");
  require(t60High > 0.0 && t60High <= t60Low, "longitudinal_t60_high_s", t60High,
          "> 0 and at most longitudinal_t60_low_s = " + formatNumber(t60Low) +
              " (higher longitudinal modes decay faster)");
  const double omega = 2.0 * std::numbers::pi * highHz;
  loss.ownLongitudinal = true;
  loss.longitudinalSigma0 = std::isfinite(t60Low) ? kLn1000 / t60Low : 0.0;
  // v decays at least at the shared σ0 (schemeLoss), so σ1_v is fitted from the larger of the
  // two: the T60 at highHz then holds wherever it is shorter than 6.908 / σ0.
  const double floor = std::max(loss.sigma0, loss.longitudinalSigma0);
  const double high = std::isfinite(t60High) ? kLn1000 / t60High : 0.0;
  loss.longitudinalSigma1 =
      std::max(0.0, high - floor) / (omega * omega * string.density / string.young);
  return loss;
}

SchemeLoss schemeLoss(const StringLoss& loss, const StringPhysics& string) {
  if (!loss.ownLongitudinal) return {.sigma1 = loss.sigma1, .weights = {}};
  const double excess = loss.longitudinalExcess();
  const double firstMode = std::pow(string.length / std::numbers::pi, 2);  // 1 / (π/L)²
  const double scale = std::max({loss.sigma1, loss.longitudinalSigma1, excess * firstMode});
  if (scale == 0.0) return {.sigma1 = 0.0, .weights = {}};
  return {.sigma1 = scale,
          .weights = {.transverse = loss.sigma1 / scale,
                      .longitudinalConstant = excess / scale,
                      .longitudinal = loss.longitudinalSigma1 / scale}};
}

void StringVoice::prepare(const StringPatch& patch, int midiNote, double sampleRate) {
  const int r = patch.oversampling;
  require(r == 1 || r == 2 || r == 4 || r == 8 || r == 16 || r == 32 || r == 64, "oversampling", r,
          "1, 2, 4, 8, 16, 32 or 64");
  require(std::isfinite(sampleRate) && sampleRate >= 8000.0 && sampleRate <= 384000.0,
          "sample rate", sampleRate, "between 8000 and 384000 Hz");
  require(std::isfinite(patch.a4Hz) && patch.a4Hz >= 400.0 && patch.a4Hz <= 480.0, "a4_hz",
          patch.a4Hz, "between 400 and 480 Hz");
  require(std::isfinite(patch.damperT60) && patch.damperT60 > 0.0, "damper_t60_s", patch.damperT60,
          "a finite time > 0 seconds");
  for (double p : patch.pickups)
    require(p > 0.0 && p < 1.0, "pickup_position", p, "a fraction of the length in (0, 1)");
  require(patch.channels == 1 || patch.channels == 2, "channels", patch.channels, "1 or 2");
  require(std::isfinite(patch.gain), "gain", patch.gain, "a finite number");
  require(patch.velocityMin >= 0.0 && patch.velocityMax >= patch.velocityMin &&
              patch.velocityMax <= 20.0,
          "hammer_velocity_max_m_s", patch.velocityMax,
          "at least hammer_velocity_min_m_s and at most 20 m/s");
  require(std::isfinite(patch.velocityCurve) && patch.velocityCurve > 0.0, "velocity_curve",
          patch.velocityCurve, "a number > 0");
  require(patch.guardEnergyMultiple > 1.0, "guard_energy_multiple", patch.guardEnergyMultiple,
          "a number > 1");
  require(patch.bendRange >= 0.0 && patch.bendRange <= 12.0, "bend_range_semitones",
          patch.bendRange, "between 0 and 12 semitones");

  // Everything is built in locals and committed only once nothing more can throw, so a failed
  // prepare() leaves the voice as it was.
  const double k = 1.0 / (sampleRate * r);
  require(std::isfinite(patch.detuneCents) && std::abs(patch.detuneCents) <= kMaxDetuneCents,
          "detune_cents", patch.detuneCents, "between −50 and 50 cents");
  const double target =
      equalTemperament(midiNote, patch.a4Hz) * std::pow(2.0, patch.detuneCents / 1200.0);
  // Oversampling runs the string faster, but the output cannot carry a fundamental above its own
  // Nyquist frequency: the decimator would fold it back, a wrong pitch (C8 at 8 kHz ×4: 3814 Hz).
  if (!(target < 0.5 * sampleRate))
    throw std::invalid_argument("target pitch = " + formatApprox(target, 6) +
                                " Hz: must be below the output's Nyquist frequency " +
                                formatApprox(0.5 * sampleRate, 6) +
                                " Hz (a higher sample rate plays it; oversampling does not)");
  // The loss sets the grid (its σ1 tightens (44)) and the tuning sets the loss (ξ depends on T0):
  // two rounds settle both, σ1 being a small correction. The grid leaves room for the bend's
  // largest tension β: on the single grids h_min grows at most as sqrt(β) (minimalSpacing), so a
  // coarser factor covers it; the two grids size u's grid for the tension max(β, margin) T0. β
  // itself depends on the grid through the stiffness term, hence a third round if needed.
  require(std::isfinite(patch.tensionMargin) && patch.tensionMargin >= 1.0 &&
              patch.tensionMargin <= 4.0,
          "tension_margin", patch.tensionMargin, "between 1 and 4 (times the tension)");
  const double widest = std::pow(2.0, 2.0 * patch.bendRange / 12.0);
  double betaMax = widest;
  TunedString tuned{patch.string, {}};
  // v's own law, if any: one time set alone stands for both.
  const bool ownLaw = patch.longitudinalT60Low || patch.longitudinalT60High;
  const double lawLow =
      ownLaw ? patch.longitudinalT60Low.value_or(*patch.longitudinalT60High) : 0.0;
  const double lawHigh = ownLaw ? patch.longitudinalT60High.value_or(lawLow) : 0.0;
  StringLoss transverse, loss;  // u's law alone, and with v's
  StringPhysics lossPhysics;    // what they were fitted on: the round's string before its tuning
  for (int round = 0; round < 3; ++round) {
    lossPhysics = tuned.physics;
    transverse = stringLossFromT60(lossPhysics, patch.t60Low, patch.t60High, patch.t60HighHz);
    loss = ownLaw ? withLongitudinalLoss(transverse, lossPhysics, lawLow, lawHigh, patch.t60HighHz)
                  : transverse;
    const bool two = patch.grid == GridRule::twoGrid;
    tuned = tuneString(patch.string, patch.tuneBy, patch.grid, k,
                       gridSigma1(loss, lossPhysics, patch.grid, k),
                       patch.gridFactor * (two ? 1.0 : std::sqrt(betaMax)), target,
                       two ? std::max(betaMax, patch.tensionMargin) : 1.0);
    const NonlinearString s(tuned.physics, tuned.grid);
    const double need = bendScale(s, k, target * std::pow(2.0, patch.bendRange / 12.0));
    if (round > 0 && need <= betaMax) break;
    betaMax = std::max(widest, need);
  }
  require(patch.feltDamper || (loss.sigma0 + kLn1000 / patch.damperT60) * k < 1.0, "damper_t60_s",
          patch.damperT60,
          "longer than ln(1000) k / (1 − σ0 k) = " +
              formatNumber(kLn1000 * k / (1.0 - loss.sigma0 * k)) + " s at this rate");
  require(patch.damperPosition > 0.0 && patch.damperPosition < 1.0, "damper_position",
          patch.damperPosition, "a fraction of the length in (0, 1)");
  require(patch.damperWidth >= 0.0 && patch.damperWidth <= 0.1, "damper_width_m", patch.damperWidth,
          "between 0 and 0.1 m");
  NonlinearString string(tuned.physics, tuned.grid);
  const Felt felt = feltUnder(patch, string);
  // The uniform damper has no felt, nor a key without a damper (kNoDamperT60).
  const bool hasFelt = patch.feltDamper && patch.damperT60 < kNoDamperT60;
  const double epsilon = gaugeShift(patch, string, k);
  string.setTensionRange(betaMax);
  // On the two grids, v's own law must keep the bound (44) on v's coarse grid too, which decay
  // times of milliseconds break. The refusal names the field the patch set (one set stands for
  // both) and the shortest stable time, found by bisection on the decay rate.
  const SchemeLoss schemeSide = schemeLoss(loss, lossPhysics);
  if (ownLaw) {
    const char* lowField =
        patch.longitudinalT60Low ? "longitudinal_t60_low_s" : "longitudinal_t60_high_s";
    const char* highField =
        patch.longitudinalT60High ? "longitudinal_t60_high_s" : "longitudinal_t60_low_s";
    auto t60 = [](double rate) { return rate > 0.0 ? kLn1000 / rate : INFINITY; };
    auto stable = [&](double lowRate, double highRate) {
      const SchemeLoss side = schemeLoss(withLongitudinalLoss(transverse, lossPhysics, t60(lowRate),
                                                              t60(highRate), patch.t60HighHz),
                                         lossPhysics);
      string.setLossWeights(side.weights);
      return k <= string.maxStableStep(side.sigma1);
    };
    // The largest stable rate between `from` (stable) and `to` (not), as a time rounded up.
    auto shortest = [&](double from, double to, auto stableAt) {
      for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (from + to);
        (stableAt(mid) ? from : to) = mid;
      }
      return formatApprox(roundedUp(t60(from)), 5);
    };
    const double lowRate = kLn1000 / lawLow, highRate = kLn1000 / lawHigh;
    const std::string why =
        " s at this rate: shorter, v's modes would decay faster than the explicit loss is stable "
        "for on its coarse grid (the bound (44))";
    // One time set alone stands for both, so each is the named field's value.
    if (!stable(lowRate, lowRate))
      require(false, lowField, lawLow,
              "at least " + shortest(0.0, lowRate, [&](double x) { return stable(x, x); }) + why);
    if (!stable(lowRate, highRate))
      require(false, highField, lawHigh, "at least " + shortest(lowRate, highRate, [&](double x) {
                                           return stable(lowRate, x);
                                         }) + why);
  }
  string.setLossWeights(schemeSide.weights);
  require(std::isfinite(patch.linearBelow) && patch.linearBelow >= 0.0 &&
              patch.linearBelow <= kMaxLinearBelow,
          "linear_below", patch.linearBelow,
          "between 0 (never linear) and 1e-3 (a relative tension change; the pitch is then off by "
          "at most 866 × it cents)");
  const bool linearisable =
      patch.linearBelow > 0.0 && k <= string.linearisedMaxStableStep(schemeSide.sigma1);
  const HammeredString system(std::move(string), patch.hammer);
  InitialState rest{Vector::Zero(system.size()), Vector::Zero(system.size())};
  rest.q[system.hammerIndex()] = kParkedAt;
  const StepParameters params{.k = k,
                              .sigma0 = loss.sigma0,
                              .sigma1 = schemeSide.sigma1,
                              .epsilon = epsilon,
                              .trackDissipation = false};
  auto scheme = std::make_unique<SplitSav<HammeredString>>(system, params, rest);
  auto atRest = std::make_unique<SplitSav<HammeredString>>(*scheme);
  Decimator decimators[2];
  for (Decimator& d : decimators) d.prepare(r);

  patch_ = patch;
  sampleRate_ = sampleRate;
  k_ = k;
  rate_ = 1.0 / k;
  feltNode_ = felt.nodes;
  feltNodes_ = hasFelt ? felt.count : 0;
  feltR_ = felt.resistance;
  loss_ = loss;
  fundamental_ = schemePartial(system.string(), k, 1);
  bendOffset_ = system.string().transverseEigenvalue(1, 0.0);
  bendSlope_ = system.string().transverseEigenvalue(1, 1.0) - bendOffset_;
  bend_ = 0.0;
  linearisable_ = linearisable;
  scheme_ = std::move(scheme);
  atRest_ = std::move(atRest);
  for (int c = 0; c < 2; ++c) {
    decimators_[c] = std::move(decimators[c]);
    taps_[c] = pickupTap(patch.pickups[c], segments());
  }
  prepareModes();
  quiet_.prepare(sampleRate);
  reset();
}

// The modal tail's probes, each by its weights on u's nodes: the pickups' taps and the hammer's
// contact (HammeredString::contactDisplacement, taken node by node); and the bridge's two nodes.
void StringVoice::prepareModes() {
  const HammeredString& system = scheme_->system();
  const Eigen::Index nu = system.string().transverseSize();
  std::array<std::vector<double>, ModalTail::kProbes> probes;
  for (std::vector<double>& p : probes) p.assign(nu, 0.0);
  for (int c = 0; c < 2; ++c) {
    probes[ModalTail::kPickup0 + c][taps_[c].node] += taps_[c].weight;
    probes[ModalTail::kPickup0 + c][taps_[c].next] += taps_[c].nextWeight;
  }
  const BridgeCoupling coupling(system.string());
  Vector unit = Vector::Zero(system.size());
  for (Eigen::Index j = 0; j < nu; ++j) {
    unit[j] = 1.0;
    probes[ModalTail::kContact][j] = system.contactDisplacement(unit);
    unit[j] = 0.0;
  }
  modal_.prepare(system.string(), k_, probes, coupling.lastIndex(), coupling.secondIndex());
  levelN_.setZero(system.size());
  levelNext_.setZero(system.size());
  stretch_.setZero(std::max(system.string().grid().longitudinal - 1, 0));
}

void StringVoice::reset() noexcept {
  *scheme_ = *atRest_;  // same sizes: copies without allocating
  for (Decimator& d : decimators_) d.reset();
  injected_ = caught_ = 0.0;
  separatedSteps_ = 0;
  quiet_.reset();
  active_ = struck_ = linear_ = steppedLinear_ = inModes_ = false;  // the copy is geometric
  parked_ = true;
  stepsInModes_ = 0;
  bridgeAt_ = bridgeBefore_ = residualLeft_ = 0.0;
  modesDue_ = ModesDue::none;
  applyBend();  // the copy brought back β = 1
}

void StringVoice::setBend(double semitones) noexcept {
  // A NaN passes through std::clamp, so it is caught first.
  const double bend =
      std::isnan(semitones) ? 0.0 : std::clamp(semitones, -patch_.bendRange, patch_.bendRange);
  // The synth sets the wheel's bend at every strike: unchanged, the tension, the coupling and the
  // modes' recursions are what applyBend would compute again (a third of a strike's work on a
  // string in its modes, with a sine per mode).
  if (bend == bend_) return;
  bend_ = bend;
  applyBend();
}

// f1 = (1/πk) arcsin(k sqrt(λ1)/2) (schemePartial) with λ1 = β·bendSlope_ + bendOffset_: the β
// that puts f1 at fundamental·2^(bend/12). Retensioning a moving string does work on it (½ q K q
// changes with β): it is counted with what the strikes put in, so the guard, which compares the
// energy with that, sees only a real instability however fast the wheel moves.
void StringVoice::applyBend() noexcept {
  const double f = fundamental_ * std::pow(2.0, bend_ / 12.0);
  const double root = 2.0 / k_ * std::sin(std::numbers::pi * k_ * f);
  const double before = energy();
  scheme_->system().string().setTensionScale((root * root - bendOffset_) / bendSlope_);
  scheme_->stiffnessChanged();
  coupling_ = BridgeCoupling(scheme_->system().string());
  modal_.setPull(coupling_.lastWeight(), coupling_.secondWeight());
  if (inModes_) retuneModes();
  injected_ += energy() - before;
}

int StringVoice::segments() const { return scheme_->system().string().segments(); }

double StringVoice::energy() const {
  return inModes_ ? modal_.energy() + besideModes_ : scheme_->energy().total();
}

double StringVoice::couplingEnergy(double w, double wNext) const noexcept {
  if (!inModes_) return coupling_.energy(scheme_->q(), scheme_->qNext(), w, wNext);
  using enum ModalTail::Probe;
  return coupling_.energy(modal_.at(kPull), modal_.atNext(kPull), w, wNext, modal_.residual());
}

void StringVoice::noteOn(double velocity) noexcept {
  // A freed voice starts from rest: what a decayed string keeps on the transverse grid (a static
  // longitudinal stretch the SAV can leave, see docs/string-grids.md) would detune the next note.
  if (!active_) reset();
  if (linear_)
    setLinear(false);  // the strike's tension modulation, from its first step (and nodes)
  const double v = velocity >= 0.0 ? std::min(velocity, 1.0) : 0.0;  // NaN too
  const double speed = patch_.velocityMin + (patch_.velocityMax - patch_.velocityMin) *
                                                std::pow(v, patch_.velocityCurve);
  const HammeredString& system = scheme_->system();
  const Eigen::Index w = system.hammerIndex();
  const double before = energy();
  // Out of contact, the hammer is placed below the string — far enough that its first step,
  // speed·k, does not reach the felt — and launched; in contact (a very fast repeat) it is only
  // given the new speed where it is. Either way ψ of the felt is set to match Φ there.
  const double gap = std::max(kStrikeGap, 2.0 * speed * k_);
  const double start = system.compression(scheme_->q()) > 0.0
                           ? scheme_->q()[w]
                           : system.contactDisplacement(scheme_->q()) - gap;
  scheme_->setCoordinate(w, start, start + speed * k_);
  scheme_->resetPsi(1);
  injected_ += energy() - before;
  liftDamper();
  separatedSteps_ = 0;
  struck_ = parked_ = false;
  quiet_.strike();
  active_ = true;
}

void StringVoice::liftDamper() noexcept {
  scheme_->setSigma0(loss_.sigma0);
  for (int m = 0; m < feltNodes_; ++m) scheme_->setPointDamper(m, feltNode_[m], 0.0);
  if (inModes_) retuneModes();
}

void StringVoice::wake() noexcept {
  if (active_) {
    // The key's other strings struck: the bridge may wake the modes this string dropped.
    if (inModes_) modesDue_ = ModesDue::restore;
    return;
  }
  reset();
  quiet_.strike();
  active_ = true;
}

bool StringVoice::stepOnBridgeAndScheme(double w, double out[2]) noexcept {
  if (residualLeft_ != 0.0) {  // modes left since the last step (leaveModes)
    injected_ += 0.5 * residualLeft_ * bridgeAt_ * w;
    residualLeft_ = 0.0;
  }
  bridgeBefore_ = bridgeAt_;
  bridgeAt_ = w;
  scheme_->setPointForce(0, coupling_.lastIndex(), coupling_.forceOnLast(w));
  scheme_->setPointForce(1, coupling_.secondIndex(), coupling_.forceOnSecond(w));
  if (!stepAndPick(out)) return false;
  out[0] *= patch_.gain;
  out[1] *= patch_.gain;
  return true;
}

void StringVoice::release(double damperScale, double contact) noexcept {
  if (!patch_.feltDamper) {
    scheme_->setSigma0(releasedSigma0(loss_.sigma0, patch_.damperT60, damperScale, k_, contact));
    if (inModes_) retuneModes();
    return;
  }
  // A NaN contact is the full damper, as releasedSigma0 takes it; r ∝ 1/T60 (D2).
  const double c = contact < 1.0 ? std::max(contact, 0.0) : 1.0;
  const double scale = damperScale > 0.0 ? damperScale : 1.0;
  if (c > 0.0 && feltNodes_ > 0 && inModes_) leaveModes();  // dashpots on nodes: not modal
  for (int m = 0; m < feltNodes_; ++m) scheme_->setPointDamper(m, feltNode_[m], c * feltR_ / scale);
}

// The back-check: once the hammer has struck and left the string (escapement: no force drives
// it back), it is caught and parked out of reach. Its kinetic energy leaves the system, and so
// does what the felt's ψ kept of the strike (its SAV residual); both are counted.
void StringVoice::catchHammer() noexcept {
  const HammeredString& system = scheme_->system();
  const Eigen::Index w = system.hammerIndex();
  // Parked, the hammer stays there until the next strike or until the string itself swings down
  // onto it: a flag, not q[w] == kParkedAt, since the loss's (1 + σ0k)/(1 + σ0k) can move it by
  // an ulp, which made the check catch it again every millisecond (two energy evaluations each
  // time: 9 % of a grand-piano key's cost).
  const Vector& q = scheme_->q();
  const bool contact = system.compression(q) > 0.0;
  if (parked_ && !contact) return;
  if (contact) {
    parked_ = false;
    struck_ = true;
    separatedSteps_ = 0;
    return;
  }
  // Falling away, clear of the string by a millimetre, and for a millisecond: a string wave
  // coming back can still meet a hammer that lingers near it.
  const bool away = scheme_->qNext()[w] < q[w] && system.compression(q) < -kCheckGap;
  if (!struck_ || !away) {
    separatedSteps_ = 0;
    return;
  }
  if (++separatedSteps_ * k_ < kCheckDelay) return;
  const double before = energy();
  scheme_->setCoordinate(w, kParkedAt, kParkedAt);
  scheme_->resetPsi(1);
  caught_ += before - energy();
  parked_ = true;
}

StringVoice::PickupTap StringVoice::pickupTap(double position, int m) {
  const double s = std::clamp(position * m - 1.0, 0.0, m - 2.0);  // grid index, x = (j + 1) h
  const int j = std::min(static_cast<int>(s), m - 2);
  const double f = s - j;
  return {j, std::min(j + 1, m - 2), 1.0 - f, f};
}

double StringVoice::pickup(const Vector& q, const Vector& qNext, const PickupTap& tap) const {
  auto at = [&](const Vector& x) {
    return tap.weight * x[tap.node] + tap.nextWeight * x[tap.next];
  };
  if (patch_.signal == PickupSignal::displacement) return at(q);
  return (at(qNext) - at(q)) * rate_;
}

// The linear tail. The tension modulation, ΔT = (EA/2) Z̄ with Z̄ = (1/L) ∫ u_x² the mean square
// slope, raises the pitch by its mean over a period, ⟨ΔT⟩/βT0 of the bent tension. That mean is
// bounded by the energy: over whole periods a vibrating string holds half of H as potential energy
// (the virial theorem: ⟨kinetic⟩ = ⟨potential⟩), of which the tension's ½ βT0 L ⟨Z̄⟩ is a part
// (bending, v and the hammer parked at rest hold the rest, >= 0), so ⟨ΔT⟩/βT0 <=
// EA H / (2 β² T0² L); at an instant ΔT reaches twice that. Once the hammer is parked and that
// bound has fallen under linearBelow (kMaxLinearBelow, if larger, under the live tail), V' is
// dropped for its quadratic part at rest (NonlinearString::setLinearised), and a step is
// Störmer–Verlet on the linear string, one pass; over twice the threshold it went linear at (energy
// the bridge brings from a sibling string, or a bend down) it is geometric again. Each switch
// changes the energy by what ψ held less the quadratic part, counted with what the strikes put
// in. Checked at fixed step counts, so the output does not depend on the block size. A linear
// string with no felt damper on it then steps its modes, the highest of them dropped as they fall
// under kModalFloor of its energy (kLiveModalFloor under the live tail; what they held counted as
// removed) at the next step's start.
void StringVoice::checkLinear() noexcept {
  const NonlinearString& string = scheme_->system().string();
  const StringPhysics& p = string.physics();
  const double beta = string.tensionScale();
  const double modulation =
      p.young * p.area * energy() / (2.0 * beta * beta * p.tension * p.tension * p.length);
  const double below =
      liveTail_ ? std::max(patch_.linearBelow, kMaxLinearBelow) : patch_.linearBelow;
  if (!linear_ && parked_ && modulation < below) {
    setLinear(true);
    linearAt_ = below;
  } else if (linear_ && modulation > 2.0 * linearAt_) {
    setLinear(false);
  }
  if (linear_ && !inModes_) enterModes();
  if (inModes_) modesDue_ = ModesDue::truncate;
}

void StringVoice::setLinear(bool on) noexcept {
  if (!on && inModes_) leaveModes();
  const double before = energy();
  if (on) releaseStretch();
  scheme_->system().string().setLinearised(on);
  if (on)
    scheme_->dropPart(0);
  else
    scheme_->restorePart(0);
  scheme_->stiffnessChanged();
  injected_ += energy() - before;
  linear_ = on;
}

// Going linear, v lets go of the stretch u's slopes held in it (quasiStaticStretch): the linear
// string's u and v are apart, so that stretch would ring at v's own modes and pull the bridge at
// them; the geometric string's follows u down. Each level's own, so that v lets go of the
// stretch's motion too; the energy it takes is counted with the switch's.
void StringVoice::releaseStretch() noexcept {
  const NonlinearString& string = scheme_->system().string();
  const Eigen::Index nu = string.transverseSize(), nv = string.grid().longitudinal - 1;
  if (nv < 1) return;
  levelN_ = scheme_->q();
  levelNext_ = scheme_->qNext();
  for (Vector* level : {&levelN_, &levelNext_}) {
    string.quasiStaticStretch(*level, stretch_.data());
    level->segment(nu, nv) -= stretch_;
  }
  scheme_->setLevels(levelN_, levelNext_, 0);
}

void StringVoice::setModalTail(bool on, double floor) noexcept {
  modalTail_ = on;
  modalFloor_ = floor;
  if (!on && inModes_) leaveModes();
}

// The modes' recursions for the string and σ0 as they are now (after a bend or a damper's move).
void StringVoice::retuneModes() noexcept {
  const StepParameters& p = scheme_->parameters();
  modal_.setCoefficients(scheme_->system().string(), p.sigma0, p.sigma1);
}

// The scheme's ψ and its parked hammer stay as they are while the modes step: what they hold of
// the energy is kept beside the modes' (with the transform's roundoff), so energy() goes on.
void StringVoice::enterModes() noexcept {
  if (!modalTail_ || !linear_ || !parked_ || scheme_->damped()) return;
  const double before = energy();
  retuneModes();
  modal_.enter(scheme_->q(), scheme_->qNext());  // every mode kept: the coupling as on the nodes
  besideModes_ = before - modal_.energy();
  stepsInModes_ = 0;
  inModes_ = true;
}

// The modes dropped come back at rest, and with them the coupling's full self-stiffness: the
// coupling energy gains ½ residual w^n w^{n+1}, counted as injected at the next step's start, where
// the bridge's w^{n+1} is known (stepOnBridgeAndScheme), or at once where the step is starting.
void StringVoice::leaveModes() noexcept {
  const double before = energy();
  levelN_ = scheme_->q();  // the same size: no allocation
  levelNext_ = scheme_->qNext();
  modal_.leave(levelN_, levelNext_);
  scheme_->setLevels(levelN_, levelNext_, stepsInModes_);
  inModes_ = false;
  stepsInModes_ = 0;  // the scheme counts them now
  modesDue_ = ModesDue::none;
  injected_ += energy() - before;
  residualLeft_ += modal_.residual();
}

void StringVoice::changeModes() noexcept {
  const double before = couplingEnergy(bridgeBefore_, bridgeAt_);
  if (modesDue_ == ModesDue::truncate)
    caught_ += modal_.truncate(
        liveTail_ && modalFloor_ > 0.0 ? std::max(modalFloor_, kLiveModalFloor) : modalFloor_);
  else
    modal_.restore();
  injected_ += couplingEnergy(bridgeBefore_, bridgeAt_) - before;
  modesDue_ = ModesDue::none;
}

bool StringVoice::stepAndPick(double out[2]) noexcept {
  steppedLinear_ = linear_;
  if (inModes_) {
    if (modesDue_ != ModesDue::none) changeModes();
    if (hammerMeetsModes()) {
      leaveModes();
      injected_ += 0.5 * residualLeft_ * bridgeBefore_ * bridgeAt_;
      residualLeft_ = 0.0;
    }
  }
  if (inModes_) {
    modal_.step(bridgeAt_);
    ++stepsInModes_;
  } else {
    scheme_->step();
    catchHammer();
  }
  bool ready = false;
  for (int c = 0; c < patch_.channels; ++c) {
    const double value =
        inModes_ ? modalPickup(c) : pickup(scheme_->q(), scheme_->qNext(), taps_[c]);
    ready = decimators_[c].push(value, out[c]);
  }
  // After the pickups: the check changes what steps next, not this step's output.
  if (linearisable_ && (scheme_->stepIndex() + stepsInModes_) % kLinearCheckSteps == 0)
    checkLinear();
  return ready;
}

std::pair<Vector, Vector> StringVoice::levels() const {
  std::pair<Vector, Vector> x(scheme_->q(), scheme_->qNext());
  if (inModes_) modal_.leave(x.first, x.second);
  return x;
}

void StringVoice::process(std::span<float> left, std::span<float> right) noexcept {
  // Stereo writes the right channel too, over as many samples as it has; a mono patch leaves it.
  const bool stereo = patch_.channels == 2 && !right.empty();
  const size_t rightCount = stereo ? std::min(left.size(), right.size()) : 0;
  if (!active_) {
    silence(left, right, rightCount);
    return;
  }
  bool finite = true;
  for (size_t i = 0; i < left.size(); ++i) {
    double out[2] = {0.0, 0.0};
    while (!stepAndPick(out)) {
    }
    left[i] = static_cast<float>(patch_.gain * out[0]);
    finite = finite && std::isfinite(left[i]);
    if (i < rightCount) {
      right[i] = static_cast<float>(patch_.gain * out[1]);
      finite = finite && std::isfinite(right[i]);
    }
  }
  // The guard: a non-finite sample or runaway energy never leaves the voice.
  const double h = energy();
  if (!finite || !std::isfinite(h) || h > patch_.guardEnergyMultiple * injected_) {
    silence(left, right, rightCount);
    ++guardEvents_;
    reset();
    return;
  }
  if (quiet_.update(left, right, rightCount)) active_ = false;
}

}  // namespace hamiltone
