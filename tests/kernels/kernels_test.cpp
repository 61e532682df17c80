// The kernels of every instruction set this CPU runs against the portable ones: the stencils and
// the plate's products and grid loops bit for bit (the same IEEE operations in the same order,
// without contraction), the two grids' stretches against their formulas written out (on the
// portable path too), the scheme's sums within their reordering bound, and a struck
// two-grid string on each path conserving energy and staying within roundoff growth of the
// portable run.
#include "kernels/kernels.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "instruments/hammer.h"
#include "schemes/sav.h"
#include "support/energy_checks.h"

namespace hamiltone {
namespace {

std::vector<const Kernels*> otherPaths() {
  std::vector<const Kernels*> paths;
  for (Isa isa : {Isa::avx2, Isa::avx512})
    if (cpuRuns(isa)) paths.push_back(&kernelsFor(isa));
  return paths;
}

std::vector<double> randomArray(long n, double scale, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(-scale, scale);
  std::vector<double> a(n);
  for (double& x : a) x = uniform(rng);
  return a;
}

// a between kMaxLanes NaNs on each side (its values start at kMaxLanes): a kernel that reads past
// either end of a carries a NaN into its results.
std::vector<double> fenced(const std::vector<double>& a) {
  std::vector<double> f(kMaxLanes, NAN);
  f.insert(f.end(), a.begin(), a.end());
  f.resize(f.size() + kMaxLanes, NAN);
  return f;
}

TEST(Kernels, StencilsAndForcesAreBitIdenticalOnEveryPath) {
  const Kernels& base = kernelsFor(Isa::portable);
  const std::vector<const Kernels*> paths = otherPaths();
  if (paths.empty()) GTEST_SKIP() << "this CPU runs only the portable kernels";
  for (const Kernels* path : paths) {
    for (long n : {1L, 2L, 7L, 64L, 343L}) {
      const std::vector<double> a = randomArray(n + 1, 1e-3, 1), b = randomArray(n + 1, 1e-3, 2);
      std::vector<double> x(n), y(n);
      base.secondDifference(a.data(), x.data(), n, -3.7);
      path->secondDifference(a.data(), y.data(), n, -3.7);
      EXPECT_EQ(x, y) << path->name << " n = " << n;
      // The stiff stencil: the two second differences and their sum, the same operations.
      std::vector<double> d2(n), d4(n), stiff(n), scratch1(n), scratch2(n);
      base.secondDifference(a.data(), d2.data(), n, 1e4);
      base.secondDifference(d2.data(), d4.data(), n, 1e4);
      for (long j = 0; j < n; ++j) stiff[j] = -3.0 * d2[j] + 2e-5 * d4[j];
      base.stiffStencil(a.data(), scratch1.data(), x.data(), n, 1e4, 3.0, 2e-5);
      path->stiffStencil(a.data(), scratch2.data(), y.data(), n, 1e4, 3.0, 2e-5);
      EXPECT_EQ(x, stiff) << "portable n = " << n;
      EXPECT_EQ(x, y) << path->name << " n = " << n;
      // With the loss from the same d2 and the last state's: the stiff stencil's bits, and
      // loss_j = cl (d2_j − d2Prev_j) written out.
      const std::vector<double> d2Prev = randomArray(n, 5.0, 3);
      std::vector<double> loss(n), loss1(n), loss2(n);
      for (long j = 0; j < n; ++j) loss[j] = -0.3 * (d2[j] - d2Prev[j]);
      base.stiffLossStencil(a.data(), scratch1.data(), d2Prev.data(), x.data(), loss1.data(), n,
                            1e4, 3.0, 2e-5, -0.3);
      path->stiffLossStencil(a.data(), scratch2.data(), d2Prev.data(), y.data(), loss2.data(), n,
                             1e4, 3.0, 2e-5, -0.3);
      EXPECT_EQ(x, stiff) << "portable n = " << n;
      EXPECT_EQ(scratch1, d2) << "portable n = " << n;
      EXPECT_EQ(loss1, loss) << "portable n = " << n;
      EXPECT_EQ(x, y) << path->name << " n = " << n;
      EXPECT_EQ(loss1, loss2) << path->name << " n = " << n;
      base.secondDifferenceOfDifference(a.data(), b.data(), x.data(), n, 2.1);
      path->secondDifferenceOfDifference(a.data(), b.data(), y.data(), n, 2.1);
      EXPECT_EQ(x, y) << path->name << " n = " << n;
    }
  }
}

// A sum of n terms taken in two orders (registers, a tail, lanes as a tree, against one by one)
// differs by at most about 2 n u Σ|terms|, u = 2⁻⁵³ (each partial sum of either rounds once).
double reorderingBound(long n, double absoluteSum) { return 2.0 * n * 1.12e-16 * absoluteSum; }

// The single grid's forces on every path, the portable one too: u and v padded, m = n + 1
// segments; the weights and the forces the bits of the formulas written out, the sum of the squared
// excesses within its reordering bound.
TEST(Kernels, SingleGridForcesAreTheFormulasOnEveryPath) {
  std::vector<const Kernels*> paths = otherPaths();
  paths.push_back(&kernelsFor(Isa::portable));
  const double invH = 100.0, c = 5.0;
  for (long n : {1L, 2L, 7L, 8L, 15L, 64L, 343L}) {
    const long m = n + 1;
    const std::vector<double> up = randomArray(m + 1, 1e-3, 12), vp = randomArray(m + 1, 1e-4, 11);
    std::vector<double> wz(m), we(m), gu(n), gv(n);
    double sum = 0.0;
    for (long l = 0; l < m; ++l) {
      const double zeta = (up[l + 1] - up[l]) * invH, eta = (vp[l + 1] - vp[l]) * invH;
      const double stretch = std::sqrt((1.0 + eta) * (1.0 + eta) + zeta * zeta);
      const double excess = (2.0 * eta + eta * eta + zeta * zeta) / (stretch + 1.0);
      const double phi = excess / stretch;
      wz[l] = c * phi * zeta;
      we[l] = c * phi * (1.0 + eta);
      sum += excess * excess;
    }
    for (long j = 0; j < n; ++j) {
      gu[j] = (wz[j] - wz[j + 1]) * invH;
      gv[j] = (we[j] - we[j + 1]) * invH;
    }
    for (const Kernels* path : paths) {
      std::vector<double> wz1(m), we1(m), gu1(n), gv1(n);
      const double sum1 = path->singleGridForces(up.data(), vp.data(), m, invH, c, wz1.data(),
                                                 we1.data(), gu1.data(), gv1.data());
      EXPECT_EQ(wz1, wz) << path->name << " n = " << n;
      EXPECT_EQ(we1, we) << path->name << " n = " << n;
      EXPECT_EQ(gu1, gu) << path->name << " n = " << n;
      EXPECT_EQ(gv1, gv) << path->name << " n = " << n;
      EXPECT_NEAR(sum1, sum, reorderingBound(m, sum)) << path->name << " n = " << n;  // terms >= 0
    }
  }
}

// The two grids' strains and forces, r fine segments a cell (chunks ending inside a cell, on its
// edge, several cells to a chunk at r = 1), strains η ~ 1e-4, every buffer exactly the size
// kernels.h asks: each path, the portable one too, gives the bits of the formulas written out
// here, so the same bits on every path. u sits after NaNs, which a read before its first node
// would carry into the results (past its last, the kernels read by construction nothing: their
// copy loads whole chunks only within u, then the ends), and the work starts as NaNs too.
TEST(Kernels, TwoGridStrainsAndForcesAreTheFormulasOnEveryPath) {
  std::vector<const Kernels*> paths = otherPaths();
  paths.push_back(&kernelsFor(Isa::portable));
  const double invH = 100.0, invHv = 10.0, c = 7.0, tension = 600.0;
  for (long mv : {1L, 2L, 7L, 64L, 343L}) {
    for (int r : {1, 2, 3, 6, 8, 11}) {
      const long m = r * mv;
      const std::vector<double> u = randomArray(m - 1, 1e-3, 9), v = randomArray(mv - 1, 1e-5, 10);
      std::vector<double> up(m + kMaxLanes, 0.0), eta(mv);
      std::copy(u.begin(), u.end(), up.begin() + 1);
      for (long j = 0; j < mv; ++j)
        eta[j] = ((j < mv - 1 ? v[j] : 0.0) - (j > 0 ? v[j - 1] : 0.0)) * invHv;
      std::vector<double> zeta(m), strain(mv), inverse(mv), gu(m - 1), gv(mv - 1), w(mv), we(mv);
      double sum = 0.0;
      for (long j = 0; j < mv; ++j) {
        double z2[4] = {};  // by position l − J r (mod 4)
        for (long l = j * r; l < (j + 1) * r; ++l) {
          zeta[l] = (up[l + 1] - up[l]) * invH;
          z2[(l - j * r) % 4] += zeta[l] * zeta[l];
        }
        const double mean = ((z2[0] + z2[1]) + (z2[2] + z2[3])) * (1.0 / r);
        const double s = std::sqrt((1.0 + eta[j]) * (1.0 + eta[j]) + mean);
        strain[j] = (2.0 * eta[j] + eta[j] * eta[j] + mean) / (s + 1.0);
        inverse[j] = 1.0 / s;
        sum += strain[j] * strain[j];
        w[j] = c * (inverse[j] * strain[j]);
        we[j] = c * r * (inverse[j] * strain[j]) * (1.0 + eta[j]);
      }
      for (long l = 0; l + 1 < m; ++l) {
        const long j = l / r;
        gu[l] = (l + 1) % r != 0 ? ((up[l] - 2.0 * up[l + 1]) + up[l + 2]) * (-w[j] * (invH * invH))
                                 : (zeta[l] * w[j] - zeta[l + 1] * w[j + 1]) * invH;
      }
      for (long j = 0; j + 1 < mv; ++j) gv[j] = (we[j] - we[j + 1]) * invHv;
      const double end = tension * eta[mv - 1] + we[mv - 1] * invHv;
      const std::vector<double> uFenced = fenced(u);
      const double* inPlace = uFenced.data() + kMaxLanes;
      for (const Kernels* k : paths) {
        std::vector<double> s(mv), i(mv), strainsWork(twoGridStrainsWork(m, mv), NAN);
        k->cellStretches(inPlace, v.data(), mv, r, invH, invHv, strainsWork.data(), s.data(),
                         i.data());
        EXPECT_EQ(s, strain) << k->name << " r = " << r << " mv = " << mv;
        EXPECT_EQ(i, inverse) << k->name << " r = " << r << " mv = " << mv;
        // The work starts as garbage; gu and gv are followed by coordinates to leave alone.
        std::vector<double> work(twoGridWork(m, mv), NAN), g(m - 1 + kMaxLanes, -1.0),
            h(mv - 1 + kMaxLanes, -1.0);
        const TwoGridSums sums = k->twoGridForces(inPlace, v.data(), mv, r, invH, invHv, c, tension,
                                                  work.data(), g.data(), h.data());
        EXPECT_EQ(sums.squaredStrains, sum) << k->name << " r = " << r << " mv = " << mv;
        EXPECT_EQ(sums.endTension, end) << k->name << " r = " << r << " mv = " << mv;
        EXPECT_TRUE(std::equal(gu.begin(), gu.end(), g.begin()))
            << k->name << " r = " << r << " mv = " << mv;
        EXPECT_TRUE(std::equal(gv.begin(), gv.end(), h.begin()))
            << k->name << " r = " << r << " mv = " << mv;
        EXPECT_TRUE(std::all_of(g.begin() + (m - 1), g.end(), [](double x) { return x == -1.0; }))
            << k->name << " wrote past u's last node, r = " << r << " mv = " << mv;
        EXPECT_TRUE(std::all_of(h.begin() + (mv - 1), h.end(), [](double x) { return x == -1.0; }))
            << k->name << " wrote past v's last node, r = " << r << " mv = " << mv;
      }
    }
  }
}

// A sum of n products reordered differs by at most ~n ε Σ|terms| (each partial sum rounds once).
// The plate's loops: a product is a sum in order of p on every path, so all of them give the bits
// of the plain triple loop; the grid stencils are the same operations on every path.
TEST(Kernels, PlateProductsAndStencilsAreBitIdenticalOnEveryPath) {
  std::vector<const Kernels*> paths = otherPaths();
  paths.push_back(&kernelsFor(Isa::portable));
  for (const Kernels* path : paths) {
    // A (16 × 7, rows padded past 13), B read with a row step of 2, n = 1 … 9 columns (the
    // blocks of four and the partial last block).
    const long m = 16, k = 7, lda = 16, ldb = 19, step = 2;
    const std::vector<double> a = randomArray(lda * k, 1.0, 3), b = randomArray(ldb * 9, 1.0, 4);
    for (long n = 1; n <= 9; ++n) {
      std::vector<double> c(m * n, -1.0), expected(m * n);
      path->matrixProduct(a.data(), lda, b.data(), ldb, step, c.data(), m, m, k, n);
      for (long j = 0; j < n; ++j)
        for (long i = 0; i < m; ++i) {
          double sum = 0.0;
          for (long p = 0; p < k; ++p) sum += a[i + lda * p] * b[step * p + ldb * j];
          expected[i + m * j] = sum;
        }
      EXPECT_EQ(c, expected) << path->name << " n = " << n;
    }
    // Grids of 1 × 1 … 13 × 5 interior points inside a zero border.
    const Kernels& base = kernelsFor(Isa::portable);
    for (long nx : {1L, 2L, 13L})
      for (long ny : {1L, 5L}) {
        const long px = nx + 2, size = px * (ny + 2);
        std::vector<double> f(size, 0.0), g(size, 0.0);
        const std::vector<double> rf = randomArray(nx * ny, 1e-3, 5),
                                  rg = randomArray(nx * ny, 1e3, 6);
        for (long row = 0; row < ny; ++row)
          for (long l = 0; l < nx; ++l) {
            f[1 + l + px * (row + 1)] = rf[l + nx * row];
            g[1 + l + px * (row + 1)] = rg[l + nx * row];
          }
        std::vector<double> x(size, 7.0), y(size, 7.0), cf(size), cg(size), cf2(size), cg2(size);
        base.gridLaplacian(f.data(), px, ny, 3.0, 5.0, x.data());
        path->gridLaplacian(f.data(), px, ny, 3.0, 5.0, y.data());
        EXPECT_EQ(x, y) << path->name;
        for (long row = 1; row <= ny; ++row)
          EXPECT_TRUE(y[px * row] == 0.0 && y[px * row + px - 1] == 0.0)
              << "border, " << path->name;
        base.gridCells(f.data(), px, ny, cf.data());
        base.gridCells(g.data(), px, ny, cg.data());
        path->gridCells(f.data(), px, ny, cf2.data());
        path->gridCells(g.data(), px, ny, cg2.data());
        EXPECT_EQ(cf, cf2) << path->name;
        base.gridBracket(f.data(), g.data(), cf.data(), cg.data(), px, ny, 3.0, 5.0, 15.0,
                         x.data());
        path->gridBracket(f.data(), g.data(), cf.data(), cg.data(), px, ny, 3.0, 5.0, 15.0,
                          y.data());
        EXPECT_EQ(x, y) << path->name;
      }
  }
}

// The SAV's passes on every path, the portable one too, with and without K q and the loss's term,
// over lengths shorter than a register, whole registers and registers with a tail: q^{n+1} element
// by element the bits of the formula written out (and the linear step's, with no gradient); the
// sums, whose order is each path's (registers, then the tail, then the lanes as a tree), within
// their reordering bound of the sum in order. The inputs sit between NaNs, which a read past
// either end would carry into the results, and q^{n+1} before a sentinel.
TEST(Kernels, SchemeSumsAgreeWithinTheirReorderingBound) {
  std::vector<const Kernels*> paths = otherPaths();
  paths.push_back(&kernelsFor(Isa::portable));
  const double down = 0.99, kk = 1e-9, c = 0.3, invUp = 1.0 / 1.01, xScale = 0.5;
  for (long n : {1L, 3L, 8L, 13L, 35L, 387L}) {
    const std::vector<double> g = randomArray(n, 1.0, 3), q = randomArray(n, 1e-3, 4),
                              qm = randomArray(n, 1e-3, 5), minv = randomArray(n, 10.0, 6),
                              kq = randomArray(n, 1e2, 7), x = randomArray(n, 1e-2, 8);
    const std::vector<double> gF = fenced(g), qF = fenced(q), qmF = fenced(qm),
                              minvF = fenced(minv), kqF = fenced(kq), xF = fenced(x);
    const double* in[6] = {gF.data() + kMaxLanes,    qF.data() + kMaxLanes,  qmF.data() + kMaxLanes,
                           minvF.data() + kMaxLanes, kqF.data() + kMaxLanes, xF.data() + kMaxLanes};
    for (bool stiff : {false, true})
      for (bool extra : {false, true}) {
        const double* kqIn = stiff ? in[4] : nullptr;
        const double* xIn = extra ? in[5] : nullptr;
        double sums[5] = {}, bound[5] = {};
        std::vector<double> next(n);
        double sdq = 0.0, sdqBound = 0.0;
        for (long i = 0; i < n; ++i) {
          const double terms[5] = {
              g[i] * q[i], g[i] * qm[i], stiff ? g[i] * (minv[i] * kq[i]) : 0.0,
              extra ? g[i] * (minv[i] * (xScale * x[i])) : 0.0, g[i] * minv[i] * g[i]};
          for (int j = 0; j < 5; ++j) sums[j] += terms[j], bound[j] += std::abs(terms[j]);
          double b = 2.0 * q[i] - down * qm[i];
          if (stiff) b -= kk * (minv[i] * kq[i]);
          if (extra) b -= minv[i] * (xScale * x[i]);
          next[i] = (b + c * (minv[i] * g[i])) * invUp;
          sdq += g[i] * (next[i] - qm[i]);
          sdqBound += std::abs(g[i] * (next[i] - qm[i]));
        }
        for (const Kernels* path : paths) {
          const std::string what = std::string(path->name) + " n = " + std::to_string(n) +
                                   (stiff ? " K q" : "") + (extra ? " loss" : "");
          double d[5];
          path->savDots(n, in[0], in[1], in[2], in[3], kqIn, xIn, xScale, d);
          for (int j = 0; j < 5; ++j)
            EXPECT_NEAR(d[j], sums[j], reorderingBound(n, bound[j])) << what;
          std::vector<double> p(n + 1, -1.0), linear(n + 1, -1.0);
          const double s = path->savUpdate(n, in[0], in[1], in[2], in[3], kqIn, xIn, xScale, down,
                                           kk, c, invUp, p.data());
          EXPECT_EQ(std::vector<double>(p.begin(), p.begin() + n), next) << what;
          EXPECT_EQ(p[n], -1.0) << what << ": wrote past q^{n+1}";
          EXPECT_NEAR(s, sdq, reorderingBound(n, sdqBound)) << what;
          // The linear step is the same update with no gradient: element by element, the bits
          // of savUpdate's with c = 0 on every path.
          path->savUpdate(n, in[0], in[1], in[2], in[3], kqIn, xIn, xScale, down, kk, 0.0, invUp,
                          p.data());
          path->linearUpdate(n, in[1], in[2], in[3], kqIn, xIn, xScale, down, kk, invUp,
                             linear.data());
          EXPECT_EQ(p, linear) << what;
        }
      }
  }
}

// The modal tail's step (voices/modal_tail.h): the recursion element by element, the same bits on
// every path as written out; the four probes' sums within their reordering bound; and v's, with
// no force and one probe.
TEST(Kernels, TheModalStepIsTheRecursionOnEveryPath) {
  std::vector<const Kernels*> paths = otherPaths();
  paths.push_back(&kernelsFor(Isa::portable));
  for (long n : {1L, 3L, 8L, 13L, 16L, 120L}) {
    const std::vector<double> c1 = randomArray(n, 2.0, 3), c2 = randomArray(n, 1.0, 4),
                              newer = randomArray(n, 1e-4, 5), older = randomArray(n, 1e-4, 6);
    std::vector<std::vector<double>> w;
    for (unsigned p = 0; p < 4; ++p) w.push_back(randomArray(n, 1.0, 7 + p));
    const double* weights[4] = {w[0].data(), w[1].data(), w[2].data(), w[3].data()};
    const double f = 3e-6;
    std::vector<double> expected(n);
    double bound[4] = {};
    for (long m = 0; m < n; ++m) {
      expected[m] = c1[m] * newer[m] - c2[m] * older[m] + f * w[2][m];
      for (int p = 0; p < 4; ++p) bound[p] += std::abs(w[p][m] * expected[m]);
    }
    for (const Kernels* path : paths) {
      std::vector<double> x = older;
      double out[4];
      path->modalStep(n, c1.data(), c2.data(), weights, f, x.data(), newer.data(), out);
      EXPECT_EQ(x, expected) << path->name << " n = " << n;
      for (int p = 0; p < 4; ++p) {
        double sum = 0.0;
        for (long m = 0; m < n; ++m) sum += w[p][m] * expected[m];
        EXPECT_NEAR(out[p], sum, n * 1.2e-16 * bound[p]) << path->name << " probe " << p;
      }
      // v's modes: no force, the first probe alone.
      std::vector<double> free = older, freeExpected(n);
      double freeSum = 0.0, freeBound = 0.0;
      for (long m = 0; m < n; ++m) {
        freeExpected[m] = c1[m] * newer[m] - c2[m] * older[m];
        freeSum += w[0][m] * freeExpected[m];
        freeBound += std::abs(w[0][m] * freeExpected[m]);
      }
      const double last =
          path->freeModalStep(n, c1.data(), c2.data(), w[0].data(), free.data(), newer.data());
      EXPECT_EQ(free, freeExpected) << path->name << " n = " << n;
      EXPECT_NEAR(last, freeSum, n * 1.2e-16 * freeBound) << path->name << " n = " << n;
    }
  }
}

// The modal tail's sine transform: the same bits on every path (row by row, no reordering), and
// the sines' recurrence within its error growth of the directly summed transform: a row's error
// grows about as t ε / sin θ, under 1e-11 of Σ|terms| for M = 344 (A0's u grid) at θ = π/M.
TEST(Kernels, TheSineSumsAreTheSineTransformOnEveryPath) {
  std::vector<const Kernels*> paths = otherPaths();
  const Kernels& base = kernelsFor(Isa::portable);
  for (long segments : {2L, 9L, 16L, 121L, 344L}) {
    const long n = segments - 1;
    std::vector<double> sinTheta(n + kMaxLanes, 0.0), twoCos(n + kMaxLanes, 0.0);
    for (long i = 1; i <= n; ++i) {
      sinTheta[i - 1] = std::sin(std::numbers::pi * i / segments);
      twoCos[i - 1] = 2.0 * std::cos(std::numbers::pi * i / segments);
    }
    const std::vector<double> in = randomArray(n, 1e-3, 11);
    for (long terms : {n, (n + 1) / 3}) {
      std::vector<double> expected(n), x(n);
      base.sineSums(n, terms, in.data(), sinTheta.data(), twoCos.data(), 0.5, expected.data());
      for (long i = 1; i <= n; ++i) {
        double sum = 0.0, size = 0.0;
        for (long t = 1; t <= terms; ++t) {
          sum += in[t - 1] * std::sin(std::numbers::pi * i * t / segments);
          size += std::abs(in[t - 1]);
        }
        EXPECT_NEAR(expected[i - 1], 0.5 * sum, 1e-11 * 0.5 * size) << "M " << segments;
      }
      for (const Kernels* path : paths) {
        path->sineSums(n, terms, in.data(), sinTheta.data(), twoCos.data(), 0.5, x.data());
        EXPECT_EQ(x, expected) << path->name << " M " << segments;
      }
    }
  }
}

// The C3 string on two grids struck at 3 m/s, 0.02 s (960 steps: the strike and 15 ms after, as in
// hammer_test) with loss, on each path: the balance (50) closes to the same roundoff as the
// portable run's (hammer_test), and the paths part only by roundoff amplified by the dynamics:
// 1e-16 per step grown over 960 steps stays far below 1e-8 of the motion's size.
TEST(Kernels, AStruckStringOnEveryPathConservesAndAgrees) {
  const double k = 1.0 / 48000.0;
  StringPhysics physics;
  physics.inertia = 6.4e-14;
  const StringGrid grid = stringGrid(physics, GridRule::twoGrid, k, 1e-4, 1.0, 1.5);
  auto run = [&](const Kernels& kernels, Vector& end) {
    HammeredString system(NonlinearString(physics, grid), HammerFelt{});
    system.string().setKernels(kernels);
    InitialState start{Vector::Zero(system.size()), Vector::Zero(system.size())};
    start.q[system.hammerIndex()] = -1e-4;
    start.p[system.hammerIndex()] = HammerFelt{}.mass * 3.0;
    SplitSav<HammeredString> scheme(
        system, {.k = k, .sigma0 = 1.0, .sigma1 = 1e-4, .epsilon = 0.02}, start);
    scheme.setKernels(kernels);
    const testing::Balance b = testing::runBalance(scheme, 960);
    end = scheme.q();
    return b;
  };
  Vector reference, other;
  const testing::Balance base = run(kernelsFor(Isa::portable), reference);
  EXPECT_LE(base.worstBalance, 1e-10);
  const Eigen::Index nu = grid.transverse - 1;
  const std::vector<const Kernels*> paths = otherPaths();
  if (paths.empty()) GTEST_SKIP() << "this CPU runs only the portable kernels";
  for (const Kernels* path : paths) {
    const testing::Balance b = run(*path, other);
    EXPECT_LE(b.worstBalance, 1e-10) << path->name;
    EXPECT_LE(b.worstIncrease, 1e-14) << path->name;
    EXPECT_LE((other.head(nu) - reference.head(nu)).lpNorm<Eigen::Infinity>(),
              1e-8 * reference.head(nu).lpNorm<Eigen::Infinity>())
        << path->name;
  }
}

TEST(Kernels, UnknownNamesAreRefusedNamingTheValidOnes) {
  try {
    kernelsNamed("avx3");
    FAIL() << "avx3 accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "instruction set \"avx3\": must be one of portable, avx2, avx512");
  }
  EXPECT_EQ(kernelsNamed("portable").isa, Isa::portable);
}

}  // namespace
}  // namespace hamiltone
