// The sympathetic strings: partials, losses and dampers, the coupling (Y1)–(Y5) and the check (Y6).
#include "instruments/sympathetic_strings.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include "instruments/piano_scale.h"
#include "util/format_number.h"

namespace hamiltone {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kLn1000 = 6.907755278982137;  // T60 = ln(1000)/σ

void requireKeyPositive(int key, const char* name, double value, const char* unit,
                        bool infinite = false) {
  if (!(value > 0.0) || (std::isinf(value) && !infinite))
    throw std::invalid_argument(
        "sympathetic key " + std::to_string(key) + " " + name + " = " + formatNumber(value) +
        ": must be " + (infinite ? "> 0 or +inf (" : "a finite number > 0 (") + unit + ")");
}

// ξ(ω), the wavenumber² of the stiff string's mode at ω: c²ξ + c² B L²/π² ξ² = ω², c = 2 f0 L
// (docs/instrument-data.md §3.4).
double wavenumber2(const SympatheticKey& s, double omega) {
  const double c2 = 4.0 * s.f0 * s.f0 * s.length * s.length;
  const double kappa2 = c2 * s.inharmonicityB * s.length * s.length / (kPi * kPi);
  if (kappa2 == 0.0) return omega * omega / c2;
  return (-c2 + std::sqrt(c2 * c2 + 4.0 * kappa2 * omega * omega)) / (2.0 * kappa2);
}

}  // namespace

void SympatheticStrings::prepare(std::span<const SympatheticKey> keys, const Soundboard& board,
                                 double sampleRate, double maxHz, int maxPartials) {
  if (static_cast<int>(keys.size()) != board.points())
    throw std::invalid_argument("sympathetic keys = " + std::to_string(keys.size()) +
                                ": must be one per soundboard bridge point (" +
                                std::to_string(board.points()) + ")");
  if (!std::isfinite(sampleRate) || sampleRate <= 0.0)
    throw std::invalid_argument("sympathetic sample rate = " + formatNumber(sampleRate) +
                                ": must be a finite number > 0 (Hz)");
  if (!(maxHz > 0.0 && maxHz < sampleRate / 4.0))  // (Y6): k² ω̂² < 2 ⇔ f < fs/4
    throw std::invalid_argument("sympathetic maxHz = " + formatNumber(maxHz) + ": must be in (0, " +
                                formatNumber(sampleRate / 4.0) + ") Hz, below fs/4");
  if (maxPartials < 1)
    throw std::invalid_argument("sympathetic maxPartials = " + std::to_string(maxPartials) +
                                ": must be >= 1");
  for (int i = 0; i < static_cast<int>(keys.size()); ++i) {
    const SympatheticKey& s = keys[i];
    requireKeyPositive(i, "f0", s.f0, "Hz");
    requireKeyPositive(i, "linearDensity", s.linearDensity, "kg/m");
    requireKeyPositive(i, "length", s.length, "m");
    requireKeyPositive(i, "tension", s.tension, "N");
    requireKeyPositive(i, "t60Low", s.t60Low, "s", true);
    requireKeyPositive(i, "t60High", s.t60High, "s", true);
    requireKeyPositive(i, "t60HighHz", s.t60HighHz, "Hz");
    requireKeyPositive(i, "damperT60", s.damperT60, "s", true);
    if (!(s.inharmonicityB >= 0.0 && s.inharmonicityB < 1.0))
      throw std::invalid_argument("sympathetic key " + std::to_string(i) + " inharmonicityB = " +
                                  formatNumber(s.inharmonicityB) + ": must be in [0, 1)");
    if (s.unisons < 1 || s.unisons > 4)
      throw std::invalid_argument("sympathetic key " + std::to_string(i) +
                                  " unisons = " + std::to_string(s.unisons) + ": must be 1 … 4");
  }

  data_.assign(keys.begin(), keys.end());
  k_ = 1.0 / sampleRate;
  const int keyCount = static_cast<int>(keys.size());
  keys_ = keyCount;
  partials_.assign(keyCount, 0);
  for (int key = 0; key < keyCount; ++key) {
    const SympatheticKey& s = keys[key];
    while (partials_[key] < maxPartials) {
      const int n = partials_[key] + 1;
      if (n * s.f0 * std::sqrt(1.0 + s.inharmonicityB * n * n) > maxHz) break;
      ++partials_[key];
    }
  }
  rows_ = keyCount ? *std::max_element(partials_.begin(), partials_.end()) : 0;
  // Row n − 1 runs over the keys up to the last with n partials: the higher the key, the fewer
  // partials below maxHz, so a row is nearly all in use.
  rowLength_.assign(rows_, 0);
  for (int key = 0; key < keyCount; ++key)
    for (int row = 0; row < partials_[key]; ++row) rowLength_[row] = key + 1;
  // Slot j = (n − 1) keys + key: partial n of every key side by side, so the loops run across the
  // keys with w_key and F_key contiguous. Missing partials are zeros that stay zero.
  const Eigen::Index total = static_cast<Eigen::Index>(rows_) * keyCount;
  mass_.setOnes(total);
  stiffness_.setZero(total);
  omega_.setZero(total);
  sigmaOwn_.setZero(total);
  cOn_.setZero(total);
  kappaOn_.resize(keyCount);
  for (int key = 0; key < keyCount; ++key) {
    const SympatheticKey& s = keys[key];
    const double u = s.unisons;
    const double sigma0 = kLn1000 / s.t60Low;
    const double sigma1 =
        std::max(0.0, (kLn1000 / s.t60High - sigma0) / wavenumber2(s, 2.0 * kPi * s.t60HighHz));
    double kappa = u * s.tension / s.length;  // (Y2): the static T/L per string
    for (int n = 1; n <= partials_[key]; ++n) {
      const Eigen::Index j = slot(key, n);
      const double fn = n * s.f0 * std::sqrt(1.0 + s.inharmonicityB * n * n);
      const double nu = n * kPi / s.length;
      const double m = u * s.linearDensity * s.length / 2.0;  // (Y1)
      const double sn = std::sin(kPi * fn * k_);              // sin(ωk/2)
      const double kHat = m * 4.0 * sn * sn / (k_ * k_);      // K̂_n
      const double c =
          u * ((n % 2) ? -1.0 : 1.0) * nu * s.tension * (1.0 + s.inharmonicityB * n * n);
      kappa += c * c / kHat;  // (Y2)
      mass_[j] = m;
      stiffness_[j] = kHat;
      omega_[j] = 2.0 * kPi * fn;
      sigmaOwn_[j] = sigma0 + sigma1 * nu * nu;  // σ0 + σ1 ξ_n, ξ_n = (nπ/L)²
      cOn_[j] = c;
    }
    kappaOn_[key] = kappa;
  }

  // (Y6): the board with the strings' springs, λmax(K̂/M + Φᵀκ Φ/M).
  const Eigen::MatrixXd& phi = board.shapes();  // modes × points
  Eigen::MatrixXd a = phi * kappaOn_.asDiagonal() * phi.transpose() / board.modalMass();
  for (int i = 0; i < board.modes(); ++i) a(i, i) += board.modeStiffness(i) / board.modalMass();
  const double lambda = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(a, Eigen::EigenvaluesOnly)
                            .eigenvalues()
                            .maxCoeff();
  if (!(lambda * k_ * k_ < 2.0))
    throw std::invalid_argument(
        "sympathetic strings: the stiffness they add at the bridge (largest kappa " +
        formatApprox(kappaOn_.maxCoeff()) +
        " N/m) makes k^2 lambda_max = " + formatApprox(lambda * k_ * k_) +
        ": must be < 2 for stability (fewer partials, a lower maxHz or a higher sample rate)");

  sigma_.setZero(total);
  c_ = cOn_;
  kappa_ = kappaOn_;
  lost_.setZero(total);
  loops_ = &selectedBodyLoops();
  a1_.setZero(total);
  a2_.setZero(total);
  a3_.setZero(total);
  b_.resize(total);
  bPrev_.resize(total);
  contact_.assign(keyCount, 0.0);
  runs_.reserve(keyCount);
  excluded_.assign(keyCount, 0);
  asleep_.assign(keyCount, 0);
  for (int key = 0; key < keyCount; ++key) setCoefficients(key);
  reset();
}

void SympatheticStrings::reset() noexcept {
  for (int key = 0; key < keys_; ++key) {  // every key not excluded coupled again
    asleep_[key] = 0;
    couple(key, 0.0, 0.0);
  }
  b_.setZero();
  bPrev_.setZero();
  lost_.setZero();
  runsStale_ = true;  // a second prepare() may find every key coupled already (couple() skips)
}

void SympatheticStrings::setCoefficients(int key) noexcept {
  const SympatheticKey& s = data_[key];
  const double c = contact_[key];
  // The damper adds c ln(1000)/damperT60 to the string's own decay rate, as it does to a voice's
  // (releasedSigma0): a damper only ever takes energy away.
  const double damper = std::isinf(s.damperT60) ? 0.0 : c * kLn1000 / s.damperT60;
  for (int n = 1; n <= partials_[key]; ++n) {
    const Eigen::Index j = slot(key, n);
    const double sigma = sigmaOwn_[j] + damper;
    sigma_[j] = sigma;
    const double damp = 1.0 + sigma * k_;  // (Y3) solved for a^{n+1}
    a1_[j] = (2.0 - stiffness_[j] * k_ * k_ / mass_[j]) / damp;
    a2_[j] = (1.0 - sigma * k_) / damp;
    a3_[j] = k_ * k_ / (mass_[j] * damp);
  }
}

void SympatheticStrings::setDamper(int key, double contact) noexcept {
  contact_[key] = std::clamp(std::isnan(contact) ? 1.0 : contact, 0.0, 1.0);
  setCoefficients(key);
}

double SympatheticStrings::keyEnergy(int key) const noexcept {
  double h = 0.0;
  for (int n = 1; n <= partials_[key]; ++n) {
    const Eigen::Index j = slot(key, n);
    const double d = (b_[j] - bPrev_[j]) / k_;
    h += 0.5 * (mass_[j] * d * d + stiffness_[j] * b_[j] * bPrev_[j]);
  }
  return h;
}

double SympatheticStrings::ringingEnergy(int key, double w, double wPrev) const noexcept {
  double h = 0.0;
  for (int n = 1; n <= partials_[key]; ++n) {
    const Eigen::Index j = slot(key, n);
    const double now = b_[j] + c_[j] * w / stiffness_[j];
    const double before = bPrev_[j] + c_[j] * wPrev / stiffness_[j];
    const double d = (now - before) / k_;
    h += 0.5 * (mass_[j] * d * d + stiffness_[j] * now * before);
  }
  return h;
}

// Key k's share of (Y5), w = w^{n+1}, wPrev = w^n.
double SympatheticStrings::keyCoupling(int key, double w, double wPrev) const noexcept {
  double h = 0.5 * kappa_[key] * w * wPrev;
  for (int n = 1; n <= partials_[key]; ++n) {
    const Eigen::Index j = slot(key, n);
    h += 0.5 * c_[j] * (b_[j] * wPrev + bPrev_[j] * w);
  }
  return h;
}

double SympatheticStrings::couple(int key, double w, double wPrev) noexcept {
  const bool on = coupled(key);
  if (on == (kappa_[key] != 0.0)) return 0.0;
  const double before = keyEnergy(key) + keyCoupling(key, w, wPrev);
  kappa_[key] = on ? kappaOn_[key] : 0.0;
  runsStale_ = true;
  for (int n = 1; n <= partials_[key]; ++n) {
    const Eigen::Index j = slot(key, n);
    c_[j] = on ? cOn_[j] : 0.0;
    // Back at rest on the board: the static shape u = w x/L, a_n = −C_n w/K̂_n.
    b_[j] = on ? -c_[j] * w / stiffness_[j] : 0.0;
    bPrev_[j] = on ? -c_[j] * wPrev / stiffness_[j] : 0.0;
  }
  return keyEnergy(key) + keyCoupling(key, w, wPrev) - before;
}

double SympatheticStrings::setExcluded(int key, bool excluded, double w, double wPrev) noexcept {
  excluded_[key] = excluded;
  return couple(key, w, wPrev);
}

double SympatheticStrings::sleep(int key, double w, double wPrev) noexcept {
  asleep_[key] = 1;
  return couple(key, w, wPrev);
}

double SympatheticStrings::wake(int key, double w, double wPrev) noexcept {
  asleep_[key] = 0;
  return couple(key, w, wPrev);
}

bool SympatheticStrings::damped(int key) const noexcept {
  return contact_[key] >= 1.0 && !std::isinf(data_[key].damperT60);
}

// The coupled keys as runs [first, last), gaps under kRunGap keys bridged: an uncoupled key's
// partials are at rest with no coupling (couple()), so stepping it leaves zeros and adds nothing
// to the forces or the loss — skipping it or not gives the same bits.
void SympatheticStrings::findRuns() noexcept {
  constexpr int kRunGap = 4;  // one AVX2 register of keys
  runs_.clear();              // within the capacity reserved in prepare
  for (int key = 0; key < keys_; ++key) {
    if (!coupled(key)) continue;
    if (!runs_.empty() && key - runs_.back().second < kRunGap)
      runs_.back().second = key + 1;
    else
      runs_.push_back({key, key + 1});
  }
  runsStale_ = false;
}

void SympatheticStrings::step(const Eigen::VectorXd& w, std::span<double> forces) noexcept {
  if (runsStale_) findRuns();
  const long keyCount = keys_;
  const double* wk = w.data();
  double* f = forces.data();
  const double* kappa = kappa_.data();
#pragma omp simd
  for (long key = 0; key < keyCount; ++key) f[key] -= kappa[key] * wk[key];  // (Y4): −κ w^n
  for (int row = 0; row < rows_; ++row) {
    for (const auto& [first, last] : runs_) {
      const long length = std::min<long>(last, rowLength_[row]) - first;
      if (length <= 0) break;  // the runs ascend: the row ends before this one
      const long at = row * keyCount + first;
      double* lost = lost_.data() + at;  // σ d² per slot (no chain of sums); × M/2k: k 2Mσ (δt· a)²
      loops_->partialsRow(length, a1_.data() + at, a2_.data() + at, a3_.data() + at, c_.data() + at,
                          sigma_.data() + at, b_.data() + at, wk + first, bPrev_.data() + at, lost,
                          f + first);  // (Y3), (Y4); bPrev_: a^{n−1} in, a^{n+1} out
    }
  }
  b_.swap(bPrev_);
}

double SympatheticStrings::dissipated() const noexcept {
  return mass_.cwiseProduct(lost_).sum() / (2.0 * k_);
}

double SympatheticStrings::energy(const Eigen::VectorXd& w,
                                  const Eigen::VectorXd& wPrev) const noexcept {
  double h = 0.0;
  for (int key = 0; key < keys(); ++key) h += keyEnergy(key) + keyCoupling(key, w[key], wPrev[key]);
  return h;
}

double SympatheticStrings::partialHz(int key, int n) const noexcept {
  return omega_[slot(key, n)] / (2.0 * kPi);
}

}  // namespace hamiltone

namespace hamiltone {

namespace {

// docs/instrument-data.md §3.2: MIDI, single-string T60 (s, unused here: it holds the board's
// loss too), T60 after release (s; 0: none).
constexpr double kDecay[][3] = {
    {21, 40.0, 1.73}, {24, 40.0, 1.65}, {28, 40.0, 1.48}, {29, 10.0, 1.44}, {33, 10.0, 1.24},
    {36, 10.0, 1.12}, {40, 9.9, 0.92},  {45, 9.2, 0.73},  {48, 8.6, 0.63},  {52, 8.6, 0.58},
    {57, 8.4, 0.53},  {60, 8.2, 0.51},  {64, 7.9, 0.46},  {69, 7.6, 0.40},  {72, 7.5, 0.37},
    {76, 7.0, 0.38},  {81, 6.4, 0.44},  {84, 6.0, 0.55},  {88, 5.4, 1.74},  {89, 5.3, 0.0},
    {93, 4.7, 0.0},   {96, 4.3, 0.0},   {99, 4.0, 0.0},   {108, 4.0, 0.0}};

double interpolated(int note, int column) {
  const int rows = sizeof kDecay / sizeof kDecay[0];
  for (int i = 1; i < rows; ++i)
    if (note <= kDecay[i][0]) {
      const double t = (note - kDecay[i - 1][0]) / (kDecay[i][0] - kDecay[i - 1][0]);
      return kDecay[i - 1][column] + t * (kDecay[i][column] - kDecay[i - 1][column]);
    }
  return kDecay[rows - 1][column];
}

}  // namespace

std::vector<SympatheticKey> grandSympatheticKeys(int lowestNote, int highestNote) {
  std::vector<SympatheticKey> keys;
  for (int note = lowestNote; note <= highestNote; ++note) {
    const StringPhysics s = pianoString(note);  // throws outside 21 … 108
    SympatheticKey key;
    key.f0 = equalTemperament(note);
    key.linearDensity = s.linearDensity();
    key.length = s.length;
    key.tension = s.tension;
    key.inharmonicityB = kPi * kPi * s.young * s.inertia / (s.tension * s.length * s.length);
    key.unisons = note <= 28 ? 1 : note <= 33 ? 2 : 3;  // §1.4
    // The string's own loss, RT-425's law (§2.1): the board's share comes from the coupling, so
    // §3.2's whole-instrument T60s would count it twice.
    const int i = note - 20;
    const double ru = std::max(0.0, 5e-3 * i - 0.015), eta = 2.78e-11 * i + 1.5274e-9;
    const double omegaHigh = 2.0 * kPi * key.t60HighHz;
    key.t60Low = ru > 0.0 ? kLn1000 / ru : std::numeric_limits<double>::infinity();
    key.t60High = kLn1000 / (ru + eta * omegaHigh * omegaHigh);
    // From F6 (89) up there is no damper (§3.2, CLM).
    key.damperT60 = note >= 89 ? std::numeric_limits<double>::infinity() : interpolated(note, 2);
    keys.push_back(key);
  }
  return keys;
}

}  // namespace hamiltone
