// The string model: ∇V' is the derivative of V' (65), K has the closed-form spectrum the tuning
// and the bound (44) rely on, the loss operator is −ρA h D2, and unphysical strings are refused.
#include "models/string.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "models/string_tuning.h"
#include "presets/piano_scale.h"
#include "schemes/sav.h"
#include "support/energy_checks.h"

namespace hamiltone {
namespace {

// The paper's C3 string (BDZ §4.2.3) with its steel core's bending stiffness, d = 1.063 mm.
StringPhysics c3(bool stiff = true) {
  StringPhysics p;
  if (stiff) p.inertia = std::numbers::pi * std::pow(1.063e-3, 4) / 64.0;
  return p;
}

using testing::randomVector;

Eigen::MatrixXd matrixOf(const NonlinearString& s, auto apply) {
  const Eigen::Index n = s.size();
  Eigen::MatrixXd a(n, n);
  Vector e(n), col(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    e.setZero();
    e[j] = 1.0;
    apply(e, col);
    a.col(j) = col;
  }
  return a;
}

// Random states of a few mm transverse and a few µm longitudinal, like a struck piano string;
// a relative 1e-6 against central differences leaves room for O(δ²) and for roundoff ~ 1e-16 V'/δ.
TEST(NonlinearString, GradientIsTheDerivativeOfTheSplitPotential) {
  const NonlinearString string(c3(), 40);
  const Eigen::Index n = string.size(), half = n / 2;
  Vector grad(n);
  for (unsigned seed = 0; seed < 4; ++seed) {
    Vector q = randomVector(n, 3e-3, seed);
    q.tail(half) *= 1e-3;
    const double v = string.splitGradient(q, grad);
    EXPECT_DOUBLE_EQ(v, string.splitPotential(q));
    testing::expectGradientIsDerivative([&](const Vector& x) { return string.splitPotential(x); },
                                        grad, q,
                                        [&](Eigen::Index j) { return j < half ? 1e-7 : 1e-10; },
                                        1e-6, 1e-9 * grad.cwiseAbs().maxCoeff());
  }
}

TEST(NonlinearString, SplitPotentialIsTheGeometricExcessEnergy) {
  // u_1 = a alone: segments 1 and 2 get ζ = ±a/h and η = 0, so s − 1 = (a/h)² / (s + 1).
  const NonlinearString string(c3(false), 4);
  Vector q = Vector::Zero(string.size());
  const double a = 1e-3, h = string.spacing();
  q[0] = a;
  const double z2 = (a / h) * (a / h);
  const double excess = z2 / (std::sqrt(1.0 + z2) + 1.0);
  const double expected = h * (2.02e11 * 8.87e-7 - 759.0) / 2.0 * 2.0 * excess * excess;
  EXPECT_NEAR(string.splitPotential(q), expected, 1e-12 * expected);
}

TEST(NonlinearString, StiffnessHasTheClosedFormSpectrum) {
  const NonlinearString string(c3(), 30);
  const Eigen::MatrixXd k =
      matrixOf(string, [&](const Vector& x, Vector& y) { string.applyStiffness(x, y); });
  EXPECT_LE((k - k.transpose()).cwiseAbs().maxCoeff(), 1e-12 * k.cwiseAbs().maxCoeff());
  // M⁻¹K eigenvalues: the transverse and the longitudinal families of the header.
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(k * string.inverseMass()[0]);
  std::vector<double> expected;
  for (int m = 1; m < string.segments(); ++m) {
    expected.push_back(string.transverseEigenvalue(m));
    expected.push_back(string.longitudinalEigenvalue(m));
  }
  std::sort(expected.begin(), expected.end());
  for (size_t i = 0; i < expected.size(); ++i)
    EXPECT_NEAR(eig.eigenvalues()[static_cast<Eigen::Index>(i)], expected[i],
                1e-9 * expected.back());
  EXPECT_NEAR(eig.eigenvalues().maxCoeff(), string.stiffnessEigenvalueMax(),
              1e-9 * expected.back());
}

TEST(NonlinearString, LossOperatorIsMinusRhoAhD2OfTheDifference) {
  const NonlinearString string(c3(), 12);
  const Eigen::Index n = string.size();
  const Vector a = randomVector(n, 1.0, 7), b = randomVector(n, 1.0, 8);
  Vector out(n);
  string.applyLossOperator(a, b, out);
  const Eigen::MatrixXd c = matrixOf(
      string, [&](const Vector& x, Vector& y) { string.applyLossOperator(x, Vector::Zero(n), y); });
  EXPECT_LE((c * (a - b) - out).cwiseAbs().maxCoeff(), 1e-12 * out.cwiseAbs().maxCoeff());
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(c * string.inverseMass()[0]);
  EXPECT_GE(eig.eigenvalues().minCoeff(), 0.0);
  EXPECT_NEAR(eig.eigenvalues().maxCoeff(), string.lossOperatorEigenvalueMax(),
              1e-9 * string.lossOperatorEigenvalueMax());
}

// The paper's first-mode start (70) at α = 300 and the extreme α = 1000 (u = 0.94 m on a 1.26 m
// string), on the transverse grid at 48 kHz where the longitudinal wave is far from resolved:
// (38) keeps its energy (41) for 2 s and the state finite. Roundoff: ~1e5 steps.
TEST(NonlinearString, LargeAmplitudeStartsConserveEnergyAtAudioRate) {
  const double k = 1.0 / 48000.0;
  const StringPhysics p = c3();
  const NonlinearString string(p, gridSegments(p, GridRule::transverse, k, 0.0, 1.0));
  for (double alpha : {300.0, 1000.0}) {
    Vector u = Vector::Zero(string.size());
    for (int j = 1; j < string.segments(); ++j)
      u[j - 1] = alpha * std::sqrt(p.area) * std::sin(std::numbers::pi * j / string.segments());
    SplitSav<NonlinearString> scheme(string, {.k = k}, {u, Vector::Zero(string.size())});
    const double h0 = scheme.energy().total();
    double worst = 0.0;
    for (long n = 0; n < 96000; ++n) {
      scheme.step();
      worst = std::max(worst, std::abs(scheme.energy().total() - h0) / h0);
    }
    EXPECT_LE(worst, 1e-10) << "alpha " << alpha;
    EXPECT_TRUE(scheme.qNext().allFinite()) << "alpha " << alpha;
  }
}

// Both losses at audio rate on the string alone, from the α = 10 start: the energy never
// rises and the balance (50) closes over 2 s.
TEST(NonlinearString, LossBalanceClosesAtAudioRate) {
  const double k = 1.0 / 48000.0, sigma1 = 1e-3;
  const StringPhysics p = c3();
  const NonlinearString string(p, gridSegments(p, GridRule::transverse, k, sigma1, 1.0));
  Vector u = Vector::Zero(string.size());
  for (int j = 1; j < string.segments(); ++j)
    u[j - 1] = 10.0 * std::sqrt(p.area) * std::sin(std::numbers::pi * j / string.segments());
  SplitSav<NonlinearString> scheme(string, {.k = k, .sigma0 = 1.0, .sigma1 = sigma1},
                                   {u, Vector::Zero(string.size())});
  const testing::Balance b = testing::runBalance(scheme, 96000);
  EXPECT_LE(b.worstIncrease, 1e-14);
  EXPECT_LE(b.worstBalance, 1e-10);
  EXPECT_LT(b.final, 0.1 * b.initial);
}

// The extremes of the keyboard, tuned, on the transverse grid at 44.1 and 192 kHz, started at
// α = 1000: finite, and (41) kept to 1e-10 over 0.3 s.
TEST(NonlinearString, KeyboardExtremesAtAlpha1000) {
  for (double rate : {44100.0, 192000.0}) {
    for (int note : {21, 108}) {
      const double k = 1.0 / rate;
      const TunedString tuned = tuneString(pianoString(note), TuneBy::tension, GridRule::transverse,
                                           k, 0.0, 1.0, equalTemperament(note));
      const NonlinearString string(tuned.physics, tuned.segments);
      Vector u = Vector::Zero(string.size());
      for (int j = 1; j < string.segments(); ++j)
        u[j - 1] = 1000.0 * std::sqrt(tuned.physics.area) *
                   std::sin(std::numbers::pi * j / string.segments());
      SplitSav<NonlinearString> scheme(string, {.k = k}, {u, Vector::Zero(string.size())});
      const double h0 = scheme.energy().total();
      double worst = 0.0;
      for (long n = 0; n < std::lround(0.3 * rate); ++n) {
        scheme.step();
        worst = std::max(worst, std::abs(scheme.energy().total() - h0) / h0);
      }
      EXPECT_LE(worst, 1e-10) << note << " at " << rate;
      EXPECT_TRUE(scheme.qNext().allFinite()) << note << " at " << rate;
    }
  }
}

TEST(NonlinearString, RefusesUnphysicalStrings) {
  auto with = [](auto change) {
    StringPhysics p = c3();
    change(p);
    return p;
  };
  EXPECT_THROW(NonlinearString(with([](auto& p) { p.density = 0; }), 10), std::invalid_argument);
  EXPECT_THROW(NonlinearString(with([](auto& p) { p.area = -1; }), 10), std::invalid_argument);
  EXPECT_THROW(NonlinearString(with([](auto& p) { p.length = NAN; }), 10), std::invalid_argument);
  EXPECT_THROW(NonlinearString(with([](auto& p) { p.inertia = -1; }), 10), std::invalid_argument);
  try {
    NonlinearString(with([](auto& p) { p.tension = 2e5; }), 10);  // EA ≈ 1.79e5 N
    FAIL() << "EA <= T0 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("tension"), std::string::npos) << e.what();
  }
  EXPECT_THROW(NonlinearString(c3(), 1), std::invalid_argument);
}

}  // namespace
}  // namespace hamiltone
