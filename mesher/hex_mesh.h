// Plain data for hexahedral meshes, shared by the mesher, the solver and the writers.
#pragma once

#include <array>
#include <vector>

#include "mesher/tri_surface.h"

namespace hexbite {

// A pure hexahedral mesh in millimetres. Each hex lists its 8 vertices in VTK order: bottom face
// 0-1-2-3 counter-clockwise seen from above (from the top face), top face 4-5-6-7 above 0-1-2-3.
// Positively oriented meshes have positive corner Jacobians everywhere.
struct HexMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 8>> hexes;
};

// The mean of hex h's eight vertices.
inline Vec3 hex_centroid(const HexMesh& mesh, int h) {
  Vec3 c{0.0, 0.0, 0.0};
  for (int v : mesh.hexes[h])
    for (int a = 0; a < 3; ++a) c[a] += mesh.vertices[v][a] / 8.0;
  return c;
}

// A quad surface: quads counter-clockwise seen from outside.
struct QuadSurface {
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 4>> quads;
};

}  // namespace hexbite
