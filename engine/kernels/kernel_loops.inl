// The loops of kernels.h, included by one file per instruction set, each of which defines
// HAMILTONE_TARGET (a function attribute) and HAMILTONE_KERNEL_NS (its namespace). Everything
// here has internal linkage or that namespace's name, so no inline function compiled for one
// instruction set can be taken by the linker for another.
namespace hamiltone::HAMILTONE_KERNEL_NS {
namespace {

HAMILTONE_TARGET void cellStretches(const double* up, const double* eta, long mv, int r,
                                    double invH, double* scratch, double* zetaOverS, double* strain,
                                    double* sumInverse) {
  const long m = mv * r;
  double* a = scratch;
  double* b = scratch + m;
  double* excess = scratch + 2 * m;
  double* inverse = scratch + 3 * m;
  for (long j = 0; j < mv; ++j) {
    const double aj = (1.0 + eta[j]) * (1.0 + eta[j]), bj = 2.0 * eta[j] + eta[j] * eta[j];
#pragma omp simd
    for (int l = 0; l < r; ++l) a[j * r + l] = aj, b[j * r + l] = bj;
  }
  // One loop over the whole fine grid, which vectorises (a loop per cell of r = 8…11 does not).
#pragma omp simd
  for (long l = 0; l < m; ++l) {
    const double zeta = (up[l + 1] - up[l]) * invH, z2 = zeta * zeta;
    const double stretch = __builtin_sqrt(a[l] + z2);
    const double t = 1.0 / (stretch * (stretch + 1.0));  // one division for all three
    const double inv = (stretch + 1.0) * t;
    excess[l] = (b[l] + z2) * stretch * t;
    inverse[l] = inv;
    zetaOverS[l] = zeta * inv;
  }
  const double invR = 1.0 / r;
  for (long j = 0; j < mv; ++j) {
    double e = 0.0, i = 0.0;
    for (int l = 0; l < r; ++l) {
      e += excess[j * r + l];
      i += inverse[j * r + l];
    }
    strain[j] = e * invR;
    sumInverse[j] = i;
  }
}

HAMILTONE_TARGET void fineForces(long mv, int r, double c, double invH, const double* strain,
                                 double* scratch, const double* zetaOverS, double* gu) {
  const long m = mv * r;
  double* w = scratch;
  for (long j = 0; j < mv; ++j) {
    const double wj = c * strain[j];
#pragma omp simd
    for (int l = 0; l < r; ++l) w[j * r + l] = wj;
  }
#pragma omp simd
  for (long l = 0; l < m - 1; ++l)
    gu[l] = (zetaOverS[l] * w[l] - zetaOverS[l + 1] * w[l + 1]) * invH;
}

HAMILTONE_TARGET double singleGridForces(const double* up, const double* vp, long m, double invH,
                                         double c, double* wz, double* we, double* gu, double* gv) {
  double sum = 0.0;
#pragma omp simd reduction(+ : sum)
  for (long l = 0; l < m; ++l) {
    const double zeta = (up[l + 1] - up[l]) * invH, eta = (vp[l + 1] - vp[l]) * invH;
    const double stretch = __builtin_sqrt((1.0 + eta) * (1.0 + eta) + zeta * zeta);
    const double excess = (2.0 * eta + eta * eta + zeta * zeta) / (stretch + 1.0);
    const double phi = excess / stretch;
    wz[l] = c * phi * zeta;
    we[l] = c * phi * (1.0 + eta);
    sum += excess * excess;
  }
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

HAMILTONE_TARGET void stiffStencil(const double* a, double* d2, double* out, long n, double invH2,
                                   double t, double ei) {
  secondDifference(a, d2, n, invH2);
  if (n == 1) {
    out[0] = -t * d2[0] + ei * (-2.0 * invH2 * d2[0]);
    return;
  }
  out[0] = -t * d2[0] + ei * (invH2 * (d2[1] - 2.0 * d2[0]));
#pragma omp simd
  for (long j = 1; j < n - 1; ++j)
    out[j] = -t * d2[j] + ei * (invH2 * (d2[j - 1] - 2.0 * d2[j] + d2[j + 1]));
  out[n - 1] = -t * d2[n - 1] + ei * (invH2 * (d2[n - 2] - 2.0 * d2[n - 1]));
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

template <bool stiff, bool extra>
HAMILTONE_TARGET void savDotsOf(long n, const double* g, const double* q, const double* qm,
                                const double* minv, const double* kq, const double* x,
                                double xScale, double out[5]) {
  double sq = 0.0, sqm = 0.0, sMKq = 0.0, sMx = 0.0, sMg = 0.0;
#pragma omp simd reduction(+ : sq, sqm, sMKq, sMx, sMg)
  for (long i = 0; i < n; ++i) {
    sq += g[i] * q[i];
    sqm += g[i] * qm[i];
    if constexpr (stiff) sMKq += g[i] * (minv[i] * kq[i]);
    if constexpr (extra) sMx += g[i] * (minv[i] * (xScale * x[i]));
    sMg += g[i] * minv[i] * g[i];
  }
  out[0] = sq, out[1] = sqm, out[2] = sMKq, out[3] = sMx, out[4] = sMg;
}

HAMILTONE_TARGET void savDots(long n, const double* g, const double* q, const double* qm,
                              const double* minv, const double* kq, const double* x, double xScale,
                              double out[5]) {
  if (kq && x) return savDotsOf<true, true>(n, g, q, qm, minv, kq, x, xScale, out);
  if (kq) return savDotsOf<true, false>(n, g, q, qm, minv, kq, x, xScale, out);
  if (x) return savDotsOf<false, true>(n, g, q, qm, minv, kq, x, xScale, out);
  savDotsOf<false, false>(n, g, q, qm, minv, kq, x, xScale, out);
}

template <bool stiff, bool extra>
HAMILTONE_TARGET double savUpdateOf(long n, const double* g, const double* q, const double* qm,
                                    const double* minv, const double* kq, const double* x,
                                    double xScale, double down, double kk, double c, double invUp,
                                    double* qp) {
  double sdq = 0.0;
#pragma omp simd reduction(+ : sdq)
  for (long i = 0; i < n; ++i) {
    double b = 2.0 * q[i] - down * qm[i];
    if constexpr (stiff) b -= kk * (minv[i] * kq[i]);
    if constexpr (extra) b -= minv[i] * (xScale * x[i]);
    qp[i] = (b + c * (minv[i] * g[i])) * invUp;
    sdq += g[i] * (qp[i] - qm[i]);
  }
  return sdq;
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

}  // namespace

extern const Kernels kernels{.isa = HAMILTONE_KERNEL_ISA,
                             .name = HAMILTONE_KERNEL_NAME,
                             .cellStretches = cellStretches,
                             .fineForces = fineForces,
                             .singleGridForces = singleGridForces,
                             .secondDifference = secondDifference,
                             .stiffStencil = stiffStencil,
                             .secondDifferenceOfDifference = secondDifferenceOfDifference,
                             .savDots = savDots,
                             .savUpdate = savUpdate};

}  // namespace hamiltone::HAMILTONE_KERNEL_NS
