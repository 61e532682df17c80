// The hot loops of the string and plate voices, compiled for several instruction sets and chosen
// once per process (when the first string or scheme is built) from what the CPU reports: plain
// x86-64 (SSE2), x86-64-v3 (AVX2 + FMA) and x86-64-v4 (AVX-512). The same path on the same CPU
// gives the same bits run to run; two paths differ in the order of their sums (the vector width),
// by roundoff.
#pragma once

#include <string>
#include <string_view>

namespace hamiltone {

enum class Isa { portable, avx2, avx512 };
constexpr int kMaxLanes = 8;  // doubles in the widest vector register (AVX-512)

struct TwoGridSums {
  double squaredStrains;  // Σ_J ε_J²
  double endTension;      // N beyond T0, at the string's far end
};
// The doubles of cellStretches' and twoGridForces' work on m fine segments and mv coarse cells.
constexpr long twoGridStrainsWork(long m, long mv) { return m + kMaxLanes + mv; }
constexpr long twoGridWork(long m, long mv) { return twoGridStrainsWork(m, mv) + 2 * mv; }

struct Kernels {
  Isa isa;
  const char* name;
  // The two grids' strains (docs/string-grids.md): from u (nodes 1 … m − 1 at u[0 … m − 2],
  // m = mv r, the ends u_0 = u_m = 0 not stored; nothing past them is read) and v (mv − 1), u
  // with its ends into work (m + kMaxLanes values, zeros past u_m) and η_J = (D₋v)_J after it
  // (mv values: twoGridStrainsWork(m, mv) in all); then each fine segment's slope
  // ζ_l = (u_{l+1} − u_l) invH, each cell's mean square slope Z_J = (1/r) Σ_{l∈J} ζ_l² (four
  // partial sums over l ≡ 0, 1, 2, 3 (mod 4) from the cell's first segment, added as
  // (p0 + p1) + (p2 + p3) on every path), its stretch S_J = sqrt((1 + η_J)² + Z_J),
  // strain_J = S_J − 1 (as (2η + η² + Z)/(S + 1): no cancellation at small strain) and
  // inverseStretch_J = 1/S_J.
  void (*cellStretches)(const double* u, const double* v, long mv, int r, double invH, double invHv,
                        double* work, double* strain, double* inverseStretch);
  // The two grids' gradient in one call (NonlinearString::twoGridGradient): from u and v as
  // cellStretches takes them, its strains, the weights w_J = c ε_J/S_J of
  // ∂V'/∂ζ_l = w_J ζ_l and ∂V'/∂η_J = c r (ε_J/S_J)(1 + η_J), then gu = D₋ᵀ(∂V'/∂ζ) (at node i,
  // gu[i − 1]: −w_J (u_{i−1} − 2u_i + u_{i+1}) invH² where segments i − 1 and i lie in cell J,
  // (w_J ζ_{i−1} − w_{J+1} ζ_i) invH where segment i − 1 is J's last) and gv = D₋ᵀ(∂V'/∂η) on the
  // coarse grid (mv − 1). work: twoGridWork(m, mv) doubles, cellStretches' first. Returns
  // Σ_J ε_J² and the end's pull beyond T0, T0 η_{mv−1} + (∂V'/∂η)_{mv−1} invHv
  // (NonlinearString::endTension). The same bits on every path, as cellStretches'.
  TwoGridSums (*twoGridForces)(const double* u, const double* v, long mv, int r, double invH,
                               double invHv, double c, double tension, double* work, double* gu,
                               double* gv);
  // One grid (BDZ (65)): with up, vp the padded u and v (m + 1 values), ζ_l, η_l their strains
  // and φ_l = (s_l − 1)/s_l, ∂V'/∂ζ_l = c φ_l ζ_l into wz and ∂V'/∂η_l = c φ_l (1 + η_l) into we
  // (m each), gu = D₋ᵀwz and gv = D₋ᵀwe (m − 1 each); returns Σ (s_l − 1)².
  double (*singleGridForces)(const double* up, const double* vp, long m, double invH, double c,
                             double* wz, double* we, double* gu, double* gv);
  // out_j = c (a_{j−1} − 2a_j + a_{j+1}), j < n, a = 0 beyond both ends.
  void (*secondDifference)(const double* a, double* out, long n, double c);
  // The stiff string's h (−βT0 D2 + EI D2²) a, D2 a = 0 at the ends (simply supported): d2 =
  // invH2 D2 a (n values), then out_j = −t d2_j + ei invH2 (D2 d2)_j in one more sweep — the
  // operations of two secondDifference passes and the sum, one pass fewer.
  void (*stiffStencil)(const double* a, double* d2, double* out, long n, double invH2, double t,
                       double ei);
  // stiffStencil with the frequency-dependent loss of the same grid in its second sweep:
  // loss_j = cl (d2_j − d2Prev_j), d2Prev the d2 this kernel (or secondDifference with c = invH2)
  // left for the last state — cl D2(a − b)/h², the stencil of the difference not taken again.
  void (*stiffLossStencil)(const double* a, double* d2, const double* d2Prev, double* out,
                           double* loss, long n, double invH2, double t, double ei, double cl);
  // The same of a − b, the difference taken as it is read.
  void (*secondDifferenceOfDifference)(const double* a, const double* b, double* out, long n,
                                       double c);
  // The split scheme's first pass with one part loaded (sav.h), x read as xScale·x: out = (gᵀq,
  // gᵀqm, gᵀM⁻¹Kq, gᵀM⁻¹x, gᵀM⁻¹g); kq or x null: that sum is 0.
  void (*savDots)(long n, const double* g, const double* q, const double* qm, const double* minv,
                  const double* kq, const double* x, double xScale, double out[5]);
  // Its second pass: qp_i = (2q_i − down qm_i − kk M⁻¹kq_i − M⁻¹x_i + c M⁻¹g_i) invUp (the kq and
  // x terms absent when null, x read as xScale·x); returns gᵀ(qp − qm).
  double (*savUpdate)(long n, const double* g, const double* q, const double* qm,
                      const double* minv, const double* kq, const double* x, double xScale,
                      double down, double kk, double c, double invUp, double* qp);
  // The same with no part loaded (g = 0: the linear string, sav.h): qp_i = (2q_i − down qm_i −
  // kk M⁻¹kq_i − M⁻¹x_i) invUp.
  void (*linearUpdate)(long n, const double* q, const double* qm, const double* minv,
                       const double* kq, const double* x, double xScale, double down, double kk,
                       double invUp, double* qp);

  // The modal tail's step (voices/modal_tail.h) over n modes: x_m = c1_m newer_m − c2_m older_m
  // + f w[2]_m (w[2] the modal weights of the bridge's pull, along which its force acts, f that
  // force scaled to a mode's step), written over older; out[p] = Σ_m w[p]_m x_m for the four
  // probes, summed in vector registers (the order differs between paths).
  void (*modalStep)(long n, const double* c1, const double* c2, const double* const* w, double f,
                    double* older, const double* newer, double out[4]);
  // The same with no force and one probe w (v's modes): returns Σ_m w_m x_m.
  double (*freeModalStep)(long n, const double* c1, const double* c2, const double* w,
                          double* older, const double* newer);

  // The modal tail's sine transform (DST-I, unnormalised): out_i = scale Σ_{t<terms} in_t
  // sin((t + 1) θ_i) for i < n, from sin θ_i and 2 cos θ_i (kMaxLanes values past n, finite),
  // the sines by their recurrence sin((t+1)θ) = 2 cos θ sin(tθ) − sin((t−1)θ), each row apart: the
  // same bits on every path.
  void (*sineSums)(long n, long terms, const double* in, const double* sinTheta,
                   const double* twoCos, double scale, double* out);

  // The plate's loops. C = A B, column-major, A m × k (leading dimension lda), B k × n read as
  // b_pj = b[stepB p + ldb j], C m × n; m a multiple of 8. Each c_ij is Σ_p a_ip b_pj summed in
  // order of p: the same bits on every path.
  void (*matrixProduct)(const double* a, long lda, const double* b, long ldb, long stepB, double* c,
                        long ldc, long m, long k, long n);
  // On zero-bordered grids — ny rows of px = nx + 2 values between a zero row above and below,
  // the first and last value of a row zero — out = cx D_xx f + cy D_yy f, its border zero again.
  void (*gridLaplacian)(const double* f, long px, long ny, double cx, double cy, double* out);
  // The mixed difference of each cell, at the index of its upper corner:
  // cells_i = f_i − f_{i−px} − f_{i−1} + f_{i−px−1}, for i from px + 1 to px (ny + 2) − 1.
  void (*gridCells)(const double* f, long px, long ny, double* cells);
  // ℓ(f, g) of (78) into out, its border zero: at each interior point
  // ix2 iy2 (δxx f δyy g + δyy f δxx g) − ½ ixy2 Σ of the four cells' products around it.
  void (*gridBracket)(const double* f, const double* g, const double* cellsF, const double* cellsG,
                      long px, long ny, double ix2, double iy2, double ixy2, double* out);
};

// The best path this CPU runs, or the one HAMILTONE_ISA names (portable, avx2, avx512): decided
// once per process. Throws std::runtime_error when HAMILTONE_ISA names an unknown path or one
// this CPU cannot run.
const Kernels& selectedKernels();
// A given path (tests and benchmarks compare them); throws std::runtime_error as above.
const Kernels& kernelsFor(Isa isa);
const Kernels& kernelsNamed(std::string_view name);  // by its name in isaNames()
bool cpuRuns(Isa isa);
std::string isaNames();  // "portable, avx2, avx512"

}  // namespace hamiltone
