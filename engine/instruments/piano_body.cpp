// The piano's body: one step of the soundboard and the sympathetic strings together.
#include "instruments/piano_body.h"

#include <stdexcept>
#include <string>

namespace hamiltone {

void PianoBody::prepare(const PianoBodySpec& spec, std::span<const BoardPoint> bridgePoints,
                        std::span<const SympatheticKey> keys) {
  board_.prepare(spec.board, spec.sampleRate, bridgePoints, spec.pickups);
  strings_.prepare(keys, board_, spec.sampleRate, spec.sympatheticMaxHz,
                   spec.sympatheticMaxPartials);
  forces_.setZero(board_.points());
  reset();
}

void PianoBody::reset() noexcept {
  board_.reset();
  strings_.reset();
  supplied_ = switched_ = 0.0;
}

void PianoBody::step(std::span<const double> bridgeForces) noexcept {
  const Eigen::VectorXd& w = board_.displacements();  // w^n; after board_.step(), w^{n+1}
  const int n = board_.points();
  double before = 0.0;  // Σ F_k w_k^{n−1}
  const double* wPrev = board_.previousDisplacements().data();
#pragma omp simd reduction(+ : before)
  for (int k = 0; k < n; ++k) before += bridgeForces[k] * wPrev[k];
  forces_.setZero();
  strings_.step(w, {forces_.data(), static_cast<std::size_t>(n)});  // (Y3), (Y4) with w^n
  board_.addForces({forces_.data(), static_cast<std::size_t>(n)});
  board_.addForces(bridgeForces);
  board_.step();
  double after = 0.0;  // Σ F_k w_k^{n+1}
  const double* wNext = board_.displacements().data();
#pragma omp simd reduction(+ : after)
  for (int k = 0; k < n; ++k) after += bridgeForces[k] * wNext[k];
  supplied_ += 0.5 * (after - before);
}

void PianoBody::setExcluded(int key, bool excluded) noexcept {
  switched_ -=
      strings_.setExcluded(key, excluded, board_.displacements(), board_.previousDisplacements());
}

double PianoBody::energy() const noexcept {
  return board_.energy() + strings_.energy(board_.displacements(), board_.previousDisplacements());
}

}  // namespace hamiltone
