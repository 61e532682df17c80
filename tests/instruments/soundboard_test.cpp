// The modal soundboard: its modes are the orthotropic plate's, each decays at its σ = ηω/2, the
// discrete energy balance (S3) holds to roundoff, and bad physics is refused by name.
#include "instruments/soundboard.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace hamiltone {
namespace {

constexpr double kRate = 48000.0;
constexpr double kPi = std::numbers::pi;
const BoardPoint kPickups[2] = {{0.45, 0.35}, {1.2, 0.9}};

Soundboard preparedBoard(const SoundboardPhysics& p = {}, std::vector<BoardPoint> points = {}) {
  if (points.empty()) points = bridgeLine(21, 108, p);
  Soundboard board;
  board.prepare(p, kRate, points, kPickups);
  return board;
}

int findMode(const Soundboard& b, int m, int n) {
  for (int i = 0; i < b.modes(); ++i)
    if (b.modeM(i) == m && b.modeN(i) == n) return i;
  return -1;
}

TEST(Soundboard, ModeFrequenciesAreTheOrthotropicPlates) {
  const SoundboardPhysics p;
  const Soundboard board = preparedBoard(p);
  for (auto [m, n] : {std::pair{1, 1}, {2, 1}, {1, 2}, {3, 2}, {5, 3}}) {
    const int i = findMode(board, m, n);
    ASSERT_GE(i, 0) << m << "," << n;
    const double a = m / p.lx, b = n / p.ly;
    const double omega2 =
        std::pow(kPi, 4) / (p.density * p.thickness) *
        (p.d1 * std::pow(a, 4) + 2 * p.d3 * a * a * b * b + p.d2 * std::pow(b, 4));
    EXPECT_NEAR(board.modeHz(i), std::sqrt(omega2) / (2 * kPi), 1e-12 * board.modeHz(i));
  }
  // Every mode up to maxModeHz, none above, in ascending order.
  for (int i = 0; i + 1 < board.modes(); ++i) EXPECT_LE(board.modeHz(i), board.modeHz(i + 1));
  EXPECT_LE(board.modeHz(board.modes() - 1), p.maxModeHz);
  EXPECT_GT(board.modes(), 50);
}

// A free board rung by a one-sample impulse: each mode oscillates at its ω (the exact-frequency
// K̂) and decays at σ = ηω/2; with centred loss the discrete rate is −ln((1 − σk)/(1 + σk))/2k,
// σ to within (σk)²/3 ≈ 1e-6, so the measured T60 is held to 1 %.
TEST(Soundboard, ImpulseDecaysAtTheModalRate) {
  Soundboard board = preparedBoard();
  board.addForce(50, 100.0);
  for (int mode : {0, 4, 20}) {
    ASSERT_LT(mode, board.modes());
  }
  const int steps = static_cast<int>(0.6 * kRate);
  std::vector<std::vector<double>> history(3);
  const int modes[3] = {0, 4, 20};
  for (int n = 0; n < steps; ++n) {
    board.step();
    for (int j = 0; j < 3; ++j) history[j].push_back(board.modeAmplitude(modes[j]));
  }
  for (int j = 0; j < 3; ++j) {
    const int i = modes[j];
    const double sigma = board.modeDecayRate(i);
    const auto& h = history[j];
    // Peak |a| over one period around t1 and t2.
    const int period = static_cast<int>(kRate / board.modeHz(i)) + 2;
    const auto peak = [&](int at) {
      double v = 0;
      for (int s = at; s < at + period; ++s) v = std::max(v, std::abs(h[s]));
      return v;
    };
    const int t1 = period, t2 = std::min(steps - period - 1, static_cast<int>(3.0 / sigma * kRate));
    const double measuredSigma = std::log(peak(t1) / peak(t2)) / ((t2 - t1) / kRate);
    EXPECT_NEAR(6.908 / measuredSigma, 6.908 / sigma, 0.01 * 6.908 / sigma) << "mode " << i;
    // Frequency from the zero crossings between t1 and t2.
    int crossings = 0;
    double first = -1, last = -1;
    for (int s = t1; s < t2; ++s)
      if (h[s] <= 0 && h[s + 1] > 0) {
        const double t = s + h[s] / (h[s] - h[s + 1]);
        if (first < 0) first = t;
        last = t;
        ++crossings;
      }
    ASSERT_GT(crossings, 3);
    const double measuredHz = (crossings - 1) / ((last - first) / kRate);
    EXPECT_NEAR(measuredHz, board.modeHz(i), 2e-3 * board.modeHz(i)) << "mode " << i;
  }
}

// (S3): H + dissipated − supplied stays at its start (0) to roundoff while a random force drives
// a few points and after it stops; ~1e4 steps of sums of ~100 terms: 1e-12 of the largest term.
void expectBalance(const SoundboardPhysics& p, double tolerance) {
  Soundboard board = preparedBoard(p);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> force(0.0, 10.0);
  double scale = 0.0, worst = 0.0;
  for (int n = 0; n < 12000; ++n) {
    if (n < 4000)
      for (int k : {3, 39, 60, 87}) board.addForce(k, force(rng));
    board.step();
    const double h = board.energy();
    scale = std::max({scale, std::abs(h), board.dissipated(), board.supplied()});
    worst = std::max(worst, std::abs(h + board.dissipated() - board.supplied()));
  }
  EXPECT_GT(scale, 0.0);
  EXPECT_LT(worst, tolerance * scale) << "residual " << worst / scale;
  std::printf("balance residual %.3g of %.3g J\n", worst / scale, scale);
}

TEST(Soundboard, EnergyBalanceUnderRandomForceToRoundoff) { expectBalance({}, 1e-12); }

TEST(Soundboard, LosslessBoardConservesEnergyExactly) {
  SoundboardPhysics p;
  p.lossFactor = 0.0;
  Soundboard board = preparedBoard(p);
  board.addForce(20, 50.0);
  board.step();
  const double h0 = board.energy();
  double worst = 0.0;
  for (int n = 0; n < 20000; ++n) {
    board.step();
    worst = std::max(worst, std::abs(board.energy() - h0));
  }
  EXPECT_EQ(board.dissipated(), 0.0);
  EXPECT_LT(worst, 1e-13 * h0);
  EXPECT_GT(h0, 0.0);
}

TEST(Soundboard, SameInputSameBits) {
  Soundboard a = preparedBoard(), b = preparedBoard();
  double la = 0, ra = 0, lb = 0, rb = 0;
  for (int n = 0; n < 3000; ++n) {
    a.addForce(n % 88, std::sin(n * 0.01));
    b.addForce(n % 88, std::sin(n * 0.01));
    a.step();
    b.step();
  }
  a.pickups(la, ra);
  b.pickups(lb, rb);
  EXPECT_EQ(la, lb);
  EXPECT_EQ(ra, rb);
  EXPECT_EQ(a.energy(), b.energy());
}

// w = Φa is taken only at the points in use; a point brought back (refreshPoint) reads the same
// bits as a board that took it at every step, and so does every point in use.
TEST(Soundboard, ARefreshedPointReadsAsIfItHadBeenInUse) {
  Soundboard all = preparedBoard(), some = preparedBoard();
  std::vector<int> third;
  for (int k = 0; k < 88; k += 3) third.push_back(k);
  some.setActivePoints(third);
  for (int n = 0; n < 500; ++n) {
    for (Soundboard* b : {&all, &some}) b->addForce((7 * n) % 88, std::sin(n * 0.03));
    all.step();
    some.step();
  }
  for (int k : third) EXPECT_EQ(some.displacement(k), all.displacement(k)) << k;
  for (int k : {1, 44, 86}) {
    some.refreshPoint(k);
    EXPECT_EQ(some.displacement(k), all.displacement(k)) << k;
    EXPECT_EQ(some.previousDisplacements()[k], all.previousDisplacements()[k]) << k;
  }
  EXPECT_NE(all.displacement(44), 0.0);
}

void expectRefused(const SoundboardPhysics& p, std::vector<BoardPoint> points,
                   std::vector<std::string> words) {
  Soundboard board;
  try {
    board.prepare(p, kRate, points, kPickups);
    ADD_FAILURE() << "accepted";
  } catch (const std::invalid_argument& e) {
    for (const auto& w : words) EXPECT_THAT(e.what(), ::testing::HasSubstr(w));
  }
}

TEST(Soundboard, InvalidPhysicsIsRefusedByName) {
  const std::vector<BoardPoint> one = {{0.5, 0.5}};
  SoundboardPhysics p;
  p.thickness = -0.009;
  expectRefused(p, one, {"thickness", "-0.009", "> 0"});
  p = {};
  p.density = std::numeric_limits<double>::quiet_NaN();
  expectRefused(p, one, {"density", "nan", "> 0"});
  p = {};
  p.maxModeHz = 30000.0;  // beyond Nyquist (24 kHz), and beyond fs/π
  expectRefused(p, one, {"maxModeHz", "30000", "(0, 15278.9) Hz"});
  p = {};
  p.lossFactor = -0.1;
  expectRefused(p, one, {"lossFactor", "-0.1", "[0, 1)"});
  expectRefused({}, {{0.5, 0.5}, {2.5, 0.5}}, {"bridge point 1", "2.5", "x <= 1.9"});
}

TEST(Soundboard, BridgeLineCoversTheKeyboardOnTheBoard) {
  const SoundboardPhysics p;
  const auto points = bridgeLine(21, 108, p);
  ASSERT_EQ(points.size(), 88u);
  for (const auto& q : points) {
    EXPECT_GT(q.x, 0.05 * p.lx);
    EXPECT_LT(q.x, 0.95 * p.lx);
    EXPECT_GT(q.y, 0.05 * p.ly);
    EXPECT_LT(q.y, 0.95 * p.ly);
  }
  // E2 ends the bass bridge, F2 starts the treble bridge: a jump between them.
  const auto e2 = points[40 - 21], f2 = points[41 - 21];
  EXPECT_GT(std::hypot(f2.x - e2.x, f2.y - e2.y), 0.1);
  EXPECT_THROW(bridgeLine(20, 108, p), std::invalid_argument);
}

}  // namespace
}  // namespace hamiltone
