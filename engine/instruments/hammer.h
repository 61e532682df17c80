// A felt piano hammer and the string it strikes: one Hamiltonian system whose potential
// V' = (string's (65)) + Φ(η) holds the collision, so the strike conserves energy exactly.
// The two are quadratised apart (two SAVs): measured at 48 kHz on the transverse grid, one ψ
// for both lets the under-resolved longitudinal part's error into the felt force, and a
// mezzo-forte hammer sinks 6 mm into the felt and stays there; with two it rebounds as it should.
#pragma once

#include <span>
#include <vector>

#include "instruments/string.h"
#include "schemes/hamiltonian.h"

namespace hamiltone {

struct HammerFelt {
  double mass = 9.45e-3;       // M_H, kg (RT-425 law at C3, docs/instrument-data.md §2.1)
  double stiffness = 1.347e9;  // K_H, N/m^p
  double exponent = 2.312;     // p
  double position = 0.12;      // strike point x0 / L
  double width = 0.01;         // contact width on the string, m
};

// Φ(η) = K_H/(p+1) [η]₊^{p+1} of the felt compression η = w − Jᵀu, and its force Φ'(η).
class Hammer {
 public:
  // Throws std::invalid_argument naming the field for a non-physical felt.
  explicit Hammer(const HammerFelt& felt);

  const HammerFelt& felt() const { return felt_; }
  double potential(double compression) const;
  double force(double compression) const;  // Φ'(η) = K_H [η]₊^p

 private:
  HammerFelt felt_;
};

// q = [u; v; w]: the string's coordinates and the hammer's height w (positive towards the string).
// J spreads the contact as the felt presses on the string: J_j = ∫ φ_j g dx, g the felt's raised
// cosine (unit area, its width, centred on the strike point) and φ_j grid point j's hat, so that
// Jᵀ1 = 1 (less the share of a fixed end the felt reaches within a segment of). Jᵀ of a mode shape
// is then the felt's own excitation of the mode, to within the linear interpolation of the mode
// between grid points, on any grid: a grid coarser than the felt does not move the strike to its
// nearest point.
class HammeredString {
 public:
  static constexpr bool hasStiffness = true;
  static constexpr int potentialParts = 2;  // 0: the string's V' (65), 1: the felt Φ

  HammeredString(NonlinearString string, const HammerFelt& felt);

  Eigen::Index size() const { return inverseMass_.size(); }
  Eigen::Index hammerIndex() const { return size() - 1; }
  const NonlinearString& string() const { return string_; }
  NonlinearString& string() { return string_; }  // for the bend (setTensionScale)
  const Hammer& hammer() const { return hammer_; }

  const Vector& inverseMass() const { return inverseMass_; }
  void applyStiffness(const Vector& q, Vector& out) const;
  double stiffnessEigenvalueMax() const { return string_.stiffnessEigenvalueMax(); }
  double splitPotential(const Vector& q) const;
  double splitGradient(const Vector& q, Vector& grad) const;
  double partPotential(int part, const Vector& q) const;
  double partGradient(int part, const Vector& q, Vector& grad) const;
  // Where ∇V'_j may be nonzero: the string's part everywhere (empty), the felt's at the hammer
  // and the nodes under it (SavScheme sums and corrects it there alone).
  std::span<const Eigen::Index> partSupport(int part) const {
    return part == 0 ? std::span<const Eigen::Index>() : std::span<const Eigen::Index>(support_);
  }
  void applyLossOperator(const Vector& a, const Vector& b, Vector& out) const;
  void applyStiffnessAndLoss(const Vector& q, const Vector& qPrev, bool prevKept, Vector& kq,
                             Vector& cq) const;  // NonlinearString's; the hammer has neither
  double lossOperatorEigenvalueMax() const { return string_.lossOperatorEigenvalueMax(); }
  double maxStableStep(double sigma1) const { return string_.maxStableStep(sigma1); }

  double compression(const Vector& q) const;          // η = w − Jᵀu
  double contactDisplacement(const Vector& q) const;  // Jᵀu

 private:
  NonlinearString string_;
  Hammer hammer_;
  Vector inverseMass_;
  std::vector<Eigen::Index> contactIndex_;  // grid indices of u under the felt
  std::vector<double> contactWeight_;       // J there
  std::vector<Eigen::Index> support_;       // the contact indices and the hammer's
};

}  // namespace hamiltone
