// The plate voice's setup (size from the note, grid, losses, strike spread), the force pulse, and
// the audio loop: R steps per output sample, two pickups, decimation, the guard.
#include "voices/plate_voice.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "util/format_number.h"
#include "voices/voice_block.h"

namespace hamiltone {

namespace {

constexpr double kLn1000 = 6.907755278982137;  // T60 = ln(1000) / σ
constexpr int kMaxPoints = 120;                // per side, allocation-free (see prepare)

void require(bool ok, const char* field, double value, const std::string& valid) {
  if (!ok)
    throw std::invalid_argument(std::string(field) + " = " + formatNumber(value) + ": must be " +
                                valid);
}

}  // namespace

PlateLoss plateLossFromT60(const PlatePhysics& plate, double t60Low, double t60High,
                           double highHz) {
  require(t60Low > 0.0, "t60_low_s", t60Low, "> 0 seconds (inf for no loss)");
  require(t60High > 0.0 && t60High <= t60Low, "t60_high_s", t60High,
          "> 0 and at most t60_low_s = " + formatNumber(t60Low));
  require(std::isfinite(highHz) && highHz > 0.0, "t60_high_hz", highHz, "a frequency > 0 Hz");
  PlateLoss loss;
  loss.sigma0 = std::isfinite(t60Low) ? kLn1000 / t60Low : 0.0;
  const double high = std::isfinite(t60High) ? kLn1000 / t60High : 0.0;
  const double kappa = std::sqrt(plate.rigidity() / (plate.density * plate.thickness));
  loss.sigma1 = (high - loss.sigma0) / (2.0 * std::numbers::pi * highHz / kappa);
  return loss;
}

void PlateVoice::prepare(const PlatePatch& patch, int midiNote, double sampleRate) {
  const int r = patch.oversampling;
  require(r == 1 || r == 2 || r == 4 || r == 8 || r == 16, "oversampling", r, "1, 2, 4, 8 or 16");
  require(std::isfinite(sampleRate) && sampleRate >= 8000.0 && sampleRate <= 384000.0,
          "sample rate", sampleRate, "between 8000 and 384000 Hz");
  require(midiNote >= patch.lowestNote && midiNote <= patch.highestNote, "note", midiNote,
          "within the patch's lowest_note … highest_note, " + std::to_string(patch.lowestNote) +
              " … " + std::to_string(patch.highestNote));
  for (double f : patch.strike) require(f > 0.0 && f < 1.0, "strike_position", f, "in (0, 1)");
  for (double f : patch.strikeHigh)
    require(f > 0.0 && f < 1.0, "strike_position_high", f, "in (0, 1)");
  for (const auto& p : patch.pickups)
    for (double f : p) require(f > 0.0 && f < 1.0, "pickup_position", f, "in (0, 1)");
  require(std::isfinite(patch.strikeWidth) && patch.strikeWidth >= 0.0, "strike_width_m",
          patch.strikeWidth, ">= 0 m");
  require(std::isfinite(patch.forceMax) && patch.forceMax > 0.0, "force_max_n", patch.forceMax,
          "> 0 N");
  require(
      patch.durationMin > 0.0 && patch.durationMax >= patch.durationMin && patch.durationMax < 0.1,
      "duration_max_s", patch.durationMax, "at least duration_min_s > 0 and under 0.1 s");
  require(patch.velocityCurve > 0.0, "velocity_curve", patch.velocityCurve, "> 0");
  require(std::isfinite(patch.damperT60) && patch.damperT60 > 0.0, "damper_t60_s", patch.damperT60,
          "a finite time > 0 seconds");
  require(std::isfinite(patch.gain), "gain", patch.gain, "a finite number");
  require(patch.guardEnergyMultiple > 1.0, "guard_energy_multiple", patch.guardEnergyMultiple,
          "> 1");

  // Frequencies go as 1/L²: a semitone up shrinks both sides by 2^(−1/24). Or, per patch, the
  // plate keeps its size and the note moves the strike point between its two positions.
  PlatePhysics physics = patch.plate;
  double strike[2] = {patch.strike[0], patch.strike[1]};
  if (patch.noteMovesStrike) {
    const double t =
        patch.highestNote == patch.lowestNote
            ? 0.0
            : double(midiNote - patch.lowestNote) / (patch.highestNote - patch.lowestNote);
    for (int c = 0; c < 2; ++c) strike[c] += t * (patch.strikeHigh[c] - strike[c]);
  } else {
    const double scale = std::pow(2.0, -(midiNote - patch.referenceNote) / 24.0);
    physics.lx *= scale;
    physics.ly *= scale;
  }
  const double k = 1.0 / (sampleRate * r);
  const PlateLoss loss = plateLossFromT60(physics, patch.t60Low, patch.t60High, patch.t60HighHz);
  require((loss.sigma0 + kLn1000 / patch.damperT60) * k < 1.0, "damper_t60_s", patch.damperT60,
          "longer than ln(1000) k / (1 − σ0 k) = " +
              formatNumber(kLn1000 * k / (1.0 - loss.sigma0 * k)) + " s at this rate");
  const int mx = plateSegments(physics, physics.lx, k, patch.gridFactor, loss.sigma1);
  const int my = plateSegments(physics, physics.ly, k, patch.gridFactor, loss.sigma1);
  // Eigen's blocked products of the Airy solve keep their buffers on the stack up to about
  // 120 points a side (measured: 130 allocates); the audio path must not allocate.
  require(std::max(mx, my) - 1 <= kMaxPoints, "grid points per side", std::max(mx, my) - 1,
          "at most " + std::to_string(kMaxPoints) +
              " for this note: lower oversampling or raise grid_factor");
  const VonKarmanPlate plate(physics, mx, my);
  const StepParameters params{
      .k = k, .sigma0 = loss.sigma0, .sigma1 = loss.sigma1, .trackDissipation = false};
  auto scheme = std::make_unique<SplitSav<VonKarmanPlate>>(
      plate, params, InitialState{Vector::Zero(plate.size()), Vector::Zero(plate.size())});
  auto atRest = std::make_unique<SplitSav<VonKarmanPlate>>(*scheme);

  // The strike spread: a raised cone over the points within width/2, or the nearest point.
  std::vector<Eigen::Index> index;
  std::vector<double> weight;
  const double x0 = strike[0] * physics.lx, y0 = strike[1] * physics.ly;
  double total = 0.0, nearest = INFINITY;
  Eigen::Index nearestIndex = 0;
  for (int m = 0; m < plate.ny(); ++m)
    for (int l = 0; l < plate.nx(); ++l) {
      const double d = std::hypot((l + 1) * plate.hx() - x0, (m + 1) * plate.hy() - y0);
      const Eigen::Index i = l + static_cast<Eigen::Index>(plate.nx()) * m;
      if (d < nearest) nearest = d, nearestIndex = i;
      if (d < 0.5 * patch.strikeWidth) {
        index.push_back(i);
        weight.push_back(0.5 * (1.0 + std::cos(2.0 * std::numbers::pi * d / patch.strikeWidth)));
        total += weight.back();
      }
    }
  if (index.empty()) index = {nearestIndex}, weight = {1.0}, total = 1.0;
  for (double& w : weight) w /= total;
  Decimator decimators[2];
  for (Decimator& d : decimators) d.prepare(r);

  patch_ = patch;
  for (DcBlocker& b : dcBlockers_) b.prepare(5.0, sampleRate);
  sampleRate_ = sampleRate;
  k_ = k;
  loss_ = loss;
  lowestMode_ =
      std::asin(0.5 * k * std::sqrt(physics.rigidity() / (physics.density * physics.thickness)) *
                plate.laplacianEigenvalue(1, 1)) /
      (std::numbers::pi * k);
  scheme_ = std::move(scheme);
  atRest_ = std::move(atRest);
  strikeIndex_ = std::move(index);
  strikeWeight_ = std::move(weight);
  for (int c = 0; c < 2; ++c) decimators_[c] = std::move(decimators[c]);
  quiet_.prepare(sampleRate);
  reset();
}

void PlateVoice::reset() noexcept {
  *scheme_ = *atRest_;
  for (Decimator& d : decimators_) d.reset();
  for (DcBlocker& b : dcBlockers_) b.reset();
  pulsing_ = active_ = false;
  quiet_.reset();
}

double PlateVoice::energy() const { return scheme_->energy().total(); }

double PlateVoice::suppliedEnergy() const { return scheme_->supplied(); }

void PlateVoice::noteOn(double velocity) noexcept {
  if (!active_) reset();
  const double v = velocity >= 0.0 ? std::min(velocity, 1.0) : 0.0;  // NaN too
  pulseDuration_ = patch_.durationMax - (patch_.durationMax - patch_.durationMin) * v;
  pulseForce_ = patch_.forceMax * std::pow(v, patch_.velocityCurve);
  pulseTime_ = 0.0;
  pulsing_ = true;
  quiet_.strike();
  active_ = true;
  scheme_->setSigma0(loss_.sigma0);
}

// The raised cosine F(t) = F0 (1 − cos(2πt/T)) / 2 on [0, T], averaged over the step's window
// [t − k/2, t + k/2]: F(t) to O(k²) for a pulse of many steps, and for one shorter than a step
// its whole impulse F0 T / 2 — sampled at t = 0, k, …, such a pulse gave F(0) = 0, silence.
// The windows tile the time axis, so the impulse delivered is F0 T / 2 at every k.
double PlateVoice::pulseOverStep() const noexcept {
  const double w = 2.0 * std::numbers::pi / pulseDuration_;
  const double a = std::clamp(pulseTime_ - 0.5 * k_, 0.0, pulseDuration_);
  const double b = std::clamp(pulseTime_ + 0.5 * k_, 0.0, pulseDuration_);
  return pulseForce_ * 0.5 * ((b - a) - (std::sin(w * b) - std::sin(w * a)) / w) / k_;
}

void PlateVoice::release(double damperScale, double contact) noexcept {
  scheme_->setSigma0(releasedSigma0(loss_.sigma0, patch_.damperT60, damperScale, k_, contact));
}

// Velocity (q^{n+1} − q^n)/k or displacement q^n, bilinear between the grid points around (x, y).
double PlateVoice::pickup(const Vector& q, const Vector& qNext, const double* at) const {
  const VonKarmanPlate& plate = scheme_->system();
  const double sx = std::clamp(at[0] * (plate.nx() + 1) - 1.0, 0.0, plate.nx() - 1.0);
  const double sy = std::clamp(at[1] * (plate.ny() + 1) - 1.0, 0.0, plate.ny() - 1.0);
  const int l = std::min(static_cast<int>(sx), plate.nx() - 1),
            m = std::min(static_cast<int>(sy), plate.ny() - 1);
  const int l1 = std::min(l + 1, plate.nx() - 1), m1 = std::min(m + 1, plate.ny() - 1);
  const double fx = sx - l, fy = sy - m;
  auto value = [&](int a, int b) {
    const Eigen::Index i = a + static_cast<Eigen::Index>(plate.nx()) * b;
    return patch_.signal == PickupSignal::displacement ? q[i] : (qNext[i] - q[i]) / k_;
  };
  return (1.0 - fy) * ((1.0 - fx) * value(l, m) + fx * value(l1, m)) +
         fy * ((1.0 - fx) * value(l, m1) + fx * value(l1, m1));
}

void PlateVoice::process(std::span<float> left, std::span<float> right) noexcept {
  const size_t rightCount = std::min(left.size(), right.size());
  if (!active_) {
    silence(left, right, rightCount);
    return;
  }
  bool finite = true;
  for (size_t i = 0; i < left.size(); ++i) {
    double out[2] = {0.0, 0.0};
    bool ready = false;
    while (!ready) {
      if (pulsing_) {
        if (pulseTime_ - 0.5 * k_ < pulseDuration_) {
          const double f = pulseOverStep();
          for (size_t s = 0; s < strikeIndex_.size(); ++s)
            scheme_->setForce(strikeIndex_[s], f * strikeWeight_[s]);
          pulseTime_ += k_;
        } else {
          scheme_->clearForce();
          pulsing_ = false;
        }
      }
      scheme_->step();
      for (int c = 0; c < 2; ++c)
        ready =
            decimators_[c].push(pickup(scheme_->q(), scheme_->qNext(), patch_.pickups[c]), out[c]);
    }
    if (patch_.signal == PickupSignal::displacement)
      for (int c = 0; c < 2; ++c) out[c] = dcBlockers_[c].process(out[c]);
    left[i] = static_cast<float>(patch_.gain * out[0]);
    finite = finite && std::isfinite(left[i]);
    if (i < rightCount) {
      right[i] = static_cast<float>(patch_.gain * out[1]);
      finite = finite && std::isfinite(right[i]);
    }
  }
  // The guard: a non-finite sample or an energy beyond what the strikes supplied never leaves.
  const Energy e = scheme_->energy();
  if (!finite || !std::isfinite(e.total()) ||
      e.total() > patch_.guardEnergyMultiple * std::max(scheme_->supplied(), 1e-12)) {
    silence(left, right, rightCount);
    ++guardEvents_;
    reset();
    return;
  }
  if (quiet_.update(left, right, rightCount)) active_ = false;
}

}  // namespace hamiltone
