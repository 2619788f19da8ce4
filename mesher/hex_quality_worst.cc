#include "mesher/hex_quality_worst.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace hexbite {

std::vector<WorstHex> worst_hexes(const HexMesh& mesh, const HexQualityField& field, std::size_t n) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const std::size_t m = mesh.hexes.size();
  n = std::min(n, m);
  if (n == 0) return {};
  // Sort keys without NaN, so that the order is a strict weak ordering.
  const auto sj = [&](int h) {
    const double v = field.scaled_jacobian[h];
    return std::isnan(v) ? -kInf : v;
  };
  const auto kappa = [&](int h) {
    const double v = field.condition[h];
    return std::isnan(v) ? kInf : v;
  };
  std::vector<int> order(m);
  std::iota(order.begin(), order.end(), 0);
  std::partial_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(n), order.end(),
                    [&](int a, int b) {
                      if (sj(a) != sj(b)) return sj(a) < sj(b);
                      if (kappa(a) != kappa(b)) return kappa(a) > kappa(b);
                      return a < b;
                    });
  std::vector<WorstHex> worst(n);
  for (std::size_t i = 0; i < n; ++i) {
    const int h = order[i];
    worst[i] = {h, field.scaled_jacobian[h], field.condition[h], hex_centroid(mesh, h)};
  }
  return worst;
}

}  // namespace hexbite
