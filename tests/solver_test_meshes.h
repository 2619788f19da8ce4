// Structured hex grids for the solver's verification tests: boxes with named sides, optionally with their
// interior vertices moved at random, and mirror-symmetric variants.
#pragma once

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "mesher/hex_block.h"
#include "mesher/hex_mesh.h"
#include "solver/elasticity.h"

namespace hexbite::test {

// An nx x ny x nz grid of hexes on the box [lower, upper]; vertex (i, j, k) has id vertex(i, j, k).
struct BoxGrid {
  HexMesh mesh;
  int nx = 0, ny = 0, nz = 0;

  int vertex(int i, int j, int k) const { return i + (nx + 1) * (j + (ny + 1) * k); }

  // The boundary quads of one side of the box: 0: x = lower, 1: x = upper, 2: y = lower, 3: y = upper,
  // 4: z = lower, 5: z = upper. `keep(a, b)` selects quads by their cell indices (a, b) in the side's two
  // in-plane directions (y, z for the x sides; x, z for the y sides; x, y for the z sides).
  template <typename Keep>
  std::vector<BoundaryQuad> side(int s, Keep keep) const {
    std::vector<BoundaryQuad> quads;
    const int axis = s / 2;
    const int n[3] = {nx, ny, nz};
    const int u = axis == 0 ? 1 : 0, w = axis == 2 ? 1 : 2;
    for (int a = 0; a < n[u]; ++a)
      for (int b = 0; b < n[w]; ++b) {
        if (!keep(a, b)) continue;
        BoundaryQuad q;
        const int corner[4][2] = {{a, b}, {a + 1, b}, {a + 1, b + 1}, {a, b + 1}};
        for (int c = 0; c < 4; ++c) {
          int ijk[3];
          ijk[axis] = s % 2 == 0 ? 0 : n[axis];
          ijk[u] = corner[c][0];
          ijk[w] = corner[c][1];
          q[c] = vertex(ijk[0], ijk[1], ijk[2]);
        }
        quads.push_back(q);
      }
    return quads;
  }
  std::vector<BoundaryQuad> side(int s) const {
    return side(s, [](int, int) { return true; });
  }
  std::vector<BoundaryQuad> all_sides() const {
    std::vector<BoundaryQuad> quads;
    for (int s = 0; s < 6; ++s) {
      const auto q = side(s);
      quads.insert(quads.end(), q.begin(), q.end());
    }
    return quads;
  }
  bool on_boundary(int i, int j, int k) const {
    return i == 0 || j == 0 || k == 0 || i == nx || j == ny || k == nz;
  }
};

inline BoxGrid box_grid(int nx, int ny, int nz, Vec3 lower, Vec3 upper) {
  BoxGrid g;
  g.nx = nx, g.ny = ny, g.nz = nz;
  g.mesh = make_block_mesh(nx, ny, nz, lower, upper);  // numbers vertices like BoxGrid::vertex()
  return g;
}

// Moves every interior vertex by a random offset of up to `fraction` of the local cell size in each
// direction (fraction <= 0.2 keeps every hex valid). With `mirror_x`, the offsets are mirror-symmetric
// about the box's mid-plane in x (nx must be even); vertices on that plane move only in y and z.
inline void distort_interior(BoxGrid& g, double fraction, unsigned seed, bool mirror_x = false) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> offset(-fraction, fraction);
  const Vec3 lo = g.mesh.vertices[g.vertex(0, 0, 0)], hi = g.mesh.vertices[g.vertex(g.nx, g.ny, g.nz)];
  const double h[3] = {(hi[0] - lo[0]) / g.nx, (hi[1] - lo[1]) / g.ny, (hi[2] - lo[2]) / g.nz};
  for (int k = 0; k <= g.nz; ++k)
    for (int j = 0; j <= g.ny; ++j)
      for (int i = 0; i <= g.nx; ++i) {
        if (g.on_boundary(i, j, k)) continue;
        if (mirror_x && 2 * i > g.nx) continue;  // copied from the mirror image below
        Vec3 d{offset(rng) * h[0], offset(rng) * h[1], offset(rng) * h[2]};
        if (mirror_x && 2 * i == g.nx) d[0] = 0.0;
        Vec3& v = g.mesh.vertices[g.vertex(i, j, k)];
        for (int c = 0; c < 3; ++c) v[c] += d[c];
        if (mirror_x && 2 * i < g.nx) {
          Vec3& m = g.mesh.vertices[g.vertex(g.nx - i, j, k)];
          m = {lo[0] + hi[0] - v[0], v[1], v[2]};
        }
      }
}

inline double norm(const Vec3& v) {
  return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

// The largest vertex displacement difference between two solutions on the same mesh, relative to the
// largest displacement of the first.
inline double relative_difference(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double diff = 0.0, scale = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    diff = std::max(diff, norm({a[i][0] - b[i][0], a[i][1] - b[i][1], a[i][2] - b[i][2]}));
    scale = std::max(scale, norm(a[i]));
  }
  return diff / scale;
}

}  // namespace hexbite::test
