// The loops of body_loops.cpp, included once per instruction set with HAMILTONE_TARGET (a
// function attribute), HAMILTONE_BODY_NS (its namespace) and HAMILTONE_BODY_LANES (the doubles in
// one of its vector registers) defined.
namespace HAMILTONE_BODY_NS {

constexpr int kLanes = HAMILTONE_BODY_LANES;
static_assert(kBodyPad % kLanes == 0);
typedef double Lanes __attribute__((vector_size(kLanes * sizeof(double))));
typedef float Floats __attribute__((vector_size(kLanes * sizeof(float))));

// kLanes floats as doubles, exactly: one conversion from memory (GCC splits its vector
// extension's conversion of eight floats in two halves and a shuffle).
HAMILTONE_TARGET inline Lanes widen(const float* p) {
#if defined(__x86_64__) && HAMILTONE_BODY_LANES == 8
  return _mm512_maskz_cvtps_pd(0xFF, _mm256_loadu_ps(p));  // (_mm512_cvtps_pd: GCC 12 warns)
#elif defined(__x86_64__) && HAMILTONE_BODY_LANES == 4
  return _mm256_cvtps_pd(_mm_loadu_ps(p));
#elif defined(__x86_64__) && HAMILTONE_BODY_LANES == 2
  return _mm_cvtps_pd(_mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p))));
#else
  Floats x;
  __builtin_memcpy(&x, p, sizeof x);
  return __builtin_convertvector(x, Lanes);
#endif
}

// `Regs` registers of outputs, columns j … j + Regs kLanes − 1 (`store` of them written): one
// product and one sum a row and register, the registers side by side, so that Regs chains run at
// once.
template <int Regs>
HAMILTONE_TARGET void combineTile(const float* m, long ld, long count, const double* x, long j,
                                  long store, double* out) {
  Lanes sum[Regs] = {};
  for (long i = 0; i < count; ++i) {
    if (x[i] == 0.0) continue;
    const Lanes xi = Lanes{} + x[i];
    const float* row = m + i * ld + j;
    for (int r = 0; r < Regs; ++r) sum[r] += widen(row + r * kLanes) * xi;
  }
  __builtin_memcpy(out + j, sum, store * sizeof(double));
}

// The last columns, fewer than eight registers: a tile of as many as they need.
template <int Regs>
HAMILTONE_TARGET void combineLast(const float* m, long ld, long count, const double* x, long j,
                                  long left, double* out) {
  if (left > (Regs - 1) * kLanes)
    combineTile<Regs>(m, ld, count, x, j, left, out);
  else if constexpr (Regs > 1)
    combineLast<Regs - 1>(m, ld, count, x, j, left, out);
}

HAMILTONE_TARGET void combineRows(const float* m, long ld, long count, const double* x, long from,
                                  long to, double* out) {
  constexpr long kWide = 8 * kLanes;
  long j = from;
  for (; j + kWide <= to; j += kWide) combineTile<8>(m, ld, count, x, j, kWide, out);
  if (j < to) combineLast<8>(m, ld, count, x, j, to - j, out);
}

// A register of each of `Rows` rows of m at a time against x's: each row's sum kept as lanes to
// the end, then added as a tree (halves, then quarters, …), then its columns past the last whole
// register one by one.
template <int Rows>
HAMILTONE_TARGET void dotTile(const float* m, long ld, const int* rows, long columns,
                              const double* x, double* out) {
  const float* row[Rows];
  for (int r = 0; r < Rows; ++r) row[r] = m + rows[r] * ld;
  Lanes sum[Rows] = {};
  long c = 0;
  for (; c + kLanes <= columns; c += kLanes) {
    Lanes xc;
    __builtin_memcpy(&xc, x + c, sizeof xc);
    for (int r = 0; r < Rows; ++r) sum[r] += widen(row[r] + c) * xc;
  }
  for (int r = 0; r < Rows; ++r) {
    double lane[kLanes];
    __builtin_memcpy(lane, &sum[r], sizeof lane);
    for (int width = kLanes / 2; width > 0; width /= 2)
      for (int i = 0; i < width; ++i) lane[i] += lane[i + width];
    double total = lane[0];
    for (long rest = c; rest < columns; ++rest)
      total += static_cast<double>(row[r][rest]) * x[rest];
    out[rows[r]] = total;
  }
}

HAMILTONE_TARGET void dotRows(const float* m, long ld, const int* rows, long count, long columns,
                              const double* x, double* out) {
  long i = 0;
  for (; i + 4 <= count; i += 4) dotTile<4>(m, ld, rows + i, columns, x, out);
  for (; i < count; ++i) dotTile<1>(m, ld, rows + i, columns, x, out);
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
