// Quad surfaces for the quad check and cycle elimination suites and the sheet mesher's benchmark: block and
// polycube boundaries, a box chain, a cubed sphere, an O-grid disk, perturbed copies, a torus, a ball with a
// self-intersecting chord and a ball without any elimination scheme.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <vector>

#include "mesher/hex_block.h"
#include "mesher/hex_boundary.h"
#include "mesher/hex_mesh.h"

namespace hexbite::test {

// The boundary of the unit-cube polycube made of the cells (i, j, k) of an nx x ny x nz block for which
// keep(i, j, k) is true.
inline QuadSurface polycube_surface(int nx, int ny, int nz, const std::function<bool(int, int, int)>& keep) {
  const HexMesh block = make_block_mesh(nx, ny, nz);
  HexMesh kept;
  kept.vertices = block.vertices;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        if (keep(i, j, k)) kept.hexes.push_back(block.hexes[i + nx * (j + ny * k)]);
  return extract_boundary(kept).surface;
}

inline QuadSurface block_surface(int nx, int ny, int nz) {
  return polycube_surface(nx, ny, nz, [](int, int, int) { return true; });
}

// A quad ball: the boundary of an n x n x n block centred at the origin, every vertex pushed onto the sphere
// of radius `radius` (6 n^2 quads, 3 n chords of length 4 n).
inline QuadSurface sphere_surface(int n, double radius = 1.0) {
  QuadSurface s = block_surface(n, n, n);
  for (Vec3& p : s.vertices) {
    double norm = 0.0;
    for (double& c : p) {
      c -= 0.5 * n;
      norm += c * c;
    }
    for (double& c : p) c *= radius / std::sqrt(norm);
  }
  return s;
}

// A chain of boxes turning twice: a Z in the xy plane made of four r x r x 2r boxes (cells (0,0), (1,0),
// (1,1), (2,1) of a 3 x 2 layout), every box a block of unit cubes.
inline QuadSurface box_chain_surface(int r) {
  return polycube_surface(3 * r, 2 * r, 2 * r, [r](int i, int j, int) {
    const int bi = i / r, bj = j / r;
    return (bj == 0 && bi <= 1) || (bj == 1 && bi >= 1);
  });
}

// A disk of radius 2 and height 1 with O-grid caps: each cap a 2 x 2 grid of unit quads surrounded by a ring
// of 8 quads out to an 8-gon rim, the side wall one ring of 8 quads (24 quads, 7 chords: the two cap rings,
// the wall ring and 4 chords through both caps). The region between the cap rings (the wall) is bounded by
// the two sharp rims: the annular sheet of a 2-step elimination.
inline QuadSurface o_grid_disk_surface() {
  QuadSurface s;
  const double pi = 3.141592653589793;
  // Per cap (z = 0, 1): the 3 x 3 grid points (id = 9 level + 3 (y + 1) + (x + 1)), then the rims.
  for (int level = 0; level < 2; ++level)
    for (int y = -1; y <= 1; ++y)
      for (int x = -1; x <= 1; ++x) s.vertices.push_back({double(x), double(y), double(level)});
  for (int level = 0; level < 2; ++level)
    for (int i = 0; i < 8; ++i)
      s.vertices.push_back({2.0 * std::cos(i * pi / 4), 2.0 * std::sin(i * pi / 4), double(level)});
  auto grid = [](int level, int x, int y) { return 9 * level + 3 * (y + 1) + (x + 1); };
  auto rim = [](int level, int i) { return 18 + 8 * level + (i % 8); };
  // The grid's boundary loop, counter-clockwise seen from +z, at the rim's angles.
  const int loop[8][2] = {{1, 0}, {1, 1}, {0, 1}, {-1, 1}, {-1, 0}, {-1, -1}, {0, -1}, {1, -1}};
  for (int level = 0; level < 2; ++level) {
    std::vector<std::array<int, 4>> cap;
    for (int y = -1; y < 1; ++y)
      for (int x = -1; x < 1; ++x)
        cap.push_back(
            {grid(level, x, y), grid(level, x + 1, y), grid(level, x + 1, y + 1), grid(level, x, y + 1)});
    for (int i = 0; i < 8; ++i) {
      const int j = (i + 1) % 8;
      cap.push_back({grid(level, loop[i][0], loop[i][1]), rim(level, i), rim(level, j),
                     grid(level, loop[j][0], loop[j][1])});
    }
    // Counter-clockwise seen from outside: from +z on top, from -z on the bottom.
    for (auto q : cap) {
      if (level == 0) std::reverse(q.begin(), q.end());
      s.quads.push_back(q);
    }
  }
  for (int i = 0; i < 8; ++i) s.quads.push_back({rim(0, i), rim(0, i + 1), rim(1, i + 1), rim(1, i)});
  return s;
}

// The 3 x 3 x 3 block with its top centre quad pillowed: the quad replaced by a quad shrunk to half its
// size around its centre, joined to the old corners by a ring of 4 quads (58 quads, 10 chords: the ring
// is a chord of length 4 whose smaller side is the shrunk quad, in the plane of the top face).
inline QuadSurface pillowed_block_surface() {
  QuadSurface s = block_surface(3, 3, 3);
  for (std::size_t q = 0; q < s.quads.size(); ++q) {
    const auto quad = s.quads[q];
    Vec3 centre{0.0, 0.0, 0.0};
    for (int v : quad)
      for (int c = 0; c < 3; ++c) centre[c] += 0.25 * s.vertices[v][c];
    if (centre[0] != 1.5 || centre[1] != 1.5 || centre[2] != 3.0) continue;
    std::array<int, 4> inner{};
    for (int k = 0; k < 4; ++k) {
      inner[k] = static_cast<int>(s.vertices.size());
      Vec3 p = s.vertices[quad[k]];
      for (int c = 0; c < 3; ++c) p[c] = 0.5 * (p[c] + centre[c]);
      s.vertices.push_back(p);
    }
    s.quads[q] = inner;
    for (int k = 0; k < 4; ++k) s.quads.push_back({quad[k], quad[(k + 1) % 4], inner[(k + 1) % 4], inner[k]});
    break;
  }
  return s;
}

// Moves every vertex by a deterministic pseudo-random offset of at most `amplitude` per coordinate.
inline QuadSurface perturbed(QuadSurface s, double amplitude) {
  unsigned state = 12345u;
  auto next = [&] {
    state = state * 1664525u + 1013904223u;
    return (state >> 8) / double(1u << 24) * 2.0 - 1.0;
  };
  for (Vec3& p : s.vertices)
    for (double& c : p) c += amplitude * next();
  return s;
}

// An n x m quad grid wrapped into a torus (genus 1).
inline QuadSurface torus_surface(int n, int m) {
  QuadSurface s;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) {
      const double u = 6.283185307179586 * i / n, v = 6.283185307179586 * j / m;
      s.vertices.push_back({(3 + std::cos(v)) * std::cos(u), (3 + std::cos(v)) * std::sin(u), std::sin(v)});
    }
  auto id = [&](int i, int j) { return (i % n) * m + (j % m); };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) s.quads.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
  return s;
}

inline int vertex_at(const QuadSurface& s, const Vec3& p) {
  for (int v = 0; v < static_cast<int>(s.vertices.size()); ++v)
    if (s.vertices[v] == p) return v;
  return -1;
}

// Collapses the quad holding the opposite corners `keep` and `drop` along that diagonal (drop merges into
// keep), then drops the unused vertex.
inline void collapse_diagonal(QuadSurface& s, const Vec3& keep, const Vec3& drop) {
  const int a = vertex_at(s, keep), c = vertex_at(s, drop);
  std::vector<std::array<int, 4>> quads;
  for (auto q : s.quads) {
    if (std::count(q.begin(), q.end(), a) && std::count(q.begin(), q.end(), c)) continue;
    for (int& v : q) {
      if (v == c) v = a;
      if (v > c) --v;  // ids above the dropped vertex move down by one
    }
    quads.push_back(q);
  }
  s.quads = quads;
  s.vertices.erase(s.vertices.begin() + c);
}

// A ball (22 quads, every vertex of degree >= 3) with one self-intersecting chord of length 20: two
// diagonal collapses on the 2 x 2 x 2 block, one on the top face and one on the bottom face, join four
// straight chords into one that crosses itself.
inline QuadSurface self_intersecting_surface() {
  QuadSurface s = block_surface(2, 2, 2);
  collapse_diagonal(s, {1, 1, 2}, {2, 2, 2});
  collapse_diagonal(s, {1, 1, 0}, {2, 0, 0});
  return s;
}

// A ball (30 quads, 6 simple chords, 3-connected) without any elimination scheme: the 3 x 2 x 2 block with
// the top and the bottom quad over the cell [1, 2] x [1, 2] collapsed along crossing diagonals. Every
// feasible first elimination leaves a surface with no feasible one (found by a search over diagonal
// collapses of small blocks).
inline QuadSurface no_scheme_surface() {
  QuadSurface s = block_surface(3, 2, 2);
  collapse_diagonal(s, {1, 2, 2}, {2, 1, 2});
  collapse_diagonal(s, {2, 2, 0}, {1, 1, 0});
  return s;
}

// The same ball with the two merged vertices moved to the middle of their collapsed diagonals, so that every
// quad is convex (no_scheme_surface() has quads with three collinear corners: a hex on one of them has a
// corner Jacobian of 0, inverted whatever the interior).
inline QuadSurface no_scheme_convex_surface() {
  QuadSurface s = no_scheme_surface();
  s.vertices[vertex_at(s, {1, 2, 2})] = {1.5, 1.5, 2};
  s.vertices[vertex_at(s, {2, 2, 0})] = {1.5, 1.5, 0};
  return s;
}

// Quads as vertex-id cycles rotated to start at their smallest id, sorted: equal for equal quad sets with
// the same orientation.
inline std::vector<std::array<int, 4>> canonical_quads(const std::vector<std::array<int, 4>>& quads) {
  std::vector<std::array<int, 4>> out;
  for (const auto& q : quads) {
    const int s = static_cast<int>(std::min_element(q.begin(), q.end()) - q.begin());
    out.push_back({q[s], q[(s + 1) % 4], q[(s + 2) % 4], q[(s + 3) % 4]});
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace hexbite::test
