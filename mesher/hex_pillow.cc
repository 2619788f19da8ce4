#include "mesher/hex_pillow.h"

#include <vector>

namespace hexbite {

int pillow_quad_boundary(HexMesh& mesh, const QuadSurface& boundary, double inset) {
  const int k = static_cast<int>(boundary.vertices.size());
  std::vector<Vec3> inward(k, Vec3{0, 0, 0});
  std::vector<int> count(k, 0);
  for (std::size_t h = 0; h < mesh.hexes.size(); ++h) {
    const Vec3 c = hex_centroid(mesh, static_cast<int>(h));
    for (int v : mesh.hexes[h])
      if (v < k) {
        for (int a = 0; a < 3; ++a) inward[v][a] += c[a];
        ++count[v];
      }
  }
  const int first = static_cast<int>(mesh.vertices.size());
  for (int v = 0; v < k; ++v) {
    Vec3 p = mesh.vertices[v];
    if (count[v] > 0)
      for (int a = 0; a < 3; ++a) p[a] += inset * (inward[v][a] / count[v] - p[a]);
    mesh.vertices.push_back(p);
  }
  for (auto& hex : mesh.hexes)
    for (int& v : hex)
      if (v < k) v += first;
  for (const auto& q : boundary.quads)
    mesh.hexes.push_back({q[0] + first, q[1] + first, q[2] + first, q[3] + first, q[0], q[1], q[2], q[3]});
  return static_cast<int>(boundary.quads.size());
}

}  // namespace hexbite
