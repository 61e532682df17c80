// The bridge's mass–spring–resistance step and its coupling to the strings' last nodes.
#include "instruments/bridge.h"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "util/format_number.h"

namespace hamiltone {

BridgeCoupling::BridgeCoupling(const NonlinearString& string)
    : last_(string.transverseSize() - 1), second_(last_ > 0 ? last_ - 1 : last_) {
  const StringPhysics& p = string.physics();
  const double h = string.spacing();
  const double tension = string.tensionScale() * p.tension / h;  // βT0/h
  const double bending = p.young * p.inertia / (h * h * h);      // EI/h³
  c1_ = -(tension + 2.0 * bending);
  c2_ = last_ > 0 ? bending : 0.0;  // one node: u_{M−2} is the fixed end
  self_ = tension + bending;
}

void Bridge::prepare(const BridgePhysics& p, double k, double addedStiffness) {
  auto require = [](bool ok, const char* field, double value, const std::string& valid) {
    if (!ok)
      throw std::invalid_argument(std::string(field) + " = " + formatNumber(value) + ": must be " +
                                  valid);
  };
  require(std::isfinite(p.mass) && p.mass > 0.0, "bridge_mass_kg", p.mass, "a finite mass > 0 kg");
  require(std::isfinite(p.stiffness) && p.stiffness >= 0.0, "bridge_stiffness_N_m", p.stiffness,
          "a finite number >= 0 N/m");
  require(std::isfinite(p.resistance) && p.resistance >= 0.0, "bridge_resistance_kg_s",
          p.resistance, "a finite number >= 0 kg/s");
  require(p.angle >= 0.0 && p.angle <= kMaxBridgeAngle, "bridge_angle_deg",
          p.angle * 180.0 / std::numbers::pi, "between 0 and 10 degrees");
  require(p.angle == 0.0 || p.resistance > 0.0, "bridge_resistance_kg_s", p.resistance,
          "> 0 kg/s where the bridge's angle is above 0: only the resistance ends the motion the "
          "strings' tension drives (bridge.h)");
  // Störmer–Verlet's bound on the bridge's own row, the strings' K_s included.
  const double stiffest = p.stiffness + addedStiffness;
  require(k * k * stiffest / p.mass < 4.0, "bridge_mass_kg", p.mass,
          "above k² (K_b + ΣK_s)/4 = " + formatNumber(k * k * stiffest / 4.0) +
              " kg at this rate, or the explicit coupling is unstable");
  physics_ = p;
  k_ = k;
  invUp_ = 1.0 / (1.0 + p.resistance * k / (2.0 * p.mass));
  down_ = 1.0 - p.resistance * k / (2.0 * p.mass);
  rate_ = 1.0 / k;
  kkOverM_ = k * k / p.mass;
  reset();
}

void Bridge::reset() noexcept {
  w0_ = w1_ = d0_ = d1_ = 0.0;
  dissipated_ = supplied_ = 0.0;
}

double Bridge::advance(double& before, double& now, double force) noexcept {
  const double next =
      (2.0 * now - down_ * before + kkOverM_ * (force - physics_.stiffness * now)) * invUp_;
  const double velocity = 0.5 * (next - before) * rate_;  // δt· w
  dissipated_ += physics_.resistance * k_ * velocity * velocity;
  before = now;
  now = next;
  return velocity;
}

double Bridge::step(double force, double drive) noexcept {
  advance(w0_, w1_, force);
  if (drive != 0.0 || d0_ != 0.0 || d1_ != 0.0) {  // a level bridge's w_D stays 0: not stepped
    const double velocity = advance(d0_, d1_, drive);
    supplied_ += drive * k_ * velocity;  // D^n (w_D^{n+1} − w_D^{n−1})/2
  }
  return w1_;
}

double Bridge::partEnergy(double before, double now) const {
  const double velocity = (now - before) / k_;
  return 0.5 * physics_.mass * velocity * velocity + 0.5 * physics_.stiffness * now * before;
}

double Bridge::energy() const { return partEnergy(w0_, w1_) + partEnergy(d0_, d1_); }

double Bridge::forceOnBoard() const {
  const double w = w1_ + d1_, before = w0_ + d0_;
  return physics_.stiffness * w + physics_.resistance * (w - before) * rate_;
}

}  // namespace hamiltone
