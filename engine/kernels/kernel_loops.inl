// The loops of kernels.h, included by one file per instruction set, each of which defines
// HAMILTONE_TARGET (a function attribute), HAMILTONE_KERNEL_NS (its namespace) and
// HAMILTONE_KERNEL_LANES (the doubles in one of its vector registers). Everything
// here has internal linkage or that namespace's name, so no inline function compiled for one
// instruction set can be taken by the linker for another.
#include <algorithm>

namespace hamiltone::HAMILTONE_KERNEL_NS {
namespace {

constexpr int kLanes = HAMILTONE_KERNEL_LANES;
static_assert(kLanes <= kMaxLanes);

// Cell by cell, in chunks of four segments on every path (one vector iteration on AVX2 and
// AVX-512, two on SSE2): a cell's last chunk reads past its r segments into the following cell's
// (or the padding's). The loop of one chunk has a fixed trip count, so it vectorises; a loop of r =
// 8…17 would not. A cell's Σ ζ_l² is four partial sums, one per position in the chunk (its last
// chunk adds 0 for the segments past the cell), then added as (p0 + p1) + (p2 + p3): every path
// adds the same values in the same order, so every path gives the same bits. The square roots and
// divisions, one and two per cell, then run over the cells.
constexpr int kChunk = 4;

// Four doubles: one vector register on AVX2 and AVX-512, two on SSE2.
typedef double Chunk __attribute__((vector_size(kChunk * sizeof(double))));

// One vector register of doubles (GCC's vector extension, so that the loops below are vectorised
// as written, whatever the compiler's cost model).
typedef double Lanes __attribute__((vector_size(kLanes * sizeof(double))));

// A register's lanes summed as a tree: halves, then quarters, … (the order of every call on a
// path).
HAMILTONE_TARGET inline double laneSum(Lanes s) {
  double lane[kLanes];
  __builtin_memcpy(lane, &s, sizeof s);
  for (int width = kLanes / 2; width > 0; width /= 2)
    for (int i = 0; i < width; ++i) lane[i] += lane[i + width];
  return lane[0];
}

HAMILTONE_TARGET inline Lanes loadLanes(const double* p) {
  Lanes x;
  __builtin_memcpy(&x, p, sizeof x);
  return x;
}

// u padded with its ends and η into work (twoGridStrainsWork), then the cells' stretches.
HAMILTONE_TARGET void cellStretches(const double* u, const double* v, long mv, int r, double invH,
                                    double invHv, double* work, double* strain,
                                    double* inverseStretch) {
  const long m = mv * r;
  double* up = work;                   // u with its fixed ends, then zeros
  double* eta = up + (m + kMaxLanes);  // η_J
  up[0] = 0.0;
  long i = 0;
  for (; i + kChunk <= m - 1; i += kChunk) __builtin_memcpy(up + 1 + i, u + i, sizeof(Chunk));
  for (; i < m - 1; ++i) up[1 + i] = u[i];
  for (long l = m; l < m + kMaxLanes; ++l) up[l] = 0.0;
  eta[0] = mv == 1 ? 0.0 : v[0] * invHv;  // v = 0 beyond both ends
  for (long j = 1; j < mv - 1; ++j) eta[j] = (v[j] - v[j - 1]) * invHv;
  if (mv > 1) eta[mv - 1] = -v[mv - 2] * invHv;
  const Chunk position = {0.0, 1.0, 2.0, 3.0}, zero = {};
  const double invR = 1.0 / r;
  double* meanSquare = strain;  // Z_J, until the last loop
  for (long j = 0; j < mv; ++j) {
    Chunk sum = {};
    const long end = (j + 1) * r;
    for (long t = j * r; t < end; t += kChunk) {
      Chunk left, right;
      __builtin_memcpy(&left, up + t, sizeof left);
      __builtin_memcpy(&right, up + t + 1, sizeof right);
      const Chunk z = (right - left) * invH;
      sum += position < static_cast<double>(end - t) ? z * z : zero;
    }
    meanSquare[j] = ((sum[0] + sum[1]) + (sum[2] + sum[3])) * invR;
  }
#pragma omp simd
  for (long j = 0; j < mv; ++j) {
    const double e = eta[j], z2 = meanSquare[j];
    const double stretch = __builtin_sqrt((1.0 + e) * (1.0 + e) + z2);
    strain[j] = (2.0 * e + e * e + z2) / (stretch + 1.0);  // S_J − 1, no cancellation
    inverseStretch[j] = 1.0 / stretch;
  }
}

// Inside cell J, (D₋ᵀ w)_l = w_J (ζ_l − ζ_{l+1}) / h = −w_J (up[l] − 2 up[l+1] + up[l+2]) / h²
// with w_J = c ε_J/S_J: a second difference under one weight, in chunks of four (the last may run
// two nodes into the next cell, which its own loop then writes again, but not past u's last node),
// then node by node. At the cell's last segment l, where the weight changes, (w_J ζ_l −
// w_{J+1} ζ_{l+1}) / h.
HAMILTONE_TARGET TwoGridSums twoGridForces(const double* u, const double* v, long mv, int r,
                                           double invH, double invHv, double c, double tension,
                                           double* work, double* gu, double* gv) {
  const long m = mv * r;
  const double* up = work;                       // u with its fixed ends, then zeros
  const double* eta = up + (m + kMaxLanes);      // η_J
  double* strain = work + (m + kMaxLanes + mv);  // ε_J, then ∂V'/∂η_J
  double* weight = strain + mv;                  // 1/S_J, then c ε_J/S_J
  cellStretches(u, v, mv, r, invH, invHv, work, strain, weight);
  const double cr = c * r;
  double sum = 0.0;
  for (long j = 0; j < mv; ++j) {
    sum += strain[j] * strain[j];
    const double w = weight[j] * strain[j];
    weight[j] = c * w;
    strain[j] = cr * w * (1.0 + eta[j]);  // ∂V'/∂η_J
  }
  const double invH2 = invH * invH;
  for (long j = 0; j < mv; ++j) {
    const double scale = -weight[j] * invH2;
    const long last = (j + 1) * r - 1;             // the cell's last segment
    const long limit = std::min(last + 2, m - 2);  // u's last node
    long l = j * r;
    for (; l < last && l + (kChunk - 1) <= limit; l += kChunk) {
      Chunk a, b, d;
      __builtin_memcpy(&a, up + l, sizeof a);
      __builtin_memcpy(&b, up + l + 1, sizeof b);
      __builtin_memcpy(&d, up + l + 2, sizeof d);
      const Chunk g = ((a - 2.0 * b) + d) * scale;
      __builtin_memcpy(gu + l, &g, sizeof g);
    }
    for (; l < last; ++l) gu[l] = ((up[l] - 2.0 * up[l + 1]) + up[l + 2]) * scale;
    if (j + 1 < mv) {
      const double zl = (up[last + 1] - up[last]) * invH, zr = (up[last + 2] - up[last + 1]) * invH;
      gu[last] = (zl * weight[j] - zr * weight[j + 1]) * invH;
    }
  }
  for (long j = 0; j < mv - 1; ++j) gv[j] = (strain[j] - strain[j + 1]) * invHv;
  return {sum, tension * eta[mv - 1] + strain[mv - 1] * invHv};
}

HAMILTONE_TARGET inline double squareRoot(double x) { return __builtin_sqrt(x); }
HAMILTONE_TARGET inline Lanes squareRoot(Lanes x) {
  for (int i = 0; i < kLanes; ++i) x[i] = __builtin_sqrt(x[i]);
  return x;
}

// One segment's weights (T: double or Lanes), its excess S − 1 returned.
template <class T>
HAMILTONE_TARGET inline T segmentWeights(T zeta, T eta, double c, T& wz, T& we) {
  const T stretch = squareRoot((1.0 + eta) * (1.0 + eta) + zeta * zeta);
  const T excess = (2.0 * eta + eta * eta + zeta * zeta) / (stretch + 1.0);
  const T phi = excess / stretch;
  wz = c * phi * zeta;
  we = c * phi * (1.0 + eta);
  return excess;
}

// Whole registers, the sum kept as lanes (savDotsOf's reason), then the last segments one by one.
HAMILTONE_TARGET double singleGridForces(const double* up, const double* vp, long m, double invH,
                                         double c, double* wz, double* we, double* gu, double* gv) {
  Lanes sums = {};
  long l = 0;
  for (; l + kLanes <= m; l += kLanes) {
    Lanes z, e;
    const Lanes excess =
        segmentWeights<Lanes>((loadLanes(up + l + 1) - loadLanes(up + l)) * invH,
                              (loadLanes(vp + l + 1) - loadLanes(vp + l)) * invH, c, z, e);
    __builtin_memcpy(wz + l, &z, sizeof z);
    __builtin_memcpy(we + l, &e, sizeof e);
    sums += excess * excess;
  }
  double sum = 0.0;
  for (; l < m; ++l) {
    const double excess = segmentWeights<double>((up[l + 1] - up[l]) * invH,
                                                 (vp[l + 1] - vp[l]) * invH, c, wz[l], we[l]);
    sum += excess * excess;
  }
  sum += laneSum(sums);
#pragma omp simd
  for (long j = 0; j < m - 1; ++j) {
    gu[j] = (wz[j] - wz[j + 1]) * invH;
    gv[j] = (we[j] - we[j + 1]) * invH;
  }
  return sum;
}

HAMILTONE_TARGET void secondDifference(const double* a, double* out, long n, double c) {
  if (n == 1) {
    out[0] = -2.0 * c * a[0];
    return;
  }
  out[0] = c * (a[1] - 2.0 * a[0]);
#pragma omp simd
  for (long j = 1; j < n - 1; ++j) out[j] = c * (a[j - 1] - 2.0 * a[j] + a[j + 1]);
  out[n - 1] = c * (a[n - 2] - 2.0 * a[n - 1]);
}

// stiffStencil's two sweeps, the second writing the loss too when `withLoss`.
template <bool withLoss>
HAMILTONE_TARGET void stiffSweeps(const double* a, double* d2, const double* d2Prev, double* out,
                                  double* loss, long n, double invH2, double t, double ei,
                                  double cl) {
  secondDifference(a, d2, n, invH2);
  auto lossAt = [&](long j) {
    if constexpr (withLoss) loss[j] = cl * (d2[j] - d2Prev[j]);
  };
  if (n == 1) {
    out[0] = -t * d2[0] + ei * (-2.0 * invH2 * d2[0]);
    lossAt(0);
    return;
  }
  out[0] = -t * d2[0] + ei * (invH2 * (d2[1] - 2.0 * d2[0]));
  lossAt(0);
#pragma omp simd
  for (long j = 1; j < n - 1; ++j) {
    out[j] = -t * d2[j] + ei * (invH2 * (d2[j - 1] - 2.0 * d2[j] + d2[j + 1]));
    lossAt(j);
  }
  out[n - 1] = -t * d2[n - 1] + ei * (invH2 * (d2[n - 2] - 2.0 * d2[n - 1]));
  lossAt(n - 1);
}

HAMILTONE_TARGET void stiffStencil(const double* a, double* d2, double* out, long n, double invH2,
                                   double t, double ei) {
  stiffSweeps<false>(a, d2, nullptr, out, nullptr, n, invH2, t, ei, 0.0);
}

HAMILTONE_TARGET void stiffLossStencil(const double* a, double* d2, const double* d2Prev,
                                       double* out, double* loss, long n, double invH2, double t,
                                       double ei, double cl) {
  stiffSweeps<true>(a, d2, d2Prev, out, loss, n, invH2, t, ei, cl);
}

HAMILTONE_TARGET void secondDifferenceOfDifference(const double* a, const double* b, double* out,
                                                   long n, double c) {
  if (n == 1) {
    out[0] = -2.0 * c * (a[0] - b[0]);
    return;
  }
  out[0] = c * ((a[1] - b[1]) - 2.0 * (a[0] - b[0]));
#pragma omp simd
  for (long j = 1; j < n - 1; ++j)
    out[j] = c * ((a[j - 1] - b[j - 1]) - 2.0 * (a[j] - b[j]) + (a[j + 1] - b[j + 1]));
  out[n - 1] = c * ((a[n - 2] - b[n - 2]) - 2.0 * (a[n - 1] - b[n - 1]));
}

// Whole registers, the five sums kept as lanes and each added once at the end as a tree; then the
// coordinates past the last whole register one by one. (An `omp simd` reduction here left GCC's
// partial sums on the stack and added them lane by lane: half the kernel's time on a short string.)
template <bool stiff, bool extra>
HAMILTONE_TARGET void savDotsOf(long n, const double* g, const double* q, const double* qm,
                                const double* minv, const double* kq, const double* x,
                                double xScale, double out[5]) {
  Lanes sq = {}, sqm = {}, sMKq = {}, sMx = {}, sMg = {};
  long i = 0;
  for (; i + kLanes <= n; i += kLanes) {
    const Lanes gi = loadLanes(g + i), mi = loadLanes(minv + i);
    sq += gi * loadLanes(q + i);
    sqm += gi * loadLanes(qm + i);
    if constexpr (stiff) sMKq += gi * (mi * loadLanes(kq + i));
    if constexpr (extra) sMx += gi * (mi * (xScale * loadLanes(x + i)));
    sMg += gi * mi * gi;
  }
  double tq = 0.0, tqm = 0.0, tMKq = 0.0, tMx = 0.0, tMg = 0.0;
  for (; i < n; ++i) {
    tq += g[i] * q[i];
    tqm += g[i] * qm[i];
    if constexpr (stiff) tMKq += g[i] * (minv[i] * kq[i]);
    if constexpr (extra) tMx += g[i] * (minv[i] * (xScale * x[i]));
    tMg += g[i] * minv[i] * g[i];
  }
  out[0] = laneSum(sq) + tq, out[1] = laneSum(sqm) + tqm, out[2] = laneSum(sMKq) + tMKq;
  out[3] = laneSum(sMx) + tMx, out[4] = laneSum(sMg) + tMg;
}

HAMILTONE_TARGET void savDots(long n, const double* g, const double* q, const double* qm,
                              const double* minv, const double* kq, const double* x, double xScale,
                              double out[5]) {
  if (kq && x) return savDotsOf<true, true>(n, g, q, qm, minv, kq, x, xScale, out);
  if (kq) return savDotsOf<true, false>(n, g, q, qm, minv, kq, x, xScale, out);
  if (x) return savDotsOf<false, true>(n, g, q, qm, minv, kq, x, xScale, out);
  savDotsOf<false, false>(n, g, q, qm, minv, kq, x, xScale, out);
}

// (40) solved by (33) at one coordinate, or at a register of them (T: double or Lanes).
template <bool stiff, bool extra, class T>
HAMILTONE_TARGET inline T savNext(T qi, T qmi, T mi, T gi, T kqi, T xi, double xScale, double down,
                                  double kk, double c, double invUp) {
  T b = 2.0 * qi - down * qmi;
  if constexpr (stiff) b -= kk * (mi * kqi);
  if constexpr (extra) b -= mi * (xScale * xi);
  return (b + c * (mi * gi)) * invUp;
}

// q^{n+1} element by element (the same bits on every path), its sum as savDotsOf's.
template <bool stiff, bool extra>
HAMILTONE_TARGET double savUpdateOf(long n, const double* g, const double* q, const double* qm,
                                    const double* minv, const double* kq, const double* x,
                                    double xScale, double down, double kk, double c, double invUp,
                                    double* qp) {
  Lanes sdq = {};
  long i = 0;
  for (; i + kLanes <= n; i += kLanes) {
    const Lanes gi = loadLanes(g + i), qmi = loadLanes(qm + i);
    const Lanes x1 = savNext<stiff, extra>(
        loadLanes(q + i), qmi, loadLanes(minv + i), gi, stiff ? loadLanes(kq + i) : Lanes{},
        extra ? loadLanes(x + i) : Lanes{}, xScale, down, kk, c, invUp);
    __builtin_memcpy(qp + i, &x1, sizeof x1);
    sdq += gi * (x1 - qmi);
  }
  double tail = 0.0;
  for (; i < n; ++i) {
    const double x1 = savNext<stiff, extra>(q[i], qm[i], minv[i], g[i], stiff ? kq[i] : 0.0,
                                            extra ? x[i] : 0.0, xScale, down, kk, c, invUp);
    qp[i] = x1;
    tail += g[i] * (x1 - qm[i]);
  }
  return laneSum(sdq) + tail;
}

HAMILTONE_TARGET double savUpdate(long n, const double* g, const double* q, const double* qm,
                                  const double* minv, const double* kq, const double* x,
                                  double xScale, double down, double kk, double c, double invUp,
                                  double* qp) {
  if (kq && x)
    return savUpdateOf<true, true>(n, g, q, qm, minv, kq, x, xScale, down, kk, c, invUp, qp);
  if (kq) return savUpdateOf<true, false>(n, g, q, qm, minv, kq, x, xScale, down, kk, c, invUp, qp);
  if (x) return savUpdateOf<false, true>(n, g, q, qm, minv, kq, x, xScale, down, kk, c, invUp, qp);
  return savUpdateOf<false, false>(n, g, q, qm, minv, kq, x, xScale, down, kk, c, invUp, qp);
}

template <bool stiff, bool extra>
HAMILTONE_TARGET void linearUpdateOf(long n, const double* q, const double* qm, const double* minv,
                                     const double* kq, const double* x, double xScale, double down,
                                     double kk, double invUp, double* qp) {
#pragma omp simd
  for (long i = 0; i < n; ++i) {
    double b = 2.0 * q[i] - down * qm[i];
    if constexpr (stiff) b -= kk * (minv[i] * kq[i]);
    if constexpr (extra) b -= minv[i] * (xScale * x[i]);
    qp[i] = b * invUp;
  }
}

HAMILTONE_TARGET void linearUpdate(long n, const double* q, const double* qm, const double* minv,
                                   const double* kq, const double* x, double xScale, double down,
                                   double kk, double invUp, double* qp) {
  if (kq && x)
    return linearUpdateOf<true, true>(n, q, qm, minv, kq, x, xScale, down, kk, invUp, qp);
  if (kq) return linearUpdateOf<true, false>(n, q, qm, minv, kq, x, xScale, down, kk, invUp, qp);
  if (x) return linearUpdateOf<false, true>(n, q, qm, minv, kq, x, xScale, down, kk, invUp, qp);
  linearUpdateOf<false, false>(n, q, qm, minv, kq, x, xScale, down, kk, invUp, qp);
}

// Whole registers, their sums kept as lanes and added once at the end; then the modes past the
// last whole register one by one (none where the modes are padded to kMaxLanes, as ModalTail's).
HAMILTONE_TARGET void modalStep(long n, const double* __restrict c1, const double* __restrict c2,
                                const double* const* w, double f, double* __restrict older,
                                const double* __restrict newer, double out[4]) {
  const double* __restrict w0 = w[0];
  const double* __restrict w1 = w[1];
  const double* __restrict w2 = w[2];
  const double* __restrict w3 = w[3];
  const Lanes force = Lanes{} + f;
  Lanes s0 = {}, s1 = {}, s2 = {}, s3 = {};
  long m = 0;
  for (; m + kLanes <= n; m += kLanes) {
    const Lanes pull = loadLanes(w2 + m);
    const Lanes x = loadLanes(c1 + m) * loadLanes(newer + m) -
                    loadLanes(c2 + m) * loadLanes(older + m) + force * pull;
    __builtin_memcpy(older + m, &x, sizeof x);
    s0 += loadLanes(w0 + m) * x;
    s1 += loadLanes(w1 + m) * x;
    s2 += pull * x;
    s3 += loadLanes(w3 + m) * x;
  }
  double p0 = laneSum(s0), p1 = laneSum(s1), p2 = laneSum(s2), p3 = laneSum(s3);
  for (; m < n; ++m) {
    const double x = c1[m] * newer[m] - c2[m] * older[m] + f * w2[m];
    older[m] = x;
    p0 += w0[m] * x;
    p1 += w1[m] * x;
    p2 += w2[m] * x;
    p3 += w3[m] * x;
  }
  out[0] = p0, out[1] = p1, out[2] = p2, out[3] = p3;
}

// modalStep with no force and one probe (v's modes).
HAMILTONE_TARGET double freeModalStep(long n, const double* __restrict c1,
                                      const double* __restrict c2, const double* __restrict w,
                                      double* __restrict older, const double* __restrict newer) {
  Lanes s = {};
  long m = 0;
  for (; m + kLanes <= n; m += kLanes) {
    const Lanes x =
        loadLanes(c1 + m) * loadLanes(newer + m) - loadLanes(c2 + m) * loadLanes(older + m);
    __builtin_memcpy(older + m, &x, sizeof x);
    s += loadLanes(w + m) * x;
  }
  double p = laneSum(s);
  for (; m < n; ++m) {
    older[m] = c1[m] * newer[m] - c2[m] * older[m];
    p += w[m] * older[m];
  }
  return p;
}

// `Rows` registers of rows from row i on, side by side: each row's recurrence is a chain of a
// product and a difference a step, so several run at once.
template <int Rows>
HAMILTONE_TARGET void sineRows(long i, long n, long terms, const double* in, const double* sinTheta,
                               const double* twoCos, double scale, double* out) {
  Lanes before[Rows] = {}, now[Rows], twoC[Rows], sum[Rows] = {};
  for (int r = 0; r < Rows; ++r) {
    now[r] = loadLanes(sinTheta + i + r * kLanes);
    twoC[r] = loadLanes(twoCos + i + r * kLanes);
  }
  for (long t = 0; t < terms; ++t) {
    for (int r = 0; r < Rows; ++r) {
      sum[r] += in[t] * now[r];
      const Lanes next = twoC[r] * now[r] - before[r];
      before[r] = now[r];
      now[r] = next;
    }
  }
  for (int r = 0; r < Rows; ++r) {
    sum[r] *= scale;
    const long count = std::min<long>(kLanes, n - i - r * kLanes);  // out holds n values
    if (count > 0) __builtin_memcpy(out + i + r * kLanes, &sum[r], count * sizeof(double));
  }
}

HAMILTONE_TARGET void sineSums(long n, long terms, const double* in, const double* sinTheta,
                               const double* twoCos, double scale, double* out) {
  constexpr long kRows = 4;
  long i = 0;
  for (; i + kRows * kLanes <= n; i += kRows * kLanes)
    sineRows<kRows>(i, n, terms, in, sinTheta, twoCos, scale, out);
  for (; i < n; i += kLanes) sineRows<1>(i, n, terms, in, sinTheta, twoCos, scale, out);
}

HAMILTONE_TARGET void matrixProduct(const double* a, long lda, const double* b, long ldb,
                                    long stepB, double* c, long ldc, long m, long k, long n) {
  // One register of rows × four columns of C held in registers while p runs; the last block's
  // missing columns repeat its last one, and are not stored.
  for (long j = 0; j < n; j += 4) {
    const double* b0 = b + ldb * j;
    const double* b1 = b + ldb * std::min(j + 1, n - 1);
    const double* b2 = b + ldb * std::min(j + 2, n - 1);
    const double* b3 = b + ldb * std::min(j + 3, n - 1);
    const long columns = std::min(4L, n - j);
    for (long i = 0; i < m; i += kLanes) {
      Lanes c0 = {}, c1 = {}, c2 = {}, c3 = {};
      for (long p = 0; p < k; ++p) {
        Lanes ap;
        __builtin_memcpy(&ap, a + i + lda * p, sizeof ap);
        c0 += ap * b0[stepB * p];
        c1 += ap * b1[stepB * p];
        c2 += ap * b2[stepB * p];
        c3 += ap * b3[stepB * p];
      }
      const Lanes* block[4] = {&c0, &c1, &c2, &c3};
      for (long t = 0; t < columns; ++t)
        __builtin_memcpy(c + i + ldc * (j + t), block[t], sizeof(Lanes));
    }
  }
}

// The grid loops run over whole padded rows as one loop (rows of 30 do not vectorise well) and
// put the border back afterwards.
HAMILTONE_TARGET void gridLaplacian(const double* f, long px, long ny, double cx, double cy,
                                    double* out) {
#pragma omp simd
  for (long i = px; i < px * (ny + 1); ++i)
    out[i] = cx * (f[i - 1] - 2.0 * f[i] + f[i + 1]) + cy * (f[i - px] - 2.0 * f[i] + f[i + px]);
  for (long row = 1; row <= ny; ++row) out[px * row] = out[px * row + px - 1] = 0.0;
}

HAMILTONE_TARGET void gridCells(const double* f, long px, long ny, double* cells) {
#pragma omp simd
  for (long i = px + 1; i < px * (ny + 2); ++i)
    cells[i] = f[i] - f[i - px] - f[i - 1] + f[i - px - 1];
}

HAMILTONE_TARGET void gridBracket(const double* f, const double* g, const double* cellsF,
                                  const double* cellsG, long px, long ny, double ix2, double iy2,
                                  double ixy2, double* out) {
  const double* cf = cellsF;
  const double* cg = cellsG;
  // Point i's four cells have upper corners i, i + 1, i + px and i + px + 1.
#pragma omp simd
  for (long i = px + 1; i < px * (ny + 1) - 1; ++i) {
    const double fxx = (f[i - 1] - 2.0 * f[i] + f[i + 1]) * ix2;
    const double fyy = (f[i - px] - 2.0 * f[i] + f[i + px]) * iy2;
    const double gxx = (g[i - 1] - 2.0 * g[i] + g[i + 1]) * ix2;
    const double gyy = (g[i - px] - 2.0 * g[i] + g[i + px]) * iy2;
    const double cross = cf[i] * cg[i] + cf[i + 1] * cg[i + 1] + cf[i + px] * cg[i + px] +
                         cf[i + px + 1] * cg[i + px + 1];
    out[i] = fxx * gyy + fyy * gxx - 0.5 * cross * ixy2;
  }
  for (long row = 1; row <= ny; ++row) out[px * row] = out[px * row + px - 1] = 0.0;
}

}  // namespace

extern const Kernels kernels{.isa = HAMILTONE_KERNEL_ISA,
                             .name = HAMILTONE_KERNEL_NAME,
                             .cellStretches = cellStretches,
                             .twoGridForces = twoGridForces,
                             .singleGridForces = singleGridForces,
                             .secondDifference = secondDifference,
                             .stiffStencil = stiffStencil,
                             .stiffLossStencil = stiffLossStencil,
                             .secondDifferenceOfDifference = secondDifferenceOfDifference,
                             .savDots = savDots,
                             .savUpdate = savUpdate,
                             .linearUpdate = linearUpdate,
                             .modalStep = modalStep,
                             .freeModalStep = freeModalStep,
                             .sineSums = sineSums,
                             .matrixProduct = matrixProduct,
                             .gridLaplacian = gridLaplacian,
                             .gridCells = gridCells,
                             .gridBracket = gridBracket};

}  // namespace hamiltone::HAMILTONE_KERNEL_NS
