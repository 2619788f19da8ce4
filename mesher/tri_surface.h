// Plain data for triangulated surfaces: the currency between readers, checks, cleanup and meshers.
#pragma once

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

}  // namespace hexbite
