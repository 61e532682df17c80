// The loops of body_loops.cpp, included once per instruction set with HAMILTONE_TARGET (a
// function attribute) and HAMILTONE_BODY_NS (its namespace) defined. The products take four
// points at a time: a's values are loaded once for four rows, g read and written once for four.
namespace HAMILTONE_BODY_NS {

HAMILTONE_TARGET void gather(const float* phi, long ld, const int* rows, long count, long modes,
                             const double* a, double* w) {
  long i = 0;
  for (; i + 4 <= count; i += 4) {
    const float *r0 = phi + rows[i] * ld, *r1 = phi + rows[i + 1] * ld,
                *r2 = phi + rows[i + 2] * ld, *r3 = phi + rows[i + 3] * ld;
    double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
#pragma omp simd reduction(+ : s0, s1, s2, s3)
    for (long m = 0; m < modes; ++m) {
      s0 += static_cast<double>(r0[m]) * a[m];
      s1 += static_cast<double>(r1[m]) * a[m];
      s2 += static_cast<double>(r2[m]) * a[m];
      s3 += static_cast<double>(r3[m]) * a[m];
    }
    w[rows[i]] = s0;
    w[rows[i + 1]] = s1;
    w[rows[i + 2]] = s2;
    w[rows[i + 3]] = s3;
  }
  for (; i < count; ++i) {
    const float* row = phi + rows[i] * ld;
    double s = 0.0;
#pragma omp simd reduction(+ : s)
    for (long m = 0; m < modes; ++m) s += static_cast<double>(row[m]) * a[m];
    w[rows[i]] = s;
  }
}

HAMILTONE_TARGET void project(const float* phi, long ld, long points, long modes, const double* f,
                              double* g) {
  for (long m = 0; m < modes; ++m) g[m] = 0.0;
  long k = 0;
  for (; k + 4 <= points; k += 4) {
    const double f0 = f[k], f1 = f[k + 1], f2 = f[k + 2], f3 = f[k + 3];
    if (f0 == 0.0 && f1 == 0.0 && f2 == 0.0 && f3 == 0.0) continue;  // points not in use
    const float *r0 = phi + k * ld, *r1 = r0 + ld, *r2 = r1 + ld, *r3 = r2 + ld;
#pragma omp simd
    for (long m = 0; m < modes; ++m)
      g[m] += ((static_cast<double>(r0[m]) * f0 + static_cast<double>(r1[m]) * f1) +
               static_cast<double>(r2[m]) * f2) +
              static_cast<double>(r3[m]) * f3;
  }
  for (; k < points; ++k) {
    const double fk = f[k];
    if (fk == 0.0) continue;
    const float* row = phi + k * ld;
#pragma omp simd
    for (long m = 0; m < modes; ++m) g[m] += static_cast<double>(row[m]) * fk;
  }
}

HAMILTONE_TARGET void partialsRow(long keys, const double* a1, const double* a2, const double* a3,
                                  const double* c, const double* sigma, const double* b,
                                  const double* w, double* prev, double* lost, double* f) {
#pragma omp simd
  for (long key = 0; key < keys; ++key) {
    f[key] -= c[key] * b[key];                                                               // (Y4)
    const double next = a1[key] * b[key] - a2[key] * prev[key] - a3[key] * c[key] * w[key];  // (Y3)
    const double d = next - prev[key];
    lost[key] += sigma[key] * d * d;
    prev[key] = next;
  }
}

}  // namespace HAMILTONE_BODY_NS
