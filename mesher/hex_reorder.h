// Reordering of the hexes and nodes of a mesh, to shrink the bandwidth and profile of the stiffness matrix.
//
// Input: a HexMesh; for breadth-first order a start point (the seed paper starts at a boundary hex at the
// left condyle).
// Output: the reordered mesh (same hexes with the same corner order, same node positions, new numbers), the
// permutations, and the bandwidth and profile of the nodal adjacency (two nodes are adjacent when they share
// a hex: the sparsity pattern of a Q1 stiffness matrix, one block per node) before and after. Methods:
//   breadth-first: hexes in breadth-first order over shared faces from the boundary hex whose centroid is
//     nearest the start point (face neighbours in local face order; further components from their lowest
//     hex); nodes numbered in order of first appearance in the new hex order;
//   reverse Cuthill-McKee: Boost.Graph's cuthill_mckee_ordering (pseudo-peripheral start per component) on
//     the nodal adjacency graph, reversed; hexes then sorted by their smallest new node number.
// Nodes that no hex uses keep their relative order and go after all the others, in both methods.
// Cost: breadth-first O(m log m) for m hexes (face matching by sorting); RCM O(E log d) for the E = O(m)
// adjacency edges and maximal degree d. Deterministic: no hashing, ties broken by the old numbers.
#pragma once

#include <vector>

#include "mesher/hex_mesh.h"

namespace hexbite {

// Of the symmetric node adjacency (the diagonal included):
//   bandwidth = max |i - j| over adjacent nodes i, j;
//   profile   = sum over nodes i of (i - smallest node adjacent to i or i itself), the envelope below the
//               diagonal, which is what a skyline (profile) solver stores besides the diagonal.
// Both count nodes; with 3 displacement components per node interleaved, the matrix bandwidth is
// 3 * bandwidth + 2.
struct AdjacencyProfile {
  long long bandwidth = 0;
  long long profile = 0;
};

AdjacencyProfile nodal_adjacency_profile(const HexMesh& mesh);

struct ReorderResult {
  HexMesh mesh;
  std::vector<int> hex_order;   // new hex i is old hex hex_order[i]
  std::vector<int> node_order;  // new node i is old node node_order[i]
  int start_hex = -1;           // breadth-first: old index of the start hex; -1 for RCM
  AdjacencyProfile before, after;
};

// Boundary hex (a hex with a face used by no other hex) whose centroid is nearest `point`; the lowest index
// wins ties. Returns -1 for a mesh without hexes.
int nearest_boundary_hex(const HexMesh& mesh, const Vec3& point);

// Boundary hex with the smallest centroid x (the lowest index wins ties): the default start without a point.
int smallest_x_boundary_hex(const HexMesh& mesh);

// Breadth-first order from `start_hex` (an old hex index; must be valid for a non-empty mesh).
ReorderResult reorder_breadth_first(const HexMesh& mesh, int start_hex);

ReorderResult reorder_reverse_cuthill_mckee(const HexMesh& mesh);

}  // namespace hexbite
