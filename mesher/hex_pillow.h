// A pillow layer under a hex mesh's quad boundary: one hex per boundary quad, so that no hex keeps two faces
// on the boundary (a hex wrapped around a rim, or two boundary faces at a flat angle, cannot be made valid
// by moving interior nodes; after pillowing every old hex lies one layer inside and can move).
//
// Input: a conforming hex mesh whose boundary is `boundary` with vertices 0 .. k - 1, k =
// boundary.vertices.size() (the cycle elimination's and the mandible sheet mesher's numbering: the boundary
// vertices first, with the same ids as the quad surface's), and an inset fraction in (0, 1).
// Output: every boundary vertex v gets an inner copy (appended, in the order of v), which takes v's place in
// the old hexes; every boundary quad gets a hex between it and the copies of its corners, oriented like the
// old hexes (the quad as the top face, as build_hex_complex() lays out its sheets). The boundary stays
// exactly `boundary`: the same vertex ids, coordinates and quads. A copy starts `inset` of the way from v to
// the mean centroid of v's old hexes, a start for the embedding only.
// Cost: O(m + k) for m hexes. Deterministic.
#pragma once

#include "mesher/hex_mesh.h"

namespace hexbite {

// Returns the number of hexes added (boundary.quads.size()).
int pillow_quad_boundary(HexMesh& mesh, const QuadSurface& boundary, double inset);

}  // namespace hexbite
