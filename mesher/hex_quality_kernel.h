// Inline per-corner and per-hex quality kernels, kept header-only so that the optimizer can call them
// millions of times without a function call or an allocation per hex.
//
// Input: the 8 corner positions of a hexahedron in VTK node order (or one corner and its three neighbours).
// Output: Jacobian, scaled Jacobian, condition number and Oddy value per corner, and their element values.
// Cost: a few dozen floating-point operations per corner, one sqrt and one cbrt; no allocation.
//
// Definitions (DESIGN.md section 3): for corner x with neighbours x1, x2, x3 in the fixed VTK/Verdict order,
// A = [x1 - x, x2 - x, x3 - x].
//   Jacobian          det(A)
//   scaled Jacobian   det(A) / (|a1| |a2| |a3|), in [-1, 1]
//   condition number  kappa(A) = |A|_F |A^-1|_F, 3 for a cube corner (Verdict prints kappa / 3)
//   Oddy              det(A)^(-4/3) (|A^T A|_F^2 - |A|_F^4 / 3), 0 for a cube corner
// Degenerate corners: where det(A) <= 0 the condition number and the Oddy value are +infinity (both are
// undefined there and grow without bound as det(A) -> 0+); where a column has zero length the scaled Jacobian
// is 0. Such a corner always makes its element inverted, because its Jacobian is <= 0.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "mesher/tri_surface.h"
#include "mesher/vec3.h"

namespace hexbite {

// Neighbours x1, x2, x3 of each corner of a VTK hexahedron, in the order that makes A positively oriented
// for a right-handed hex (the order Verdict uses).
inline constexpr int kHexCornerNeighbours[8][3] = {{1, 3, 4}, {2, 0, 5}, {3, 1, 6}, {0, 2, 7},
                                                   {7, 5, 0}, {4, 6, 1}, {5, 7, 2}, {6, 4, 3}};

// The quality of one corner (or, in HexQuality, of one element).
struct CornerQuality {
  double jacobian = 0.0;         // det(A)
  double scaled_jacobian = 0.0;  // det(A) with unit columns
  double condition = 0.0;        // kappa(A), cube = 3; +inf where det(A) <= 0
  double oddy = 0.0;             // cube = 0; +inf where det(A) <= 0
};

// Element values: minimum Jacobian and scaled Jacobian over the corners, maximum condition number and Oddy
// value over the corners; inverted when any corner Jacobian is <= 0.
struct HexQuality {
  double jacobian = 0.0;
  double scaled_jacobian = 0.0;
  double condition = 0.0;  // cube = 3; Verdict's scale is condition / 3
  double oddy = 0.0;
  bool inverted = false;
};

namespace detail {

using vec3::cross;
using vec3::dot;
using vec3::sub;

}  // namespace detail

// det(A) for A = [a, b, c]: the corner Jacobian alone, for validity checks.
inline double corner_jacobian(const Vec3& a, const Vec3& b, const Vec3& c) {
  return detail::dot(a, detail::cross(b, c));
}

// kappa(A)^2 = |A|_F^2 |adj(A)|_F^2 / det(A)^2 without a square root: the optimizer's objective term.
// The rows of adj(A) are b x c, c x a and a x b. Returns +inf where det(A) <= 0.
inline double corner_condition_squared(const Vec3& a, const Vec3& b, const Vec3& c) {
  using detail::cross;
  using detail::dot;
  const Vec3 bc = cross(b, c);
  const double det = dot(a, bc);
  if (!(det > 0.0)) return std::numeric_limits<double>::infinity();
  const Vec3 ca = cross(c, a);
  const Vec3 ab = cross(a, b);
  const double norm_a2 = dot(a, a) + dot(b, b) + dot(c, c);
  const double norm_adj2 = dot(bc, bc) + dot(ca, ca) + dot(ab, ab);
  return norm_a2 * norm_adj2 / (det * det);
}

// All four measures of the corner with edge vectors a = x1 - x, b = x2 - x, c = x3 - x.
inline CornerQuality corner_quality(const Vec3& a, const Vec3& b, const Vec3& c) {
  using detail::cross;
  using detail::dot;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const Vec3 bc = cross(b, c);
  const Vec3 ca = cross(c, a);
  const Vec3 ab = cross(a, b);
  const double det = dot(a, bc);
  // Entries of the metric tensor G = A^T A.
  const double g11 = dot(a, a), g22 = dot(b, b), g33 = dot(c, c);
  const double g12 = dot(a, b), g13 = dot(a, c), g23 = dot(b, c);

  CornerQuality q;
  q.jacobian = det;
  const double lengths2 = g11 * g22 * g33;
  q.scaled_jacobian = lengths2 > 0.0 ? det / std::sqrt(lengths2) : 0.0;
  if (det > 0.0) {
    const double norm_a2 = g11 + g22 + g33;
    const double norm_adj2 = dot(bc, bc) + dot(ca, ca) + dot(ab, ab);
    q.condition = std::sqrt(norm_a2 * norm_adj2) / det;
    const double norm_g2 = g11 * g11 + g22 * g22 + g33 * g33 + 2.0 * (g12 * g12 + g13 * g13 + g23 * g23);
    // det^(-4/3) as 1 / (det * cbrt(det)): one cbrt instead of a general pow.
    q.oddy = (norm_g2 - norm_a2 * norm_a2 / 3.0) / (det * std::cbrt(det));
  } else {
    q.condition = kInf;
    q.oddy = kInf;
  }
  return q;
}

// The Jacobian matrix columns of corner `corner` of a hex given by its 8 positions.
inline void hex_corner_columns(const Vec3* x, int corner, Vec3& a, Vec3& b, Vec3& c) {
  const int* n = kHexCornerNeighbours[corner];
  a = detail::sub(x[n[0]], x[corner]);
  b = detail::sub(x[n[1]], x[corner]);
  c = detail::sub(x[n[2]], x[corner]);
}

// Quality of corner `corner` (0..7) of the hex with positions x[0..7].
inline CornerQuality hex_corner_quality(const Vec3* x, int corner) {
  Vec3 a, b, c;
  hex_corner_columns(x, corner, a, b, c);
  return corner_quality(a, b, c);
}

// Element quality of the hex with positions x[0..7] (VTK order).
inline HexQuality hex_quality(const Vec3* x) {
  HexQuality h;
  h.jacobian = std::numeric_limits<double>::infinity();
  h.scaled_jacobian = std::numeric_limits<double>::infinity();
  for (int corner = 0; corner < 8; ++corner) {
    const CornerQuality q = hex_corner_quality(x, corner);
    // Written as a negated comparison so that a NaN coordinate counts as inverted, never as valid.
    if (!(q.jacobian > 0.0)) h.inverted = true;
    h.jacobian = std::min(h.jacobian, q.jacobian);
    h.scaled_jacobian = std::min(h.scaled_jacobian, q.scaled_jacobian);
    h.condition = std::max(h.condition, q.condition);
    h.oddy = std::max(h.oddy, q.oddy);
  }
  return h;
}

// Convenience overload for a hex stored as an array of 8 positions.
inline HexQuality hex_quality(const std::array<Vec3, 8>& x) {
  return hex_quality(x.data());
}

}  // namespace hexbite
