// The string model: ∇V' is the derivative of V' (65) and of its two-grid form (SCHEMES §3b), K has
// the closed-form spectrum the tuning and the bound (44) rely on, the loss operator is −ρA h D2 on
// each grid, one coarse cell is the Kirchhoff–Carrier string, the grid rules size the grids as
// documented, and unphysical strings are refused.
#include "instruments/string.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <random>

#include "instruments/piano_scale.h"
#include "instruments/string_tuning.h"
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
// On the single grid of (65), on nested grids of 5 and 8 fine segments per cell, and on one cell
// (of 40, 3 and 2 segments: the in-place sweeps of oneCell with their ends).
TEST(NonlinearString, GradientIsTheDerivativeOfTheSplitPotential) {
  for (const StringGrid grid : {StringGrid{40, 40}, StringGrid{40, 8}, StringGrid{40, 5},
                                StringGrid{40, 1}, StringGrid{2, 1}, StringGrid{3, 1}}) {
    const NonlinearString string(c3(), grid);
    const Eigen::Index n = string.size(), nu = string.transverseSize();
    Vector grad(n);
    for (unsigned seed = 0; seed < 4; ++seed) {
      Vector q = randomVector(n, 3e-3, seed);
      q.tail(n - nu) *= 1e-3;
      const double v = string.splitGradient(q, grad);
      EXPECT_DOUBLE_EQ(v, string.splitPotential(q));
      testing::expectGradientIsDerivative([&](const Vector& x) { return string.splitPotential(x); },
                                          grad, q,
                                          [&](Eigen::Index j) { return j < nu ? 1e-7 : 1e-10; },
                                          1e-6, 1e-9 * grad.cwiseAbs().maxCoeff());
    }
  }
}

// A cell's strain: with every fine segment of a cell stretched alike (the same |ζ|) its mean
// square slope gives that stretch, so V' of the nested grids equals V' of the single grid whose v
// follows the coarse one — here u is a triangle whose kinks sit on the cell boundaries (|ζ| the
// same in each cell) and v is linear in each cell.
TEST(NonlinearString, TwoGridPotentialIsTheSingleGridsWhereEachCellStretchesAlike) {
  const int r = 4, mv = 6, mu = r * mv;
  const NonlinearString nested(c3(), StringGrid{mu, mv}), single(c3(), mu);
  Vector qn = Vector::Zero(nested.size()), qs = Vector::Zero(single.size());
  const double peak = 4e-3, stretch = 2e-6;
  for (int j = 1; j < mu; ++j) {  // u: up over the first half, down over the second
    qn[j - 1] = qs[j - 1] = peak * (j <= mu / 2 ? j : mu - j) / (mu / 2.0);
  }
  for (int cell = 1; cell < mv; ++cell)  // v at the coarse points, a zigzag
    qn[mu - 1 + cell - 1] = stretch * (cell % 2);
  for (int j = 1; j < mu; ++j)  // the same v, linear in each cell, on the fine grid
    qs[mu - 1 + j - 1] = stretch * (j / r % 2 == 0 ? double(j % r) / r : 1.0 - double(j % r) / r);
  EXPECT_NEAR(nested.splitPotential(qn), single.splitPotential(qs),
              1e-12 * single.splitPotential(qs));
}

// Hooke at the end: u at rest and v rising by ε0 h_v a cell up to the last node, the end held at
// 0, so the last cell falls back: η_M = −ε0 (Mv − 1). With u at rest every s_l = 1 + η_J, so ε_J
// = η_J, and the pull on the far end is T0 η_M + (EA − T0) ε_M (1 + η_M)/(1 + η_M) = EA η_M:
// Hooke's law with the last cell's strain, on either grid.
TEST(NonlinearString, EndTensionIsHookesLawOfTheLastCell) {
  const StringPhysics p = c3();
  const double ea = p.young * p.area;
  for (const StringGrid grid : {StringGrid{24, 24}, StringGrid{24, 6}}) {
    const NonlinearString string(p, grid);
    Vector q = Vector::Zero(string.size());
    const double eps0 = 3e-5, hv = string.longitudinalSpacing();
    const int mv = grid.longitudinal;
    for (int j = 1; j < mv; ++j) q[grid.transverse - 1 + j - 1] = eps0 * j * hv;
    Vector grad(string.size());
    string.splitGradient(q, grad);
    const double last = -eps0 * (mv - 1);  // η_M = (0 − v_{M−1}) / h_v
    EXPECT_NEAR(string.endTension(), ea * last, 1e-9 * ea * std::abs(last))
        << "Mu = " << grid.transverse << ", Mv = " << mv;
  }
}

// The linear string (the linear tail): its K is the geometric K plus the Hessian of V' at rest —
// only v's block, at EA − T0, since V' is quartic in u there — taken by central differences of
// ∇V' at q = 0 (V' is smooth, so O(δ²) against roundoff ~1e-16 |∇V'|/δ: 1e-6 of the column's
// largest entry). Its end tension is Hooke's EA η_M, which the geometric string's tends to at
// small strain (the case of EndTensionIsHookesLawOfTheLastCell, with u moving too).
TEST(NonlinearString, TheLinearStringTakesTheHessianOfVPrimeAtRestIntoK) {
  for (const StringGrid grid : {StringGrid{24, 24}, StringGrid{24, 6}, StringGrid{24, 1}}) {
    NonlinearString string(c3(), grid);
    const Eigen::MatrixXd k =
        matrixOf(string, [&](const Vector& e, Vector& out) { string.applyStiffness(e, out); });
    string.setLinearised(true);
    const Eigen::MatrixXd linear =
        matrixOf(string, [&](const Vector& e, Vector& out) { string.applyStiffness(e, out); });
    string.setLinearised(false);
    const Eigen::Index n = string.size();
    Eigen::MatrixXd hessian(n, n);
    Vector plus(n), minus(n);
    for (Eigen::Index j = 0; j < n; ++j) {
      const double delta = 1e-6 * string.spacing();
      Vector q = Vector::Zero(n);
      q[j] = delta;
      string.splitGradient(q, plus);
      q[j] = -delta;
      string.splitGradient(q, minus);
      hessian.col(j) = (plus - minus) / (2.0 * delta);
    }
    const double scale = linear.cwiseAbs().maxCoeff();
    EXPECT_LE((linear - k - hessian).cwiseAbs().maxCoeff(), 1e-6 * scale)
        << "Mu = " << grid.transverse << ", Mv = " << grid.longitudinal;
    EXPECT_LE(hessian.topLeftCorner(23, 23).cwiseAbs().maxCoeff(), 1e-9 * scale);
  }
  const StringPhysics p = c3();
  const NonlinearString string(p, StringGrid{24, 6});
  Vector q = 1e-6 * randomVector(string.size(), 1.0, 3);
  q.head(string.transverseSize()) *= 1e-3;  // u's slopes' share is of second order
  Vector grad(string.size());
  string.splitGradient(q, grad);
  EXPECT_NEAR(string.linearEndTension(q), string.endTension(),
              1e-4 * std::abs(string.linearEndTension(q)));
}

// The linear string is stable where v's grid resolves the longitudinal wave at EA (h_v >= c_L k),
// and not on the single grid at the transverse bound (c_L k / h ≈ 15 at 48 kHz): there the linear
// tail is never taken.
TEST(NonlinearString, TheLinearStringIsStableOnlyWhereVResolvesTheLongitudinalWave) {
  const StringPhysics p = c3();
  const double k = 1.0 / 48000.0;
  const double cL = std::sqrt(p.young / p.density);
  const int mv = static_cast<int>(std::floor(p.length / (1.05 * cL * k)));
  const NonlinearString two(p, StringGrid{mv * 6, mv});
  EXPECT_GE(two.linearisedMaxStableStep(0.0), k);
  const int fine = gridSegments(p, GridRule::transverse, k, 0.0, kOffTheBound);
  const NonlinearString single(p, fine);
  EXPECT_GE(single.maxStableStep(0.0), k);
  EXPECT_LT(single.linearisedMaxStableStep(0.0), 0.2 * k);
}

// Mv = 1 leaves no longitudinal unknown: V' = (EA − T0) L ε² / 2 with ε = S − 1, S = sqrt(1 + Z),
// Z = (1/M) Σ ζ_l² the string's mean square slope, and the force on u is that of the extra tension
// (EA − T0) ε along the string: ∂V'/∂ζ_l = h (EA − T0) ε ζ_l / S. To leading order ε = Z/2 =
// (1/2L) ∫ u_x² dx: Kirchhoff–Carrier's tension from the mean strain, the same everywhere.
TEST(NonlinearString, OneCellIsTheKirchhoffCarrierString) {
  const StringPhysics p = c3();
  const int mu = 30;
  const NonlinearString string(p, StringGrid{mu, 1});
  ASSERT_EQ(string.size(), mu - 1);
  const Vector q = randomVector(string.size(), 5e-3, 3);
  const double h = string.spacing();
  std::vector<double> zeta(mu);
  double meanSquare = 0.0;
  for (int l = 0; l < mu; ++l) {
    zeta[l] = ((l < mu - 1 ? q[l] : 0.0) - (l > 0 ? q[l - 1] : 0.0)) / h;
    meanSquare += zeta[l] * zeta[l] / mu;
  }
  const double stretch = std::sqrt(1.0 + meanSquare), strain = stretch - 1.0;
  const double ea = p.young * p.area - p.tension;
  EXPECT_NEAR(strain, 0.5 * meanSquare, 0.2 * meanSquare * meanSquare);  // Z/2 − Z²/8 + …
  const double expected = 0.5 * ea * p.length * strain * strain;
  Vector grad(string.size());
  EXPECT_NEAR(string.splitGradient(q, grad), expected, 1e-9 * expected);
  // The pull on the end: the extra tension along the string's mean direction, (EA − T0) ε / S.
  EXPECT_NEAR(string.endTension(), ea * strain / stretch, 1e-9 * ea * strain);
  for (int j = 0; j < mu - 1; ++j) {  // D₋ᵀ of the segment forces
    const double force = ea * strain / stretch * (zeta[j] - zeta[j + 1]);
    EXPECT_NEAR(grad[j], force, 1e-9 * ea * strain) << j;
  }
}

// A cell's strain comes from its mean square slope, S = f(Z), f(x) = sqrt((1 + η)² + x), where
// the mean of the exact stretches of its segments (SCHEMES §3b) takes mean f(ζ_l²): f is concave,
// so S − 1 is the larger, by between min|f''|/2 · var(ζ²) and max|f''|/2 · var(ζ²), |f''(x)| =
// ((1 + η)² + x)^(−3/2) / 4 over 0 <= x <= max ζ². On a struck string's slopes of a few percent
// that is a few 1e-4 of the strain: the same geometric tension. One cell (η = 0), then two with the
// first compressed by 5 % under slopes of tens of percent and the second flat, whose strain is η₂
// on both forms and is taken out of V'.
TEST(NonlinearString, ACellsStrainIsTheMeanStretchWithinTheSlopesVariance) {
  const StringPhysics p = c3();
  const double ea = p.young * p.area - p.tension;
  const int mu = 24;
  for (const int mv : {1, 2}) {
    const NonlinearString string(p, StringGrid{mu, mv});
    const int r = mu / mv;
    const double h = string.spacing(), hv = string.longitudinalSpacing();
    const double eta = mv == 1 ? 0.0 : -0.05;
    for (unsigned seed = 0; seed < 4; ++seed) {
      Vector q = Vector::Zero(string.size());
      q.head(r - 1) = randomVector(r - 1, mv == 1 ? 2e-3 : 6e-2, seed);  // u inside cell 1
      if (mv == 2) q[mu - 1] = eta * hv;  // v_1: η₁ = −η₂ = η
      double z2 = 0.0, z4 = 0.0, meanStretch = 0.0, steepest = 0.0;
      for (int l = 0; l < r; ++l) {
        const double zeta = ((l < r - 1 ? q[l] : 0.0) - (l > 0 ? q[l - 1] : 0.0)) / h;
        steepest = std::max(steepest, zeta * zeta);
        z2 += zeta * zeta / r;
        z4 += zeta * zeta * zeta * zeta / r;
        meanStretch += (std::sqrt((1.0 + eta) * (1.0 + eta) + zeta * zeta) - 1.0) / r;
      }
      const double rest = mv == 1 ? 0.0 : eta * eta;  // the flat cell's ε₂² = η²
      const double strain = std::sqrt(2.0 * string.splitPotential(q) / (ea * hv) - rest);
      const double a = (1.0 + eta) * (1.0 + eta), variance = z4 - z2 * z2;
      const double most = variance / (8.0 * std::pow(a, 1.5)),
                   least = variance / (8.0 * std::pow(a + steepest, 1.5));
      ASSERT_GT(meanStretch, 0.0) << "the test wants the first cell stretched, mv = " << mv;
      EXPECT_GE(strain - meanStretch, least - 1e-9 * strain) << "mv = " << mv << ", seed " << seed;
      EXPECT_LE(strain - meanStretch, most + 1e-9 * strain) << "mv = " << mv << ", seed " << seed;
      if (mv == 1) {
        EXPECT_LT(strain - meanStretch, 1e-3 * strain) << seed;
      }
    }
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
  for (const StringGrid grid : {StringGrid{30, 30}, StringGrid{30, 6}, StringGrid{30, 1}}) {
    const NonlinearString string(c3(), grid);
    const Eigen::MatrixXd k =
        matrixOf(string, [&](const Vector& x, Vector& y) { string.applyStiffness(x, y); });
    EXPECT_LE((k - k.transpose()).cwiseAbs().maxCoeff(), 1e-12 * k.cwiseAbs().maxCoeff());
    // M⁻¹K eigenvalues (of the symmetric M^-½ K M^-½): the two families of the header.
    const Vector root = string.inverseMass().cwiseSqrt();
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(root.asDiagonal() * k * root.asDiagonal());
    std::vector<double> expected;
    for (int m = 1; m < grid.transverse; ++m) expected.push_back(string.transverseEigenvalue(m));
    for (int m = 1; m < grid.longitudinal; ++m)
      expected.push_back(string.longitudinalEigenvalue(m));
    std::sort(expected.begin(), expected.end());
    for (size_t i = 0; i < expected.size(); ++i)
      EXPECT_NEAR(eig.eigenvalues()[static_cast<Eigen::Index>(i)], expected[i],
                  1e-9 * expected.back());
    EXPECT_NEAR(eig.eigenvalues().maxCoeff(), string.stiffnessEigenvalueMax(),
                1e-9 * expected.back());
  }
}

TEST(NonlinearString, LossOperatorIsMinusRhoAhD2OfTheDifference) {
  for (const StringGrid grid : {StringGrid{12, 12}, StringGrid{12, 4}}) {
    const NonlinearString string(c3(), grid);
    const Eigen::Index n = string.size();
    const Vector a = randomVector(n, 1.0, 7), b = randomVector(n, 1.0, 8);
    Vector out(n);
    string.applyLossOperator(a, b, out);
    const Eigen::MatrixXd c = matrixOf(string, [&](const Vector& x, Vector& y) {
      string.applyLossOperator(x, Vector::Zero(n), y);
    });
    EXPECT_LE((c * (a - b) - out).cwiseAbs().maxCoeff(), 1e-12 * out.cwiseAbs().maxCoeff());
    // M⁻¹C = −D2 on each grid: eigenvalues (4/h²) sin²(mπ/2M), the largest on u's grid.
    const Vector root = string.inverseMass().cwiseSqrt();
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(root.asDiagonal() * c * root.asDiagonal());
    EXPECT_GE(eig.eigenvalues().minCoeff(), 0.0);
    EXPECT_NEAR(eig.eigenvalues().maxCoeff(), string.lossOperatorEigenvalueMax(),
                1e-9 * string.lossOperatorEigenvalueMax());
    // The smallest is v's first mode: the coarser grid's −D2 sits further below (π/L)².
    const double hv = string.longitudinalSpacing();
    EXPECT_NEAR(
        eig.eigenvalues().minCoeff(),
        4.0 / (hv * hv) * std::pow(std::sin(std::numbers::pi / (2.0 * grid.longitudinal)), 2),
        1e-9 * string.lossOperatorEigenvalueMax())
        << grid.longitudinal;
  }
}

// The stiffness sweep's loss (applyStiffnessAndLoss): K q and C(q − qPrev) as applyStiffness and
// applyLossOperator give them, the loss's D2 qPrev/h² taken afresh or kept from the call before
// (prevKept), with u bent (K's β) and v's own law. C's u part is cl (d2(q) − d2(qPrev)) for the
// stencil's D2(q − qPrev)/h²: each d2 carries a few roundings of its own magnitude (four
// operations: <= 4 ulp), so the two differ by at most 8ε max|cl d2|; ask 16ε. K q is the same
// arithmetic. v's parts are the same operations, bit for bit, on every grid — those of up to
// kFewCoarseCells cells take one sweep of their own (coarseStiffnessAndLoss) — with and without
// the constant loss weight, and linearised (v's stiffness EA).
TEST(NonlinearString, TheStiffnessSweepsLossIsTheLossOperator) {
  for (const StringGrid grid :
       {StringGrid{24, 24}, StringGrid{24, 12}, StringGrid{24, 8}, StringGrid{24, 4},
        StringGrid{24, 3}, StringGrid{24, 2}, StringGrid{24, 1}})
    for (const NonlinearString::LossWeights weights :
         {NonlinearString::LossWeights{0.5, 3.0, 2.0}, NonlinearString::LossWeights{0.5, 0.0, 2.0}})
      for (const bool linear : {false, true}) {
        NonlinearString string(c3(), grid);
        string.setLossWeights(weights);
        string.setLinearised(linear);
        string.setTensionRange(1.2);
        string.setTensionScale(1.1);
        const Eigen::Index n = string.size(), nu = grid.transverse - 1;
        const Vector q0 = randomVector(n, 1e-3, 11), q1 = randomVector(n, 1e-3, 12),
                     q2 = q1 + randomVector(n, 1e-6, 13);  // a step's small change
        Vector kq(n), cq(n), kqRef(n), cqRef(n);
        const double h = string.spacing(), rhoA = c3().linearDensity();
        auto expectBoth = [&](const Vector& q, const Vector& qPrev, bool prevKept) {
          string.applyStiffnessAndLoss(q, qPrev, prevKept, kq, cq);
          string.applyStiffness(q, kqRef);
          string.applyLossOperator(q, qPrev, cqRef);
          EXPECT_LE((kq - kqRef).cwiseAbs().maxCoeff(), 1e-15 * kqRef.cwiseAbs().maxCoeff());
          EXPECT_EQ(kq.tail(n - nu), kqRef.tail(n - nu))
              << "v's stiffness: the same stencil, " << grid.longitudinal << " cells";
          auto d2Max = [&](const Vector& x) {  // max |D2 x/h²| on u
            double top = 0.0;
            for (Eigen::Index j = 0; j < nu; ++j)
              top = std::max(top, std::abs((j > 0 ? x[j - 1] : 0.0) - 2.0 * x[j] +
                                           (j + 1 < nu ? x[j + 1] : 0.0)) /
                                      (h * h));
            return top;
          };
          const double scale = 0.5 * rhoA * h * std::max(d2Max(q), d2Max(qPrev));  // |cl| max |d2|
          EXPECT_LE((cq - cqRef).head(nu).cwiseAbs().maxCoeff(),
                    16.0 * std::numeric_limits<double>::epsilon() * scale)
              << grid.longitudinal << (prevKept ? " kept" : " taken");
          EXPECT_EQ(cq.tail(n - nu), cqRef.tail(n - nu)) << "v's part: the same stencil";
        };
        expectBoth(q1, q0, false);  // D2 q0 taken here
        expectBoth(q2, q1, true);   // D2 q1 kept from the call before
        // Kept means the same bits as taken afresh.
        Vector kept = cq;
        string.applyStiffnessAndLoss(q1, q0, false, kq, cq);
        string.applyStiffnessAndLoss(q2, q1, false, kq, cq);
        EXPECT_EQ(kept, cq);
      }
}

// Each wave its own law: with weights (w_u, w_v0, w_v1), M⁻¹C is w_u (−D2) on u and w_v0 + w_v1
// (−D2) on v, so its eigenvalues are those of the two blocks, and the bound reports the larger top.
TEST(NonlinearString, WeightedLossOperatorGivesEachWaveItsLaw) {
  const StringGrid grid{12, 4};
  for (const NonlinearString::LossWeights w :
       {NonlinearString::LossWeights{0.25, 3.0, 2.0}, NonlinearString::LossWeights{1.0, 0.0, 40.0},
        NonlinearString::LossWeights{0.0, 5.0, 0.0}}) {
    NonlinearString string(c3(), grid);
    string.setLossWeights(w);
    const Eigen::Index n = string.size();
    const Eigen::MatrixXd c = matrixOf(string, [&](const Vector& x, Vector& y) {
      string.applyLossOperator(x, Vector::Zero(n), y);
    });
    const Vector root = string.inverseMass().cwiseSqrt();
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(root.asDiagonal() * c * root.asDiagonal());
    std::vector<double> expected;
    auto minusD2 = [](int m, int segments, double h) {
      return 4.0 / (h * h) * std::pow(std::sin(m * std::numbers::pi / (2.0 * segments)), 2);
    };
    for (int m = 1; m < grid.transverse; ++m)
      expected.push_back(w.transverse * minusD2(m, grid.transverse, string.spacing()));
    for (int m = 1; m < grid.longitudinal; ++m)
      expected.push_back(w.longitudinalConstant +
                         w.longitudinal *
                             minusD2(m, grid.longitudinal, string.longitudinalSpacing()));
    std::sort(expected.begin(), expected.end());
    const double top = expected.back();
    for (size_t i = 0; i < expected.size(); ++i)
      EXPECT_NEAR(eig.eigenvalues()[static_cast<Eigen::Index>(i)], expected[i], 1e-9 * top);
    EXPECT_NEAR(string.lossOperatorEigenvalueMax(), top, 1e-9 * top);
    // Applied to a difference, with the constant part too.
    const Vector a = randomVector(n, 1.0, 9), b = randomVector(n, 1.0, 10);
    Vector out(n);
    string.applyLossOperator(a, b, out);
    EXPECT_LE((c * (a - b) - out).cwiseAbs().maxCoeff(), 1e-12 * out.cwiseAbs().maxCoeff());
  }
  NonlinearString string(c3(), grid);
  for (const double bad : {-1.0, static_cast<double>(NAN), static_cast<double>(INFINITY)})
    EXPECT_THROW(string.setLossWeights({1.0, bad, 1.0}), std::invalid_argument) << bad;
}

// The bound (44) block by block: in each block K and C share their modes (sines of the block's
// grid), so the exact condition is k²λK/4 + σ1 k λC <= 1 mode by mode, and its tightest mode is
// each block's top one. With v's loss far above u's the string-wide maxima, u's stiffness with v's
// loss, give a lower bound than the truth — by 0.1 % here, enough to refuse RT-425's longitudinal
// law on a grid sized at the bound (paper-c3-string's transverse grid, hostile review).
TEST(NonlinearString, TheStabilityBoundIsTakenBlockByBlock) {
  const StringGrid grid{120, 12};
  NonlinearString string(c3(), grid);
  string.setLossWeights({1.0, 2000.0, 1000.0});
  const double sigma1 = 2.4e-4;
  double exact = INFINITY;
  const double hv = string.longitudinalSpacing();
  for (int m = 1; m < grid.transverse; ++m) {
    const double lc = 4.0 / std::pow(string.spacing(), 2) *
                      std::pow(std::sin(m * std::numbers::pi / (2.0 * grid.transverse)), 2);
    exact = std::min(exact, maxStableStep(string.transverseEigenvalue(m), lc, sigma1));
  }
  for (int m = 1; m < grid.longitudinal; ++m) {
    const double lc =
        2000.0 + 100.0 * 4.0 / (hv * hv) *
                     std::pow(std::sin(m * std::numbers::pi / (2.0 * grid.longitudinal)), 2);
    exact = std::min(exact, maxStableStep(string.longitudinalEigenvalue(m), lc, sigma1));
  }
  EXPECT_NEAR(string.maxStableStep(sigma1), exact, 1e-12 * exact);
  const double mixed =
      maxStableStep(string.stiffnessEigenvalueMax(), string.lossOperatorEigenvalueMax(), sigma1);
  std::printf("block by block %.6g s, string-wide %.6g s\n", exact, mixed);
  EXPECT_LT(mixed, (1.0 - 5e-4) * exact);
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
      const NonlinearString string(tuned.physics, tuned.grid);
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

// SCHEMES §3b's sizing on the paper's C3 at 48 kHz: v on floor(L / (1.05 c_L k)) = 11 cells
// (Courant c_L k / h_v <= 1/1.05), u on the finest grid the stiff-string bound allows at 1.5 T0
// (124 segments) rounded down to a multiple of 11: 121, 130 unknowns. Sized for T0 instead, u
// would have 136 segments. A treble string shorter than c_L k has a single cell (Mv = 1).
TEST(StringGrids, TwoGridsAreNestedAndSizedForTheDesignTension) {
  const double k = 1.0 / 48000.0;
  const StringPhysics p = c3();
  const double cL = std::sqrt(p.young / p.density);
  const StringGrid grid = stringGrid(p, GridRule::twoGrid, k, 0.0, 1.0, 1.5);
  EXPECT_EQ(grid.longitudinal, static_cast<int>(p.length / (1.05 * cL * k)));
  EXPECT_EQ(grid.longitudinal, 11);
  EXPECT_EQ(grid.transverse % grid.longitudinal, 0);
  StringPhysics design = p;
  design.tension *= 1.5;
  const int finest = gridSegments(design, GridRule::transverse, k, 0.0, 1.0);
  EXPECT_EQ(finest, 124);
  EXPECT_EQ(grid.transverse, finest / 11 * 11);
  EXPECT_LE(cL * k / (p.length / grid.longitudinal), 1.0 / 1.05 + 1e-12);
  EXPECT_GT(gridSegments(p, GridRule::transverse, k, 0.0, 1.0), grid.transverse);
  EXPECT_EQ(NonlinearString(p, grid).size(), 130);
  // The other rules keep one grid; the transverse one at least kOffTheBound off the bound.
  const StringGrid single = stringGrid(p, GridRule::transverse, k, 0.0, 1.0, 1.5);
  EXPECT_EQ(single.transverse, single.longitudinal);
  EXPECT_EQ(single.transverse, gridSegments(p, GridRule::transverse, k, 0.0, kOffTheBound));
  EXPECT_EQ(stringGrid(p, GridRule::transverse, k, 0.0, 1.12, 1.5).transverse,
            gridSegments(p, GridRule::transverse, k, 0.0, 1.12));
  StringPhysics treble = p;
  treble.length = 0.9 * cL * k;  // 9.5 cm
  EXPECT_EQ(stringGrid(treble, GridRule::twoGrid, k, 0.0, 1.0, 1.5).longitudinal, 1);
  EXPECT_THROW(stringGrid(p, GridRule::twoGrid, k, 0.0, 1.0, 0.9), std::invalid_argument);
  // A string whose longitudinal wave is under twice as fast as its transverse one (EA = 2.25 T0):
  // rounding u's grid down to a multiple of Mv would halve it; fewer, longer cells keep it.
  StringPhysics slack = p;
  slack.young = 2.25 * p.tension / p.area;
  StringPhysics slackDesign = slack;
  slackDesign.tension *= 1.5;
  const int slackFinest = gridSegments(slackDesign, GridRule::transverse, k, 0.0, 1.0);
  const StringGrid kept = stringGrid(slack, GridRule::twoGrid, k, 0.0, 1.0, 1.5);
  EXPECT_EQ(kept.transverse % kept.longitudinal, 0);
  EXPECT_GE(kept.transverse, slackFinest - 1);
  EXPECT_LE(std::sqrt(slack.young / slack.density) * k / (slack.length / kept.longitudinal),
            1.0 / 1.05 + 1e-12);
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
  EXPECT_THROW(NonlinearString(c3(), StringGrid{12, 5}), std::invalid_argument);  // not nested
  EXPECT_THROW(NonlinearString(c3(), StringGrid{12, 0}), std::invalid_argument);
}

}  // namespace
}  // namespace hamiltone
