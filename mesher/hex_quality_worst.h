// The worst hexes of a mesh: the ones `hexbite quality --worst N` lists, for finding where a mesh is bad.
//
// Input: a mesh and its per-element measures (compute_hex_quality). Output: up to n hexes, worst first.
// Cost: O(m + n log m) for m hexes (a partial sort of the indices).
#pragma once

#include <cstddef>
#include <vector>

#include "mesher/hex_mesh.h"
#include "mesher/hex_quality.h"

namespace hexbite {

struct WorstHex {
  int hex = -1;                  // 0-based index in the mesh
  double scaled_jacobian = 0;    // element value (minimum over the corners)
  double condition = 0;          // element value (maximum over the corners, cube = 3); +inf when inverted
  Vec3 centroid{0.0, 0.0, 0.0};  // mean of the 8 vertices, mm
};

// The min(n, hexes) hexes with the lowest element scaled Jacobian, in ascending order of it; ties go to the
// larger condition number first, then to the lower index. A NaN scaled Jacobian (a NaN coordinate) ranks
// below every number and a NaN condition number above every number, so broken hexes come first.
std::vector<WorstHex> worst_hexes(const HexMesh& mesh, const HexQualityField& field, std::size_t n);

}  // namespace hexbite
