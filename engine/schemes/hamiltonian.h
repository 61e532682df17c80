// What a scheme needs to know of a model: the Hamiltonian system of BDZ §2, in split form (16).
#pragma once

#include <Eigen/Core>
#include <concepts>

namespace hamiltone {

using Vector = Eigen::VectorXd;

// H = ½ pᵀM⁻¹p + ½ qᵀKq + V'(q),  M diagonal SPD, K symmetric PSD, V' >= 0   (1), (16).
// A model with no natural split says `hasStiffness = false`: K = 0 and V' is the whole V.
// Outputs are written into caller-owned vectors of size(): nothing here may allocate.
template <class S>
concept HamiltonianSystem = requires(const S& s, const Vector& q, Vector& out) {
  { S::hasStiffness } -> std::convertible_to<bool>;
  { s.size() } -> std::convertible_to<Eigen::Index>;
  { s.inverseMass() } -> std::convertible_to<const Vector&>;      // diagonal of M⁻¹
  s.applyStiffness(q, out);                                       // out = K q
  { s.stiffnessEigenvalueMax() } -> std::convertible_to<double>;  // λmax(M^-½ K M^-½), for (44)
  { s.splitPotential(q) } -> std::convertible_to<double>;         // V'(q)
  { s.splitGradient(q, out) } -> std::convertible_to<double>;     // out = ∇V'(q); returns V'(q)
};

// A model whose V' is a sum V' = Σ_j V'_j of parts quadratised separately, each with its own
// auxiliary variable ψ_j (SCHEMES §3: one SAV per nonlinearity, rank-P Woodbury update), so that
// the error of one part's ψ does not leak into the others' forces. splitPotential and
// splitGradient still give the sum. partGradient is handed the vector it filled for the same
// part the time before (zeros at first), so a sparse part may rewrite only its own entries;
// V'_j = 0 must mean ∇V'_j = 0 (true of any differentiable V'_j >= 0).
template <class S>
concept PartitionedPotential = requires(const S& s, const Vector& q, Vector& out, int j) {
  { S::potentialParts } -> std::convertible_to<int>;
  { s.partPotential(j, q) } -> std::convertible_to<double>;
  { s.partGradient(j, q, out) } -> std::convertible_to<double>;  // out = ∇V'_j; returns V'_j
};

// The full potential V = ½ qᵀKq + V' of (16), for the schemes that do not split it.
// `scratch` receives K q.
template <HamiltonianSystem S>
double fullPotential(const S& s, const Vector& q, Vector& scratch) {
  double v = s.splitPotential(q);
  if constexpr (S::hasStiffness) {
    s.applyStiffness(q, scratch);
    v += 0.5 * q.dot(scratch);
  }
  return v;
}

// ∇V = K q + ∇V' into `grad`; returns V(q). `scratch` receives K q.
template <HamiltonianSystem S>
double fullGradient(const S& s, const Vector& q, Vector& grad, Vector& scratch) {
  double v = s.splitGradient(q, grad);
  if constexpr (S::hasStiffness) {
    s.applyStiffness(q, scratch);
    grad += scratch;
    v += 0.5 * q.dot(scratch);
  }
  return v;
}

// The discrete energy a scheme reports after every step, and its two parts.
struct Energy {
  double kinetic = 0.0;
  double potential = 0.0;
  double total() const { return kinetic + potential; }
};

// Initial state of a run: q(0), p(0).
struct InitialState {
  Vector q;
  Vector p;
};

}  // namespace hamiltone

namespace hamiltone {

// Kinetic energy ½ (δq)ᵀM(δq)/k² of the interval between q0 and q1 — the first term of (36), (41).
inline double intervalKineticEnergy(const Vector& inverseMass, const Vector& q0, const Vector& q1,
                                    double k) {
  return 0.5 * ((q1 - q0).array().square() / inverseMass.array()).sum() / (k * k);
}

}  // namespace hamiltone
