// Internal sheets for the sheet mesher (mesher/cycle_elimination.h), inserted while the hex complex is built
// in reverse elimination order (the seed paper's improvement; ../shared/DESIGN.md section 3).
//
// Input: the hex complex built so far, bounded by the surface after an elimination; that elimination's
// (outer quad, inner quad) pairs (its side Q before and after the collapse, corner by corner) and the range
// of vertex ids it created (the interior vertices of the inner quads).
// Output: true, and the complex bounded by the surface before the elimination through an internal sheet:
// the hexes H that hold a created vertex or a face on an inner quad (the hexes below the enclosed quads)
// keep their faces on the side,
// now named by the outer quads' vertices, and one new hex is placed on every face between H and the other
// hexes (the interface I), whose interior vertices are duplicated for H. An external sheet puts one hex on
// every quad of the side, each with a face on the boundary; the internal sheet meets the boundary only in
// the strip quads (its hexes along the rail have one strip quad as their only boundary face), so a chord in a
// flat or smooth region does not leave hexes with two nearly coplanar boundary faces along its rail.
// Conditions, else false and the complex unchanged: H's boundary faces are exactly the inner quads, and I is
// a disk (connected, every edge in one or two of its faces, V - E + F = 1) whose boundary edges are exactly
// the rail (the edges that lie in only one inner quad). Where the side meets the strip at a sharp angle the
// hexes of H there also carry faces of the other side, and the external sheet stays.
// Cost: O(m log m) for m hexes (a sorted face table). Deterministic: no hashing; new vertices are appended
// in ascending order of the vertex they duplicate, at its position.
#pragma once

#include <array>
#include <vector>

#include "mesher/hex_mesh.h"

namespace hexbite {

bool insert_internal_sheet(HexMesh& mesh, const std::vector<std::array<std::array<int, 4>, 2>>& side,
                           int first_created, int created);

}  // namespace hexbite
