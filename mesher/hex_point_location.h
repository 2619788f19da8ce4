// Points in the trilinear hexes of a mesh: the map from a hex's unit cube to space, its inverse, and the
// point of a hex nearest to a point outside it.
//
// Why: a probe is evaluated in the hex that holds it, and whether a hex holds a point is a question about
// its trilinear map, not about the triangles its faces are drawn with; a point moved just inside a fan of
// boundary triangles can still lie outside the curved hex behind them (0.02-0.6 mm on warped boundary
// quads), and was then evaluated elsewhere or not at all.
// Input: a HexMesh in VTK order (corner k at unit coordinates (k&1 ^ k>>1&1, k>>1&1, k>>2&1)).
// Cost: a few Newton steps of a 3 x 3 system per hex asked about.
#pragma once

#include <optional>
#include <vector>

#include "mesher/hex_mesh.h"

namespace hexbite {

// x(u) for unit coordinates u in [0, 1]^3 of hex h.
Vec3 trilinear_point(const HexMesh& mesh, int h, const Vec3& unit);

// The unit coordinates u with x(u) = point in hex h, by Newton's method from the centre (also for points a
// little outside the hex, whose u then lie outside [0, 1]^3); nullopt when it does not converge.
std::optional<Vec3> trilinear_unit(const HexMesh& mesh, int h, const Vec3& point);

// Whether hex h holds `point` (its unit coordinates within [-tolerance, 1 + tolerance]^3).
bool hex_holds(const HexMesh& mesh, int h, const Vec3& point, double tolerance = 1e-9);

struct PointInHex {
  int hex = -1;
  Vec3 point{};           // in the hex, strictly inside its unit cube by `inset`
  double distance = 0.0;  // from the point asked about, mm
};

// Among `hexes`, the point nearest to `point` that lies inside one of them: for each hex, `point`'s unit
// coordinates clamped to [inset, 1 - inset]^3 and mapped back (not the exact nearest point of a curved hex,
// but inside it by construction); the nearest of those. hex = -1 when `hexes` is empty or no inverse map
// converges.
PointInHex nearest_point_inside(const HexMesh& mesh, const std::vector<int>& hexes, const Vec3& point,
                                double inset = 1e-3);

}  // namespace hexbite
