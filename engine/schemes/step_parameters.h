// The numbers every time-stepping scheme takes, and their validation.
#pragma once

#include <cmath>
#include <stdexcept>
#include <string>

#include "schemes/hamiltonian.h"
#include "util/format_number.h"

namespace hamiltone {

struct StepParameters {
  double k = 0.0;       // time step, s
  double sigma0 = 0.0;  // mass-proportional loss: force −2σ0 M q', 1/s   (6), (49)
  double sigma1 = 0.0;  // frequency-dependent loss: force −2σ1 C q', m²/s (linear_loss.h)
  double epsilon = 0.0;  // gauge shift of the quadratised potential, §2.5 (SAV schemes only)
  // Accumulate the energy the loss takes (dissipated(), the balance (50)) — one more pass over
  // the grid per lossy step, which a voice that only needs the sound leaves out.
  bool trackDissipation = true;
};

// Throws std::invalid_argument naming the parameter, its value and what is valid.
inline void checkStepParameters(const StepParameters& p, bool hasEpsilon) {
  if (!std::isfinite(p.k) || p.k <= 0.0)
    throw std::invalid_argument("time step k = " + formatNumber(p.k) +
                                ": must be a finite number > 0 (seconds)");
  if (!std::isfinite(p.sigma0) || p.sigma0 < 0.0)
    throw std::invalid_argument("loss sigma0 = " + formatNumber(p.sigma0) +
                                ": must be a finite number >= 0 (1/s)");
  if (p.sigma0 * p.k >= 1.0)
    throw std::invalid_argument("loss sigma0 = " + formatNumber(p.sigma0) +
                                " with k = " + formatNumber(p.k) +
                                ": sigma0*k must be < 1, i.e. sigma0 < " + formatApprox(1.0 / p.k));
  if (!std::isfinite(p.sigma1) || p.sigma1 < 0.0)
    throw std::invalid_argument("loss sigma1 = " + formatNumber(p.sigma1) +
                                ": must be a finite number >= 0 (m^2/s)");
  if (!hasEpsilon && p.epsilon != 0.0)
    throw std::invalid_argument("gauge shift epsilon = " + formatNumber(p.epsilon) +
                                ": only the SAV schemes (27), (38) take a gauge shift");
  if (!std::isfinite(p.epsilon) || p.epsilon < 0.0)
    throw std::invalid_argument("gauge shift epsilon = " + formatNumber(p.epsilon) +
                                ": must be a finite number >= 0 (J)");
}

inline void checkInitialState(const InitialState& s, Eigen::Index n) {
  if (s.q.size() != n || s.p.size() != n)
    throw std::invalid_argument("initial state has " + std::to_string(s.q.size()) +
                                " positions and " + std::to_string(s.p.size()) +
                                " momenta; the system has " + std::to_string(n) + " coordinates");
  if (!s.q.allFinite() || !s.p.allFinite())
    throw std::invalid_argument("initial state is not finite");
}

}  // namespace hamiltone
