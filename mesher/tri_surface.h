// Plain data for triangulated surfaces: the currency between readers, checks, cleanup and meshers.
#pragma once

#include <algorithm>
#include <array>
#include <vector>

namespace hexbite {

using Vec3 = std::array<double, 3>;

// A triangle surface in millimetres. Triangles index into vertices, counter-clockwise seen from
// outside once the surface has passed check_surface().
struct TriSurface {
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;
};

// The largest side of the bounding box of the points (0 without points).
inline double largest_extent(const std::vector<Vec3>& points) {
  if (points.empty()) return 0.0;
  Vec3 lo = points.front(), hi = lo;
  for (const Vec3& p : points)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
  return std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
}

// The largest side of the bounding box of the surface's vertices (0 without vertices).
inline double largest_extent(const TriSurface& surface) {
  return largest_extent(surface.vertices);
}

}  // namespace hexbite
