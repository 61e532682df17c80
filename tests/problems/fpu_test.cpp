// The FPU chain: the split (53) adds up to (52), its gradient is the derivative of its potential,
// and its stiffness matrix has the spectrum that gives the bound (54).
#include "problems/fpu.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <random>

#include "support/energy_checks.h"

namespace hamiltone {
namespace {

using testing::randomVector;

Eigen::MatrixXd stiffnessMatrix(const FermiPastaUlam& chain) {
  const Eigen::Index n = chain.size();
  Eigen::MatrixXd k(n, n);
  Vector e(n), col(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    e.setZero();
    e[j] = 1.0;
    chain.applyStiffness(e, col);
    k.col(j) = col;
  }
  return k;
}

TEST(FermiPastaUlam, SplitPotentialAddsUpToThePaperPotential) {
  for (int pairs : {1, 3, 10}) {
    FermiPastaUlam chain(pairs, 50.0);
    Vector kq(chain.size());
    for (unsigned seed = 0; seed < 5; ++seed) {
      const Vector q = randomVector(chain.size(), 2.0, seed);
      chain.applyStiffness(q, kq);
      const double split = 0.5 * q.dot(kq) + chain.splitPotential(q);  // (53)
      // Both sums are of positive terms: agreement to a few ulps of the total.
      EXPECT_NEAR(split, chain.potential(q), 1e-13 * chain.potential(q)) << "pairs " << pairs;
    }
  }
}

TEST(FermiPastaUlam, GradientIsTheDerivativeOfThePotential) {
  FermiPastaUlam chain(5, 50.0);
  Vector grad(chain.size());
  for (unsigned seed = 0; seed < 5; ++seed) {
    Vector q = randomVector(chain.size(), 1.5, seed);
    const double v = chain.splitGradient(q, grad);
    EXPECT_DOUBLE_EQ(v, chain.splitPotential(q));
    // Central differences: error O(δ²) times the third derivative (~24 e), roundoff ~ 1e-16 V / δ.
    testing::expectGradientIsDerivative([&](const Vector& x) { return chain.splitPotential(x); },
                                        grad, q, [](Eigen::Index) { return 1e-5; }, 1e-6,
                                        1e-9 * grad.cwiseAbs().maxCoeff());
  }
}

TEST(FermiPastaUlam, StiffnessIsSymmetricPsdWithLargestEigenvalueOmegaSquared) {
  FermiPastaUlam chain(4, 50.0);
  const Eigen::MatrixXd k = stiffnessMatrix(chain);
  EXPECT_EQ((k - k.transpose()).norm(), 0.0);
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(k);
  EXPECT_GE(eig.eigenvalues().minCoeff(), -1e-12);
  EXPECT_NEAR(eig.eigenvalues().maxCoeff(), chain.stiffnessEigenvalueMax(), 1e-9);
  EXPECT_DOUBLE_EQ(chain.stiffnessEigenvalueMax(), 2500.0);
}

TEST(FermiPastaUlam, InitialStateDisplacesTheFourthCoordinate) {
  FermiPastaUlam chain(3, 50.0);
  const InitialState s = fpuInitialState(chain, 10.0);
  Vector expected = Vector::Zero(6);
  expected[3] = 10.0;
  EXPECT_EQ(s.q, expected);
  EXPECT_EQ(s.p, Vector::Zero(6));
}

TEST(FermiPastaUlam, RejectsInvalidParameters) {
  EXPECT_THROW(FermiPastaUlam(0, 50.0), std::invalid_argument);
  EXPECT_THROW(FermiPastaUlam(3, 0.0), std::invalid_argument);
  EXPECT_THROW(FermiPastaUlam(3, std::nan("")), std::invalid_argument);
  EXPECT_THROW(fpuInitialState(FermiPastaUlam(1, 50.0), 1.0), std::invalid_argument);
  EXPECT_THROW(fpuInitialState(FermiPastaUlam(3, 50.0), INFINITY), std::invalid_argument);
}

}  // namespace
}  // namespace hamiltone
