// The piano's body: the soundboard and the sympathetic strings as one linear conservative system,
// stepped once per sample on one thread; the keys' voices drive it with their bridge forces.
#pragma once

#include <span>

#include "instruments/soundboard.h"
#include "instruments/sympathetic_strings.h"

namespace hamiltone {

struct PianoBodySpec {
  SoundboardPhysics board;
  double sampleRate = 48000.0;
  double sympatheticMaxHz = 4500.0;  // partials up to here (< fs/4): C8's fundamental too …
  int sympatheticMaxPartials = 16;   // … and at most this many per key
  BoardPoint pickups[2] = {{0.45, 0.35}, {1.2, 0.9}};  // m
};

// One step: the board takes the voices' forces F_ext and the strings' (Y4), both at level n, the
// strings take w^n; then both advance. H_board + H_strings + H_c + dissipated − supplied is
// constant to roundoff, supplied = Σ_n Σ_k F_ext,k^n (w_k^{n+1} − w_k^{n−1})/2.
class PianoBody {
 public:
  // May allocate; one key per bridge point. Throws std::invalid_argument (see the parts).
  void prepare(const PianoBodySpec& spec, std::span<const BoardPoint> bridgePoints,
               std::span<const SympatheticKey> keys);
  void reset() noexcept;

  // One force per key point, N, at any point: the board takes it through its modes.
  void step(std::span<const double> bridgeForces) noexcept;
  void output(double& left, double& right) const noexcept { board_.pickups(left, right); }

  // Lifting a sleeping key's damper wakes it (below).
  void setDamper(int key, double contact) noexcept;
  // A key a voice is playing: its sympathetic strings leave the coupling; the energy they take
  // away (or bring back) is booked in dissipated(), so the balance holds across the switch. The
  // voice drives its point through step()'s forces. Excluding a key (a strike) also wakes every
  // sleeping key and keeps them all awake for 50 ms, while the struck string's wave travels.
  void setExcluded(int key, bool excluded) noexcept;
  // Points in use: where the board computes w, the keys whose strings are coupled. A step costs
  // modes × (points in use + points driven) for the board's two products, and the coupled keys'
  // partials. Every 256 steps a key whose damper is on, whose strings ring (about the shape the
  // bridge gives them) with less than the floor (J) and would hold less than the floor following
  // the board in their static shape (½ U T0/L w²) sleeps — it leaves the coupling, booked like an
  // exclusion — until the board moves it past four floors or its damper lifts. Keys without
  // dampers never sleep. The floor is the larger of `joules` and `relative` times the body's
  // energy: damped strings still ring a little while the voices drive the board (1e-3 to 1e-2 of
  // it each, measured), so only a relative floor lets them sleep then — at the price of that
  // ring.
  void setQuietFloor(double joules, double relative = 0.0) noexcept {
    quietFloor_ = joules;
    quietRelative_ = relative;
  }
  int pointsInUse() const noexcept { return board_.activePoints(); }

  double energy() const noexcept;  // H^{n+½}: board + strings + coupling, J
  double dissipated() const noexcept {
    return board_.dissipated() + strings_.dissipated() + switched_;
  }
  double supplied() const noexcept { return supplied_; }

  int keys() const noexcept { return board_.points(); }
  // w at a key's point: current where its strings are coupled (a point in use), stale elsewhere.
  double displacement(int key) const noexcept { return board_.displacement(key); }
  const Soundboard& board() const noexcept { return board_; }
  const SympatheticStrings& strings() const noexcept { return strings_; }

 private:
  Soundboard board_;
  SympatheticStrings strings_;
  void sleepAndWakeKeys() noexcept;
  void wakeAtRest(int key) noexcept;
  void updateActivePoints() noexcept;
  Eigen::VectorXd forces_;  // the strings' (Y4), per point
  std::vector<int> active_;
  double supplied_ = 0.0, switched_ = 0.0;
  double quietFloor_ = 1e-12, quietRelative_ = 0.0;
  int sinceCheck_ = 0;
  int awakeSteps_ = 0, awakeLeft_ = 0;  // no key sleeps for awakeLeft_ more steps (a strike)
};

}  // namespace hamiltone
