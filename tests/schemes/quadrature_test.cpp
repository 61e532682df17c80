// The quadratures of Marazzato's scheme: symmetric [M 11], of the degree [M Remark 2] states.
#include "schemes/quadrature.h"

#include <gtest/gtest.h>

#include <cmath>

namespace hamiltone {
namespace {

double integrate(const Quadrature& q, int degree) {
  double s = 0.0;
  for (int i = 0; i < q.count; ++i) s += q.weight[i] * std::pow(q.node[i], degree);
  return s;
}

constexpr QuadratureRule kRules[] = {QuadratureRule::midpoint,       QuadratureRule::gaussLegendre2,
                                     QuadratureRule::gaussLegendre3, QuadratureRule::gaussLegendre5,
                                     QuadratureRule::lobatto3,       QuadratureRule::lobatto5};

TEST(Quadrature, ExactUpToItsDegreeAndNoFurther) {
  for (QuadratureRule rule : kRules) {
    const Quadrature q = quadrature(rule);
    for (int d = 0; d <= q.exactDegree; ++d)
      EXPECT_NEAR(integrate(q, d), 1.0 / (d + 1), 1e-15) << name(rule) << " degree " << d;
    // One degree more is not exact: the stated degree is the rule's true degree.
    EXPECT_GT(std::abs(integrate(q, q.exactDegree + 1) - 1.0 / (q.exactDegree + 2)), 1e-6)
        << name(rule);
  }
}

TEST(Quadrature, IsSymmetric) {
  for (QuadratureRule rule : kRules) {
    const Quadrature q = quadrature(rule);
    for (int i = 0; i < q.count; ++i) {
      bool mirrored = false;
      for (int j = 0; j < q.count; ++j)
        mirrored |= std::abs(q.node[j] - (1.0 - q.node[i])) < 1e-15 && q.weight[j] == q.weight[i];
      EXPECT_TRUE(mirrored) << name(rule) << " node " << q.node[i];
    }
  }
}

TEST(Quadrature, NodeCountsAndNames) {
  EXPECT_EQ(quadrature(QuadratureRule::midpoint).count, 1);
  EXPECT_EQ(quadrature(QuadratureRule::gaussLegendre5).count, 5);
  EXPECT_EQ(quadrature(QuadratureRule::lobatto3).count, 3);
  for (QuadratureRule rule : kRules) EXPECT_EQ(parseQuadratureRule(name(rule)), rule);
  EXPECT_FALSE(parseQuadratureRule("simpson").has_value());
}

}  // namespace
}  // namespace hamiltone
