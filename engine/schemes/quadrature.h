// Symmetric quadratures on [0, 1] for Marazzato et al.'s force integral, [M 8]–[M 11].
#pragma once

#include <array>
#include <optional>
#include <string_view>

namespace hamiltone {

enum class QuadratureRule {
  midpoint,
  gaussLegendre2,
  gaussLegendre3,
  gaussLegendre5,
  lobatto3,
  lobatto5
};

// ∫₀¹ f(θ) dθ ≈ Σ weight[i] f(node[i]); symmetric in the sense of [M 11].
struct Quadrature {
  int count = 0;
  std::array<double, 5> node{};
  std::array<double, 5> weight{};
  int exactDegree = 0;  // polynomials up to this degree are integrated exactly ([M Remark 2])
};

Quadrature quadrature(QuadratureRule rule);

// CLI names: midpoint, gl2, gl3, gl5, lobatto3, lobatto5.
std::optional<QuadratureRule> parseQuadratureRule(std::string_view name);
std::string_view name(QuadratureRule rule);

}  // namespace hamiltone
