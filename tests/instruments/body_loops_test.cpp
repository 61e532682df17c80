// The body's loops (body_loops.h) on every path this CPU runs: the column sums of g = Φᵀf are the
// rows added in order, to the bit, from any start; a row's dot product of w = Φa does not depend
// on the rows computed with it; both agree with double sums within roundoff.
#include "instruments/body_loops.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace hamiltone {
namespace {

std::vector<const BodyLoops*> paths() {
  std::vector<const BodyLoops*> all{&bodyLoopsFor(Isa::portable)};
  for (Isa isa : {Isa::avx2, Isa::avx512})
    if (cpuRuns(isa)) all.push_back(&bodyLoopsFor(isa));
  return all;
}

// A rows × columns float matrix, padded to bodyPadded(columns) with zeros, and a vector with
// zeros in it (the points no key pushes).
struct Case {
  long rows, columns, ld;
  std::vector<float> m;
  std::vector<double> x;
};

Case randomCase(long rows, long columns, std::mt19937& random) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Case c{rows, columns, bodyPadded(columns), {}, {}};
  c.m.assign(rows * c.ld, 0.0f);
  for (long i = 0; i < rows; ++i)
    for (long j = 0; j < columns; ++j) c.m[i * c.ld + j] = static_cast<float>(u(random));
  c.x.resize(rows);
  for (long i = 0; i < rows; ++i) c.x[i] = i % 5 == 2 ? 0.0 : u(random);
  return c;
}

TEST(BodyLoops, ColumnSumsAreTheRowsAddedInOrderOnEveryPath) {
  std::mt19937 random(7);
  for (long columns : {1L, 3L, 8L, 61L, 64L, 70L, 130L}) {
    const Case c = randomCase(88, columns, random);
    std::vector<double> expected(columns, 0.0);
    for (long j = 0; j < columns; ++j)
      for (long i = 0; i < c.rows; ++i)
        if (c.x[i] != 0.0) expected[j] += static_cast<double>(c.m[i * c.ld + j]) * c.x[i];
    for (const BodyLoops* path : paths()) {
      std::vector<double> out(columns + 1, -7.0);  // one past the end: must stay as it is
      path->combineRows(c.m.data(), c.ld, c.rows, c.x.data(), 0, columns, out.data());
      for (long j = 0; j < columns; ++j) EXPECT_EQ(out[j], expected[j]) << columns << " " << j;
      EXPECT_EQ(out[columns], -7.0);
      // From a later start (a multiple of kBodyPad), the same bits; those before it untouched.
      if (columns > kBodyPad) {
        std::vector<double> part(columns, -7.0);
        path->combineRows(c.m.data(), c.ld, c.rows, c.x.data(), kBodyPad, columns, part.data());
        for (long j = 0; j < kBodyPad; ++j) EXPECT_EQ(part[j], -7.0);
        for (long j = kBodyPad; j < columns; ++j) EXPECT_EQ(part[j], expected[j]);
      }
    }
  }
}

TEST(BodyLoops, ARowsDotProductIsItsOwnWhicheverRowsComeWithIt) {
  std::mt19937 random(11);
  for (long columns : {1L, 5L, 8L, 61L, 67L}) {
    const Case c = randomCase(13, columns, random);
    std::vector<double> a(columns);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (double& v : a) v = u(random);
    std::vector<int> rows(c.rows);
    for (long i = 0; i < c.rows; ++i) rows[i] = static_cast<int>(c.rows - 1 - i);  // any order
    for (const BodyLoops* path : paths()) {
      std::vector<double> together(c.rows), alone(c.rows);
      path->dotRows(c.m.data(), c.ld, rows.data(), c.rows, columns, a.data(), together.data());
      for (long i = 0; i < c.rows; ++i) {
        const int row = static_cast<int>(i);
        path->dotRows(c.m.data(), c.ld, &row, 1, columns, a.data(), alone.data());
        EXPECT_EQ(together[i], alone[i]) << columns << " " << i;
        double exact = 0.0, size = 0.0;
        for (long j = 0; j < columns; ++j) {
          exact += static_cast<double>(c.m[i * c.ld + j]) * a[j];
          size += std::abs(static_cast<double>(c.m[i * c.ld + j]) * a[j]);
        }
        // A sum of n terms in any order: within n ε of the sum of their magnitudes.
        EXPECT_NEAR(together[i], exact, columns * 2.3e-16 * size) << columns << " " << i;
      }
    }
  }
}

}  // namespace
}  // namespace hamiltone
