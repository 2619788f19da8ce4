// Quad surfaces for the quad check and cycle elimination suites: block and polycube boundaries, perturbed
// copies, a torus, and a ball with a self-intersecting chord.
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
