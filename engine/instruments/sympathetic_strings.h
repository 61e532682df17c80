// The strings that ring in sympathy: every key's unison as the first partials of a stiff string
// pinned at its far end and standing on the soundboard's bridge, coupled to it explicitly and
// conservatively.
#pragma once

#include <Eigen/Dense>
#include <span>
#include <vector>

#include "instruments/body_loops.h"
#include "instruments/soundboard.h"

namespace hamiltone {

struct SympatheticKey {
  double f0 = 261.6;              // Hz
  double inharmonicityB = 4e-4;   // f_n = n f0 sqrt(1 + B n²)
  double linearDensity = 7.8e-3;  // ρA, kg/m
  double length = 0.64;           // L, m
  double tension = 670.0;         // T0, N
  int unisons = 3;
  double t60Low = 8.0;   // s, at 0 Hz (docs/instrument-data.md §3.4); +inf: lossless
  double t60High = 2.0;  // s, at t60HighHz; +inf: lossless
  double t60HighHz = 2000.0;
  double damperT60 = 0.5;  // s, the damper's own decay, added to the string's; +inf: no damper
};

// The concert grand's keys lowestNote … highestNote (MIDI 21 … 108): the strings of pianoString()
// tuned to equal temperament (A4 = 440 Hz) with their B, the unisons of docs/instrument-data.md
// §1.4, the string's own loss of RT-425 (§2.1: the board adds its share through the coupling) and
// the damper's T60 of §3.2 (no damper from F6 up).
std::vector<SympatheticKey> grandSympatheticKeys(int lowestNote = 21, int highestNote = 108);

// String j of key k, on 0 ≤ x ≤ L with u(0) = 0 and u(L) = w_k, the board at the bridge, u'' = 0 at
// both ends. Its partials a_n = (2/L) ∫ u sin(nπx/L) dx (the sine coefficients of u itself, the
// end included); integrating ρA ü = T u'' − EI u'''' against sin(nπx/L) by parts leaves the
// end's terms (Y1):
//   M_n ä_n = −K_n a_n − C_n w,   M_n = ρA L/2,   K_n = (L/2) T ν²(1 + Bn²),
//   C_n = (−1)^n ν T (1 + Bn²),   ν = nπ/L,  B = π² EI/(T L²)                         (Y1)
// and the force on the bridge is −T u'(L) + EI u'''(L) = −Σ_n C_n a_n − κ w. The energy
//   H = Σ_n [M_n/2 ȧ_n² + K_n/2 a_n²] + w Σ_n C_n a_n + κ/2 w²,  κ = T/L + Σ_n C_n²/K_n   (Y2)
// is T/2 ∫u'² + EI/2 ∫u''² of the truncated series: ≥ 0 (complete the square in each a_n), the
// static end stiffness exactly T/L, and the bridge's dynamic stiffness −F/w = T/L − Σ_n C_n²
// ω²M_n/(K_n(K_n − ω²M_n)) is the partial-fraction expansion of T k cot(kL) cut at P partials.
// The U unisons are identical, so only their in-phase motion couples: one string of U times the
// mass, stiffness and coupling. Discretely (K̂_n for the exact frequency, centred loss σ_n):
//   M_n δtt a_n = −K̂_n a_n^n − 2M_nσ_n δt· a_n − C_n w^n                               (Y3)
//   board force  F_k^n = −κ_k w_k^n − Σ_n C_n a_n^n                                       (Y4)
//   H_c^{n+½} = Σ_k κ_k/2 w_k^{n+1} w_k^n + Σ_n C_n (a_n^{n+1} w^n + a_n^n w^{n+1})/2       (Y5)
// so board + strings conserve H_board + H_strings + H_c exactly (the coupling matrix is symmetric
// and taken at level n on both sides). Stability: with A = K̂_board + Φᵀ diag(κ) Φ the board's
// stiffness with the strings' springs, the whole stiffness is ⪯ 2 (A ⊕ K̂_strings), so H > 0 if
//   k² λmax(A/M_board) < 2   and   k² ω̂_n² < 2 (every partial below fs/4)              (Y6)
// which prepare() checks; κ_k is the stiffness the strings add at key k's bridge point.
class SympatheticStrings {
 public:
  // May allocate. One key per bridge point of `board`; partials up to maxHz (< fs/4) and at most
  // maxPartials per key. Throws std::invalid_argument naming the key, field, value and range.
  void prepare(std::span<const SympatheticKey> keys, const Soundboard& board, double sampleRate,
               double maxHz, int maxPartials = 16);
  void reset() noexcept;  // at rest, dampers as set, tallies zero

  // 0: lifted (the string's own loss); 1: the damper on, adding ln(1000)/damperT60 to every
  // partial's decay rate; between, `contact` times that.
  void setDamper(int key, double contact) noexcept;
  // An excluded key's strings leave the coupling (a voice plays them); it returns at rest on the
  // board, statically attached. w, wPrev: the key's w^{n+1}, w^n. The jump in H_strings + H_c is
  // returned (J): PianoBody books it.
  double setExcluded(int key, bool excluded, double w, double wPrev) noexcept;
  bool excluded(int key) const noexcept { return excluded_[key] != 0; }
  // A damped key gone quiet sleeps: it leaves the coupling like an excluded one, so the board
  // need not compute w at its point; it wakes, at rest on the board, when the board moves it or
  // its damper lifts (PianoBody).
  // Both return the jump in H_strings + H_c, J.
  double sleep(int key, double w, double wPrev) noexcept;
  double wake(int key, double w, double wPrev) noexcept;
  bool asleep(int key) const noexcept { return asleep_[key] != 0; }
  bool coupled(int key) const noexcept { return !excluded_[key] && !asleep_[key]; }
  // The damper fully on (a key without one never is).
  bool damped(int key) const noexcept;

  // (Y3): level n → n+1 given w = w^n; adds the strings' forces (Y4) at level n on the board's
  // points to `forces`, N (one pass over the coupled keys' partials for both).
  void step(const Eigen::VectorXd& w, std::span<double> forces) noexcept;

  // H_strings + H_c at n+½ given w^{n+1} (w) and w^n (wPrev), J.
  double energy(const Eigen::VectorXd& w, const Eigen::VectorXd& wPrev) const noexcept;
  double dissipated() const noexcept;  // J; a sum over the partials, not for every sample
  // One key's string energy Σ M/2 (δt₋ a)² + K̂/2 a^n a^{n−1}, J (no coupling term).
  double keyEnergy(int key) const noexcept;
  // The same of its motion about the bridge's static shape, a_n + C_n w/K̂_n (w, wPrev: w^{n+1},
  // w^n): what rings, not what merely follows the board; J.
  double ringingEnergy(int key, double w, double wPrev) const noexcept;
  // What its strings hold when they merely follow the board at w, in the static shape u = w x/L:
  // ½ U T0/L w², J.
  double followingEnergy(int key, double w) const noexcept {
    const SympatheticKey& s = data_[key];
    return 0.5 * s.unisons * s.tension / s.length * w * w;
  }

  int keys() const noexcept { return keys_; }
  int partials(int key) const noexcept { return partials_[key]; }
  double partialHz(int key, int n) const noexcept;                        // n = 1 … partials(key)
  double bridgeStiffness(int key) const noexcept { return kappa_[key]; }  // κ_k, N/m
  double partialDecayRate(int key, int n) const noexcept { return sigma_[slot(key, n)]; }
  double partialAmplitude(int key, int n) const noexcept { return b_[slot(key, n)]; }

 private:
  Eigen::Index slot(int key, int n) const noexcept {
    return static_cast<Eigen::Index>(n - 1) * keys_ + key;
  }
  void setCoefficients(int key) noexcept;
  void findRuns() noexcept;
  double couple(int key, double w, double wPrev) noexcept;  // applies coupled(key); the jump
  double keyCoupling(int key, double w, double wPrev) const noexcept;
  std::vector<SympatheticKey> data_;
  double k_ = 0.0;
  int keys_ = 0, rows_ = 0;  // rows_: the most partials of any key
  std::vector<int> partials_, rowLength_;
  const BodyLoops* loops_ = nullptr;
  std::vector<double> contact_;
  std::vector<char> excluded_, asleep_;
  std::vector<std::pair<int, int>> runs_;  // the keys step() steps: [first, last), ascending
  bool runsStale_ = true;
  Eigen::VectorXd kappa_, kappaOn_;  // κ_k in use (0 when excluded) and as prepared
  // Per partial slot (n − 1) keys + key: mass, K̂, ω, own σ, σ in use, coupling in use and as
  // prepared, step coefficients.
  Eigen::VectorXd mass_, stiffness_, omega_, sigmaOwn_, sigma_, c_, cOn_, a1_, a2_, a3_;
  Eigen::VectorXd b_, bPrev_;
  Eigen::VectorXd lost_;  // per slot, Σ σ (a^{n+1} − a^{n−1})²: times M/2k, what the loss took
};

}  // namespace hamiltone
