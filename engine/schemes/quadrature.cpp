// Nodes and weights of the symmetric quadratures, mapped from [−1, 1] to [0, 1].
#include "schemes/quadrature.h"

#include <cmath>
#include <initializer_list>
#include <utility>

namespace hamiltone {

namespace {

// Maps a rule given on [−1, 1] by its nodes x ≥ 0 and their weights to [0, 1], mirroring it.
Quadrature mirrored(std::initializer_list<std::pair<double, double>> half, int exactDegree) {
  Quadrature q;
  q.exactDegree = exactDegree;
  for (auto [x, w] : half) {
    q.node[q.count] = 0.5 * (1.0 - x);
    q.weight[q.count++] = 0.5 * w;
    if (x != 0.0) {
      q.node[q.count] = 0.5 * (1.0 + x);
      q.weight[q.count++] = 0.5 * w;
    }
  }
  return q;
}

}  // namespace

Quadrature quadrature(QuadratureRule rule) {
  switch (rule) {
    case QuadratureRule::midpoint:
      return mirrored({{0.0, 2.0}}, 1);
    case QuadratureRule::gaussLegendre2:
      return mirrored({{1.0 / std::sqrt(3.0), 1.0}}, 3);
    case QuadratureRule::gaussLegendre3:
      return mirrored({{0.0, 8.0 / 9.0}, {std::sqrt(0.6), 5.0 / 9.0}}, 5);
    case QuadratureRule::gaussLegendre5: {
      const double a = 2.0 * std::sqrt(10.0 / 7.0);
      const double b = 13.0 * std::sqrt(70.0);
      return mirrored({{0.0, 128.0 / 225.0},
                       {std::sqrt(5.0 - a) / 3.0, (322.0 + b) / 900.0},
                       {std::sqrt(5.0 + a) / 3.0, (322.0 - b) / 900.0}},
                      9);
    }
    case QuadratureRule::lobatto3:
      return mirrored({{0.0, 4.0 / 3.0}, {1.0, 1.0 / 3.0}}, 3);
    case QuadratureRule::lobatto5:
      return mirrored({{0.0, 32.0 / 45.0}, {std::sqrt(3.0 / 7.0), 49.0 / 90.0}, {1.0, 0.1}}, 7);
  }
  return {};
}

namespace {
constexpr std::pair<QuadratureRule, std::string_view> kNames[] = {
    {QuadratureRule::midpoint, "midpoint"},  {QuadratureRule::gaussLegendre2, "gl2"},
    {QuadratureRule::gaussLegendre3, "gl3"}, {QuadratureRule::gaussLegendre5, "gl5"},
    {QuadratureRule::lobatto3, "lobatto3"},  {QuadratureRule::lobatto5, "lobatto5"}};
}

std::optional<QuadratureRule> parseQuadratureRule(std::string_view text) {
  for (auto [rule, n] : kNames)
    if (n == text) return rule;
  return std::nullopt;
}

std::string_view name(QuadratureRule rule) {
  for (auto [r, n] : kNames)
    if (r == rule) return n;
  return "?";
}

}  // namespace hamiltone
