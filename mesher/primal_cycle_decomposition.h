// Decomposition of a quad surface of a ball along a primal cycle, for the sheet mesher
// (mesher/cycle_elimination.h) when no elimination is feasible: the seed paper's improvement of splitting
// the domain and meshing an internal 2-manifold bounded by the cycle (../shared/DESIGN.md section 3).
//
// Input: a QuadSurface that check_quad_surface() finds usable, with n vertices.
// Candidates: the simple cycles of surface edges ("primal cycles") of even length 2m, 4 <= 2m <= max length,
// with at least 2 quads on either side; the most balanced first (largest smaller side), then the shorter,
// then the lexicographically smaller vertex list (started at its smallest vertex and run towards its smaller
// neighbour). On a sphere every simple cycle splits the quads into two disks, the sides. For each cycle the
// internal disks tried, in this order, all with the cycle c_0 .. c_{2m-1} as boundary:
//   - ladder: m - 1 quads (c_i, c_{i+1}, c_{2m-2-i}, c_{2m-1-i}) between two opposite cycle edges, no
//     interior vertex (one quad for 2m = 4, two for 2m = 6), for each of the m pairs of opposite edges;
//   - fan (2m >= 6): one centre vertex p and m quads (c_{2i}, c_{2i+1}, c_{2i+2}, p), both rotations;
//   - ring + ladder, ring + fan: a ring of 2m quads (c_i, c_{i+1}, p_{i+1}, p_i) around an inner cycle of
//     new vertices p_i, which is filled by a ladder (first pair of edges) or a fan (first rotation).
// The disk has V_i + m - 1 quads for V_i interior vertices, so ladders and fans have opposite parities: both
// parts (one side plus the disk) are even exactly when the disk's parity is that of the sides.
// A split is handed to the caller when both parts are usable quad surfaces of balls: even, every chord
// simple, and simple, planar, 3-connected (is_polyhedral_ball(), then check_quad_surface() to be sure).
// Disk vertices get the ids n, n + 1, ... and positions: the centre at the centroid of the cycle's vertices,
// ring vertices halfway between their cycle vertex and that centroid (only a start for the embedding).
// Cost: all cycles up to the length bound are enumerated and their sides found (O(F) each) before the first
// split is tried: a depth-first search from each vertex over larger vertices, pruned by breadth-first
// distance to the start, exponential in the bound (1,288-quad block: 12,930 / 49,258 / 210,622 cycles in
// 0.46 / 1.34 / 4.59 s up to length 8 / 10 / 12); O(C L) memory for C cycles. The test of a split costs
// O(F log F), check_quad_surface() O(V (V + E)).
// Deterministic: fixed orders, no hashing.
#pragma once

#include <array>
#include <functional>
#include <vector>

#include "mesher/hex_mesh.h"

namespace hexbite {

struct DecompositionOptions {
  int max_cycle_length = 12;  // even cycles of length 4 .. this
  int max_splits = 64;        // usable splits handed to the caller at most
  int max_depth = 2;  // nested decompositions of a part (mesh_by_cycle_elimination); 0: never decompose
  // mesh_by_cycle_elimination: a pillow layer under each part of a split (its side's quads and the disk),
  // so that every hex of the parts' complexes lies one layer inside and can move in the embedding.
  bool pillow_parts = true;
};

struct PrimalCycleSplit {
  std::vector<int> cycle;                // surface vertex ids, in order
  int disk_vertices = 0;                 // interior vertices of the disk: ids n .. n + disk_vertices - 1
  std::vector<Vec3> disk_positions;      // their positions
  std::vector<std::array<int, 4>> disk;  // the disk's quads, oriented outward for part 0
  std::array<QuadSurface, 2> parts;      // side s plus the disk, oriented outward, vertices 0 .. k_s - 1
  std::array<std::vector<int>, 2> ids;   // part vertex -> surface id (< n) or disk vertex id (>= n)
  std::array<int, 2> side_quads{0, 0};   // quads of each side
};

struct DecompositionSearch {
  int cycles = 0;  // cycles looked at
  int splits = 0;  // usable splits handed to the caller
  bool accepted = false;
};

// Hands the usable splits to `accept` in the order above until it returns true or max_splits were handed.
DecompositionSearch search_primal_cycle_splits(const QuadSurface& surface,
                                               const DecompositionOptions& options,
                                               const std::function<bool(const PrimalCycleSplit&)>& accept);

}  // namespace hexbite
