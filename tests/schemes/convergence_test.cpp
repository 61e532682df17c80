// Second-order convergence of every scheme on FPU, BDZ Fig. 3: the L² error (55) over 1 s against
// Störmer–Verlet at k = 2⁻¹⁸, for k = 2⁻⁸ … 2⁻¹¹, α = 10.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "support/energy_checks.h"
#include "support/fpu_runs.h"

namespace hamiltone {
namespace {

using testing::paperChain;
using testing::stepsFor;

constexpr double kAlpha = 10.0;
constexpr int kReferenceLog2 = 18;

const std::vector<Vector>& reference() {
  static const std::vector<Vector> ref = [] {
    const FermiPastaUlam chain = paperChain();
    const double k = std::ldexp(1.0, -kReferenceLog2);
    StormerVerlet<FermiPastaUlam> sv(chain, {.k = k}, fpuInitialState(chain, kAlpha));
    return testing::trajectory(sv, stepsFor(1.0, k));
  }();
  return ref;
}

// (55): sqrt(Σ_n k ‖q^n − q_ref(n k)‖²). k = 2^−log2k, so q_ref(n k) is reference step
// n·2^(18−log2k).
double error55(const std::vector<Vector>& q, int log2k) {
  const double k = std::ldexp(1.0, -log2k);
  const long stride = 1L << (kReferenceLog2 - log2k);
  double sum = 0.0;
  for (size_t n = 0; n < q.size(); ++n) sum += k * (q[n] - reference()[n * stride]).squaredNorm();
  return std::sqrt(sum);
}

// Least-squares slope of log(error) against log(k).
template <class MakeScheme>
double convergenceOrder(MakeScheme make) {
  std::vector<double> x, y;
  for (int log2k = 8; log2k <= 11; ++log2k) {
    const double k = std::ldexp(1.0, -log2k);
    auto scheme = make(k);
    const double e = error55(testing::trajectory(scheme, stepsFor(1.0, k)), log2k);
    x.push_back(std::log(k));
    y.push_back(std::log(e));
  }
  const double order = testing::leastSquaresSlope(x, y);
  ::testing::Test::RecordProperty("order", std::to_string(order));
  return order;
}

const InitialState& start() {
  static const InitialState s = fpuInitialState(paperChain(), kAlpha);
  return s;
}

TEST(Convergence, StormerVerletIsSecondOrder) {
  const double order = convergenceOrder(
      [](double k) { return StormerVerlet<FermiPastaUlam>(paperChain(), {.k = k}, start()); });
  EXPECT_GE(order, 1.8);
  EXPECT_LE(order, 2.2);
}

TEST(Convergence, MarazzatoMidpointIsSecondOrder) {
  const double order = convergenceOrder([](double k) {
    return Marazzato<FermiPastaUlam>(paperChain(), {.k = k}, start(), QuadratureRule::midpoint);
  });
  EXPECT_GE(order, 1.8);
  EXPECT_LE(order, 2.2);
}

TEST(Convergence, NonSplitSavIsSecondOrder) {
  const double order = convergenceOrder(
      [](double k) { return NonSplitSav<FermiPastaUlam>(paperChain(), {.k = k}, start()); });
  EXPECT_GE(order, 1.8);
  EXPECT_LE(order, 2.2);
}

TEST(Convergence, SplitSavIsSecondOrder) {
  const double order = convergenceOrder(
      [](double k) { return SplitSav<FermiPastaUlam>(paperChain(), {.k = k}, start()); });
  EXPECT_GE(order, 1.8);
  EXPECT_LE(order, 2.2);
}

// The gauge shift changes g (39) but not the limit: with ε = 1e3 J (V ≈ 7e4 J here) the
// scheme still converges to the reference at second order.
TEST(Convergence, SplitSavWithAGaugeShiftIsSecondOrder) {
  const double order = convergenceOrder([](double k) {
    return SplitSav<FermiPastaUlam>(paperChain(), {.k = k, .epsilon = 1e3}, start());
  });
  EXPECT_GE(order, 1.8);
  EXPECT_LE(order, 2.2);
}

// BDZ Fig. 3: "the errors for Störmer–Verlet and the split scheme (38) track each other quite
// closely". Both are second order with error constants of the same size here, so at k = 2⁻¹⁰ the
// ratio of their errors (55) is near 1 (measured 0.96); the band [0.8, 1.25] fails for a start
// ψ^{½} that is off by O(k²) — the mean (q⁰ + q¹)/2 doubled (38)'s error (ratio 1.92), because the
// exactly conserved energy keeps the start's error for the whole run.
TEST(Convergence, SplitSavTracksStormerVerlet) {
  constexpr int log2k = 10;
  const double k = std::ldexp(1.0, -log2k);
  StormerVerlet<FermiPastaUlam> sv(paperChain(), {.k = k}, start());
  SplitSav<FermiPastaUlam> split(paperChain(), {.k = k}, start());
  const double svError = error55(testing::trajectory(sv, stepsFor(1.0, k)), log2k);
  const double splitError = error55(testing::trajectory(split, stepsFor(1.0, k)), log2k);
  ::testing::Test::RecordProperty("ratio", std::to_string(splitError / svError));
  EXPECT_GE(splitError / svError, 0.8) << splitError << " vs " << svError;
  EXPECT_LE(splitError / svError, 1.25) << splitError << " vs " << svError;
}

}  // namespace
}  // namespace hamiltone
