// The von Kármán plate: the Airy solve is exact, ∇V' = −h² ℓ(q, F) is the derivative of V' (so
// the misprint in (78) is corrected), (38) conserves (41) through turbulence, the linear modes
// are the closed-form ones, and large amplitude shortens the period (BDZ §4.3).
#include "instruments/plate.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "schemes/sav.h"
#include "schemes/stormer_verlet.h"
#include "support/energy_checks.h"
#include "support/modal.h"

namespace hamiltone {
namespace {

// The paper's steel plate on the grid (84) gives for k.
VonKarmanPlate paperPlate(double k) {
  const PlatePhysics p;
  return VonKarmanPlate(p, plateSegments(p, p.lx, k, 1.0), plateSegments(p, p.ly, k, 1.0));
}

TEST(VonKarmanPlate, AirySolveIsExact) {
  const VonKarmanPlate plate(PlatePhysics{}, 13, 9);
  const Vector rhs = testing::randomVector(plate.size(), 1.0, 4);
  Vector f(plate.size()), lap(plate.size()), back(plate.size());
  plate.solveBiharmonic(rhs, f);
  plate.laplacian(f, lap);
  plate.laplacian(lap, back);
  EXPECT_LE((back - rhs).norm(), 1e-12 * rhs.norm());
}

// States of a few plate thicknesses: the nonlinearity is fully engaged. V' is quartic in q, so a
// central difference with δ = 1e-6 ξ is exact to ~1e-12 relative; the floor covers roundoff.
TEST(VonKarmanPlate, GradientIsTheDerivativeOfTheSplitPotential) {
  const VonKarmanPlate plate(PlatePhysics{}, 10, 8);
  Vector grad(plate.size());
  for (unsigned seed = 0; seed < 3; ++seed) {
    const Vector q = testing::randomVector(plate.size(), 3e-3, seed);
    const double v = plate.splitGradient(q, grad);
    EXPECT_DOUBLE_EQ(v, plate.splitPotential(q));
    testing::expectGradientIsDerivative([&](const Vector& x) { return plate.splitPotential(x); },
                                        grad, q, [](Eigen::Index) { return 2e-9; }, 1e-6,
                                        1e-9 * grad.cwiseAbs().maxCoeff());
  }
}

// BDZ Fig. 11: α = 10 (turbulent) at k = 1e-5, and at 48 kHz, over 0.5 s.
TEST(VonKarmanPlate, SplitSchemeConservesEnergyThroughTurbulence) {
  for (double k : {1e-5, 1.0 / 48000.0}) {
    const VonKarmanPlate plate = paperPlate(k);
    SplitSav<VonKarmanPlate> scheme(plate, {.k = k},
                                    {plateFirstMode(plate, 10.0), Vector::Zero(plate.size())});
    const testing::Balance b = testing::runBalance(scheme, std::lround(0.5 / k));
    EXPECT_LE(b.worstBalance, 1e-10) << "k " << k;
    EXPECT_TRUE(scheme.qNext().allFinite());
  }
}

TEST(VonKarmanPlate, LossNeverAddsEnergyAndTheBalanceCloses) {
  const double k = 1.0 / 48000.0;
  const VonKarmanPlate plate = paperPlate(k);
  SplitSav<VonKarmanPlate> scheme(plate, {.k = k, .sigma0 = 2.0, .sigma1 = 1e-3},
                                  {plateFirstMode(plate, 5.0), Vector::Zero(plate.size())});
  const testing::Balance b = testing::runBalance(scheme, 24000);
  EXPECT_LE(b.worstIncrease, 1e-14);
  EXPECT_LE(b.worstBalance, 1e-10);
  EXPECT_LT(b.final, 0.5 * b.initial);
}

// Mode (i, j) of the linear scheme: f = (1/πk) arcsin(k sqrt(λ)/2), λ = (D/ρξ) μ_ij², μ the
// −DΔ eigenvalue. Started in the six lowest modes, each measured by projection onto
// sin(iπx/Lx) sin(jπy/Ly). Amplitude 1e-3 ξ per mode: the von Kármán shift grows as
// (amplitude/ξ)², 1e-6 here (0.002 cent); at α = 0.01 it is already ~1e-4, 0.2 cent.
TEST(VonKarmanPlate, LinearModesAreTheClosedFormOnes) {
  const double k = 1e-5;
  const PlatePhysics p;
  const VonKarmanPlate plate(p, 12, 10);  // finer than (84) needs; a rectangle of 11 × 9 points
  const double kappa2 = p.rigidity() / (p.density * p.thickness);
  struct Mode {
    int i, j;
    double f;
  };
  std::vector<Mode> modes;
  for (int i = 1; i <= plate.nx(); ++i)
    for (int j = 1; j <= plate.ny(); ++j) {
      const double lambda = kappa2 * std::pow(plate.laplacianEigenvalue(i, j), 2);
      modes.push_back({i, j, std::asin(0.5 * k * std::sqrt(lambda)) / (std::numbers::pi * k)});
    }
  std::sort(modes.begin(), modes.end(), [](const Mode& a, const Mode& b) { return a.f < b.f; });
  modes.resize(6);
  auto shape = [&](int i, int j, int l, int m) {
    return std::sin(std::numbers::pi * i * (l + 1) / (plate.nx() + 1)) *
           std::sin(std::numbers::pi * j * (m + 1) / (plate.ny() + 1));
  };
  Vector q = Vector::Zero(plate.size());
  for (const Mode& mode : modes)
    for (int m = 0; m < plate.ny(); ++m)
      for (int l = 0; l < plate.nx(); ++l)
        q[l + plate.nx() * m] += 1e-3 * p.thickness * shape(mode.i, mode.j, l, m);
  SplitSav<VonKarmanPlate> scheme(plate, {.k = k}, {q, Vector::Zero(plate.size())});
  std::vector<std::vector<double>> amplitude(6);
  for (int n = 0; n < 40000; ++n) {
    for (size_t a = 0; a < modes.size(); ++a) {
      double s = 0.0;
      for (int m = 0; m < plate.ny(); ++m)
        for (int l = 0; l < plate.nx(); ++l)
          s += scheme.q()[l + plate.nx() * m] * shape(modes[a].i, modes[a].j, l, m);
      amplitude[a].push_back(s);
    }
    scheme.step();
  }
  for (size_t a = 0; a < modes.size(); ++a) {
    const double f = testing::zeroCrossingFrequency(amplitude[a], k);
    EXPECT_NEAR(testing::cents(f, modes[a].f), 0.0, 0.1)
        << "mode " << modes[a].i << "," << modes[a].j;
    // And near the continuous plate's ω_mn = sqrt(D/ρξ)((mπ/Lx)² + (nπ/Ly)²): the 5-point
    // Laplacian lowers each direction's term by at most (mπ/M)²/12 relative, and so f.
    const double continuous = std::sqrt(kappa2) *
                              (std::pow(modes[a].i * std::numbers::pi / p.lx, 2) +
                               std::pow(modes[a].j * std::numbers::pi / p.ly, 2)) /
                              (2.0 * std::numbers::pi);
    const double bound = std::numbers::pi * std::numbers::pi / 12.0 *
                         std::max(std::pow(modes[a].i / (plate.nx() + 1.0), 2),
                                  std::pow(modes[a].j / (plate.ny() + 1.0), 2));
    EXPECT_LT(f, continuous * 1.001) << "mode " << modes[a].i << "," << modes[a].j;
    EXPECT_GT(f, continuous * (1.0 - bound)) << "mode " << modes[a].i << "," << modes[a].j;
  }
}

// BDZ §4.3.3: at α = 2 (amplitude near the thickness) the period is shorter than at α = 0.01.
// On a grid twice as coarse as (84) allows (21 × 21 points): the first mode needs no more.
TEST(VonKarmanPlate, LargeAmplitudeShortensThePeriod) {
  const double k = 1e-5;
  const PlatePhysics p;
  const int segments = plateSegments(p, p.lx, k, 2.0);
  const VonKarmanPlate plate(p, segments, segments);
  const Eigen::Index centre = plate.nx() / 2 + plate.nx() * (plate.ny() / 2);
  auto frequency = [&](double alpha) {
    SplitSav<VonKarmanPlate> scheme(plate, {.k = k},
                                    {plateFirstMode(plate, alpha), Vector::Zero(plate.size())});
    std::vector<double> x;
    for (int n = 0; n < 20000; ++n) {
      x.push_back(scheme.q()[centre]);
      scheme.step();
    }
    return testing::zeroCrossingFrequency(x, k);
  };
  EXPECT_GT(frequency(2.0), 1.1 * frequency(0.01));
}

// BDZ Fig. 9: at α = 10 the split scheme converges to Störmer–Verlet at k = 2.5e-6 on the
// grid (84) gives for k = 1e-5. Over 2 ms the centre's error at k = 1e-5, 5e-6 falls about
// 5× — (16 − 1)/(4 − 1), the reference's own O(k²) error included.
TEST(VonKarmanPlate, TurbulentRunConvergesToTheReference) {
  const VonKarmanPlate plate = paperPlate(1e-5);
  const InitialState start{plateFirstMode(plate, 10.0), Vector::Zero(plate.size())};
  const Eigen::Index centre = plate.nx() / 2 + plate.nx() * (plate.ny() / 2);
  auto probe = [&](auto scheme, double k) {
    std::vector<double> x;
    for (long n = 0; n <= std::lround(2e-3 / k); ++n) {
      x.push_back(scheme.q()[centre]);
      scheme.step();
    }
    return x;
  };
  const double kRef = 2.5e-6;
  const auto ref = probe(StormerVerlet<VonKarmanPlate>(plate, {.k = kRef}, start), kRef);
  auto error = [&](int multiple) {
    const auto x =
        probe(SplitSav<VonKarmanPlate>(plate, {.k = multiple * kRef}, start), multiple * kRef);
    double e = 0.0, norm = 0.0;
    for (size_t n = 0; n < x.size(); ++n) {
      e += std::pow(x[n] - ref[n * multiple], 2);
      norm += ref[n * multiple] * ref[n * multiple];
    }
    return std::sqrt(e / norm);
  };
  EXPECT_NEAR(error(4) / error(2), 5.0, 1.0);
}

// And it stays stable at α = 10 at 44.1 kHz, on its grid, for 0.2 s.
TEST(VonKarmanPlate, TurbulentRunIsStableAtAudioRate) {
  const double k = 1.0 / 44100.0;
  const VonKarmanPlate plate = paperPlate(k);
  SplitSav<VonKarmanPlate> scheme(plate, {.k = k},
                                  {plateFirstMode(plate, 10.0), Vector::Zero(plate.size())});
  const testing::Balance b = testing::runBalance(scheme, 8820);
  EXPECT_LE(b.worstBalance, 1e-10);
  EXPECT_TRUE(scheme.qNext().allFinite());
}

TEST(VonKarmanPlate, RefusesUnphysicalPlates) {
  PlatePhysics p;
  p.poisson = 0.5;
  EXPECT_THROW(VonKarmanPlate(p, 10, 10), std::invalid_argument);
  EXPECT_THROW(VonKarmanPlate(PlatePhysics{}, 1, 10), std::invalid_argument);
  PlatePhysics thin;
  thin.thickness = -1.0;
  EXPECT_THROW(VonKarmanPlate(thin, 10, 10), std::invalid_argument);
  EXPECT_THROW(plateSegments(PlatePhysics{}, 0.5, 1.0, 1.0), std::invalid_argument);
}

}  // namespace
}  // namespace hamiltone
