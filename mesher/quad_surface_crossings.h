// Geometric self-intersection of a quad surface: quads that cross each other (a surface folded over itself).
//
// quad check's combinatorial measures cannot see this, and no valid hex mesh has such a boundary (the hexes
// on either side would overlap), so the sheet mesher's embedding leaves hexes inverted there.
// The bilinear quads are compared as triangles by CGAL (Polygon_mesh_processing::self_intersections on a
// Surface_mesh, exact predicates). A twisted quad's two triangles depend on the diagonal chosen, so the test
// runs twice, once with each quad split along its first diagonal (corners 0-2) and once along its second
// (1-3), and a pair of quads counts only when both splits find it: a fold crosses in both, while a pair that
// only one diagonal's triangles make touch is left alone.
// Input: a manifold, consistently oriented quad surface without degenerate quads (quad check tests it for
// closed ones only); for one that CGAL's Surface_mesh cannot hold the result is empty. Cost: CGAL's box
// intersection, O(F log F) typically.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "mesher/hex_mesh.h"

namespace hexbite {

// Pairs of 0-based quad indices {a, b}, a <= b, sorted; a == b is a quad whose two halves cross (a bow tie).
std::vector<std::array<int, 2>> crossing_quads(const QuadSurface& surface);

// Empty when `pairs` (crossing_quads' result) is; else "<subject> crosses itself: quads a and b cross each
// other (centres ...) (N crossing pairs in all); ... no valid hex mesh has this boundary", naming the first
// pair with its place, for the caller to add what to do.
std::string crossing_quads_problem(const QuadSurface& surface, const std::vector<std::array<int, 2>>& pairs,
                                   const std::string& subject = "the surface");

// What to do about a quad surface file that crosses itself (the user's, made outside hexbite).
inline constexpr const char* kUntangleQuadSurface =
    "untangle the surface there (where it was made), or mesh the solid with --method grid";

}  // namespace hexbite
