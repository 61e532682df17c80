// The modal soundboard: its modes, the step (S1) and the energy tallies (S2)–(S3).
#include "instruments/soundboard.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "util/format_number.h"

namespace hamiltone {

namespace {

constexpr double kPi = std::numbers::pi;

void requirePositive(const char* name, double value, const char* unit) {
  if (!std::isfinite(value) || value <= 0.0)
    throw std::invalid_argument(std::string("soundboard ") + name + " = " + formatNumber(value) +
                                ": must be a finite number > 0 (" + unit + ")");
}

// ω_mn² = (π⁴/ρh)(D1 (m/lx)⁴ + 2 D3 (m/lx)²(n/ly)² + D2 (n/ly)⁴): the orthotropic plate, simply
// supported (Leissa; Lekhnitskii's Huber plate).
double modeOmega(const SoundboardPhysics& p, int m, int n) {
  const double a = m / p.lx, b = n / p.ly;
  const double pi4 = kPi * kPi * kPi * kPi;
  return std::sqrt(pi4 / p.surfaceDensity() *
                   (p.d1 * a * a * a * a + 2.0 * p.d3 * a * a * b * b + p.d2 * b * b * b * b));
}

void requireOnBoard(const char* what, int index, const BoardPoint& q, const SoundboardPhysics& p) {
  const bool inside = std::isfinite(q.x) && std::isfinite(q.y) && q.x >= 0.0 && q.x <= p.lx &&
                      q.y >= 0.0 && q.y <= p.ly;
  if (!inside)
    throw std::invalid_argument(std::string(what) + " " + std::to_string(index) + " = (" +
                                formatNumber(q.x) + ", " + formatNumber(q.y) +
                                ") m: must lie on the board, 0 <= x <= " + formatNumber(p.lx) +
                                ", 0 <= y <= " + formatNumber(p.ly));
}

}  // namespace

void Soundboard::prepare(const SoundboardPhysics& p, double sampleRate,
                         std::span<const BoardPoint> bridgePoints,
                         const BoardPoint (&pickupPoints)[2]) {
  requirePositive("lx", p.lx, "m");
  requirePositive("ly", p.ly, "m");
  requirePositive("thickness", p.thickness, "m");
  requirePositive("density", p.density, "kg/m^3");
  requirePositive("d1", p.d1, "N m");
  requirePositive("d2", p.d2, "N m");
  requirePositive("d3", p.d3, "N m");
  if (!std::isfinite(sampleRate) || sampleRate <= 0.0)
    throw std::invalid_argument("soundboard sample rate = " + formatNumber(sampleRate) +
                                ": must be a finite number > 0 (Hz)");
  if (!(p.lossFactor >= 0.0 && p.lossFactor < 1.0))
    throw std::invalid_argument("soundboard lossFactor = " + formatNumber(p.lossFactor) +
                                ": must be in [0, 1)");
  // (S2) is positive while ωk < 2, i.e. f < fs/π: the modes stop below it.
  const double stableHz = sampleRate / kPi;
  if (!(p.maxModeHz > 0.0 && p.maxModeHz < stableHz))
    throw std::invalid_argument("soundboard maxModeHz = " + formatNumber(p.maxModeHz) +
                                ": must be in (0, " + formatApprox(stableHz, 6) +
                                ") Hz, below fs/pi at fs = " + formatNumber(sampleRate) + " Hz");
  for (std::size_t i = 0; i < bridgePoints.size(); ++i)
    requireOnBoard("soundboard bridge point", static_cast<int>(i), bridgePoints[i], p);
  for (int i = 0; i < 2; ++i) requireOnBoard("soundboard pickup", i, pickupPoints[i], p);

  const double omegaMax = 2.0 * kPi * p.maxModeHz;
  std::vector<std::pair<double, std::pair<int, int>>> found;
  for (int m = 1; modeOmega(p, m, 1) <= omegaMax; ++m)
    for (int n = 1; modeOmega(p, m, n) <= omegaMax; ++n)
      found.push_back({modeOmega(p, m, n), {m, n}});
  if (found.empty())
    throw std::invalid_argument("soundboard maxModeHz = " + formatNumber(p.maxModeHz) +
                                ": below the lowest mode, " +
                                formatApprox(modeOmega(p, 1, 1) / (2.0 * kPi)) + " Hz");
  std::sort(found.begin(), found.end());  // by frequency, then (m, n): the same order every time

  physics_ = p;
  k_ = 1.0 / sampleRate;
  mass_ = p.surfaceDensity() * p.lx * p.ly / 4.0;  // ∫ρh φ² = ρh lx ly / 4
  const int modeCount = static_cast<int>(found.size());
  index_.resize(modeCount);
  omega_.resize(modeCount);
  omegaHat2_.resize(modeCount);
  sigma_.resize(modeCount);
  c1_.resize(modeCount);
  c2_.resize(modeCount);
  c3_.resize(modeCount);
  for (int i = 0; i < modeCount; ++i) {
    index_[i] = found[i].second;
    const double omega = found[i].first;
    const double s = std::sin(omega * k_ / 2.0);
    omega_[i] = omega;
    omegaHat2_[i] = 4.0 * s * s / (k_ * k_);   // K̂/M of (S1)
    sigma_[i] = p.lossFactor * omega / 2.0;    // σ_m = η ω_m / 2
    const double damp = 1.0 + sigma_[i] * k_;  // (S1) solved for a^{n+1}
    c1_[i] = (2.0 - 4.0 * s * s) / damp;
    c2_[i] = (1.0 - sigma_[i] * k_) / damp;
    c3_[i] = k_ * k_ / (mass_ * damp);
  }
  const int pointCount = static_cast<int>(bridgePoints.size());
  ldModes_ = bodyPadded(modeCount);
  phi_.assign(pointCount * ldModes_, 0.0f);
  phiColumns_.resize(modeCount, pointCount);
  for (int k = 0; k < pointCount; ++k)
    for (int i = 0; i < modeCount; ++i) {
      phi_[k * ldModes_ + i] = static_cast<float>(shape(i, bridgePoints[k]));
      phiColumns_(i, k) = phi_[k * ldModes_ + i];
    }
  loops_ = &selectedBodyLoops();
  pickupShapes_.resize(2, modeCount);
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < modeCount; ++i) pickupShapes_(j, i) = shape(i, pickupPoints[j]);
  a_.resize(modeCount);
  aPrev_.resize(modeCount);
  g_.resize(modeCount);
  force_.resize(pointCount);
  w_.resize(pointCount);
  wPrev_.resize(pointCount);
  active_.resize(pointCount);
  for (int k = 0; k < pointCount; ++k) active_[k] = k;
  activeCount_ = pointCount;
  reset();
}

void Soundboard::reset() noexcept {
  a_.setZero();
  aPrev_.setZero();
  g_.setZero();
  force_.setZero();
  w_.setZero();
  wPrev_.setZero();
  dissipated_ = supplied_ = lastWork_ = 0.0;
}

double Soundboard::shape(int mode, const BoardPoint& p) const noexcept {
  return std::sin(index_[mode].first * kPi * p.x / physics_.lx) *
         std::sin(index_[mode].second * kPi * p.y / physics_.ly);
}

double Soundboard::modeHz(int mode) const noexcept { return omega_[mode] / (2.0 * kPi); }

void Soundboard::addForces(std::span<const double> forces) noexcept {
  const long n = static_cast<long>(forces.size());
  double* f = force_.data();
#pragma omp simd
  for (long k = 0; k < n; ++k) f[k] += forces[k];
}

void Soundboard::step() noexcept {
  const long n = a_.size(), points = force_.size();
  loops_->combineRows(phi_.data(), ldModes_, points, force_.data(), 0, n,
                      g_.data());  // g_m = Σ_k φ_m(x_k) F_k
  const double* c1 = c1_.data();
  const double* c2 = c2_.data();
  const double* c3 = c3_.data();
  const double* sigma = sigma_.data();
  const double* g = g_.data();
  const double* a = a_.data();
  double* prev = aPrev_.data();  // a^{n−1} in, a^{n+1} out
  double lost = 0.0, work = 0.0;
#pragma omp simd reduction(+ : lost, work)
  for (long i = 0; i < n; ++i) {
    const double next = c1[i] * a[i] - c2[i] * prev[i] + c3[i] * g[i];  // (S1)
    const double d = next - prev[i];                                    // 2k δt· a
    lost += sigma[i] * d * d;  // (S3): k 2Mσ (δt· a)²/M
    work += g[i] * d;          // (S3): 2 g δt· a k
    prev[i] = next;
  }
  dissipated_ += mass_ * lost / (2.0 * k_);
  lastWork_ = 0.5 * work;  // Σ_k F_k (w^{n+1} − w^{n−1})/2 = Σ_m g_m (a^{n+1} − a^{n−1})/2
  supplied_ += lastWork_;
  a_.swap(aPrev_);
  wPrev_.swap(w_);
  loops_->dotRows(phi_.data(), ldModes_, active_.data(), activeCount_, n, a_.data(),
                  w_.data());  // w_k = Σ_m φ_m(x_k) a_m
  force_.setZero();
}

void Soundboard::setActivePoints(std::span<const int> points) noexcept {
  activeCount_ = static_cast<int>(std::min(points.size(), active_.size()));
  std::copy_n(points.begin(), activeCount_, active_.begin());
}

// The same sum, to the bit, as the step's at that point.
void Soundboard::refreshPoint(int point) noexcept {
  const long n = a_.size();
  loops_->dotRows(phi_.data(), ldModes_, &point, 1, n, a_.data(), w_.data());
  loops_->dotRows(phi_.data(), ldModes_, &point, 1, n, aPrev_.data(), wPrev_.data());
}

void Soundboard::pickups(double& left, double& right) const noexcept {
  const long n = a_.size();
  const double* a = a_.data();
  const double* prev = aPrev_.data();
  const double* s0 = pickupShapes_.row(0).data();
  const double* s1 = pickupShapes_.row(1).data();
  double l = 0.0, r = 0.0;
#pragma omp simd reduction(+ : l, r)
  for (long i = 0; i < n; ++i) {
    const double v = a[i] - prev[i];
    l += s0[i] * v;
    r += s1[i] * v;
  }
  left = l / k_;
  right = r / k_;
}

double Soundboard::energy() const noexcept {
  const long n = a_.size();
  const double* a = a_.data();
  const double* prev = aPrev_.data();
  const double* w2 = omegaHat2_.data();
  const double invK2 = 1.0 / (k_ * k_);
  double h = 0.0;
#pragma omp simd reduction(+ : h)
  for (long i = 0; i < n; ++i) {
    const double d = a[i] - prev[i];
    h += d * d * invK2 + w2[i] * a[i] * prev[i];  // (S2) over M/2
  }
  return 0.5 * mass_ * h;
}

std::vector<BoardPoint> bridgeLine(int lowestNote, int highestNote, const SoundboardPhysics& board,
                                   const BridgeGeometry& g) {
  constexpr int kA0 = 21, kE2 = 40, kF2 = 41, kC8 = 108;
  if (lowestNote < kA0 || highestNote > kC8 || lowestNote > highestNote)
    throw std::invalid_argument("bridgeLine notes " + std::to_string(lowestNote) + " … " +
                                std::to_string(highestNote) +
                                ": must be MIDI notes within 21 … 108, lowest first");
  const auto along = [&](BoardPoint from, BoardPoint to, double t) {
    return BoardPoint{board.lx * (from.x + t * (to.x - from.x)),
                      board.ly * (from.y + t * (to.y - from.y))};
  };
  std::vector<BoardPoint> points;
  points.reserve(highestNote - lowestNote + 1);
  for (int note = lowestNote; note <= highestNote; ++note) {
    if (note <= kE2)
      points.push_back(along(g.bassLow, g.bassHigh, double(note - kA0) / (kE2 - kA0)));
    else
      points.push_back(along(g.trebleLow, g.trebleHigh, double(note - kF2) / (kC8 - kF2)));
  }
  return points;
}

}  // namespace hamiltone
