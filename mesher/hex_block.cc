#include "mesher/hex_block.h"

namespace hexbite {

HexMesh make_block_mesh(int nx, int ny, int nz, const Vec3& lower, const Vec3& upper) {
  HexMesh mesh;
  mesh.vertices.reserve(static_cast<std::size_t>(nx + 1) * (ny + 1) * (nz + 1));
  mesh.hexes.reserve(static_cast<std::size_t>(nx) * ny * nz);
  const auto at = [](double lo, double hi, int i, int n) { return lo + (hi - lo) * i / n; };
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i)
        mesh.vertices.push_back(
            {at(lower[0], upper[0], i, nx), at(lower[1], upper[1], j, ny), at(lower[2], upper[2], k, nz)});
  const auto id = [&](int i, int j, int k) { return i + (nx + 1) * (j + (ny + 1) * k); };
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        mesh.hexes.push_back({id(i, j, k), id(i + 1, j, k), id(i + 1, j + 1, k), id(i, j + 1, k),
                              id(i, j, k + 1), id(i + 1, j, k + 1), id(i + 1, j + 1, k + 1),
                              id(i, j + 1, k + 1)});
  return mesh;
}

HexMesh make_block_mesh(int nx, int ny, int nz) {
  return make_block_mesh(nx, ny, nz, {0.0, 0.0, 0.0}, {double(nx), double(ny), double(nz)});
}

}  // namespace hexbite
