// Volume-fitting of a hex mesh's boundary: moves the boundary nodes along their normals so that the
// bilinear boundary quads straddle the input surface instead of lying inside it.
//
// Why: boundary nodes placed on a curved surface make every boundary quad a chord of it; on a convex part the
// quad lies inside by about e^2 / (8 R) at its centre (edge e, radius of curvature R), so a coarse mesh of a
// thin bone is systematically thinner than the bone (the built-in mandible at 2,500 hexes, 3.15 mm edges:
// -3.4 % volume, -0.9 % after one uniform refinement, the e^2 rate). Moving each node out by the mean gap
// of its quads makes the mean signed distance of the boundary to the surface about zero: the volume then
// matches, and the largest distance falls because the quads' centres come closer while their corners leave
// the surface by about half as much.
//
// Input: a valid HexMesh, the surface it fills (SurfaceProjector), a per-vertex `fixed` mask (may be empty).
// Output: moved boundary nodes. A move is shortened (halved up to three times, else dropped) until every hex
// around the node keeps its scaled Jacobian above the smaller of its value and the mesh's minimum, loses at
// most max_scaled_jacobian_drop of it per move, and keeps its condition number below the larger of its value
// and the mesh's maximum: validity and the worst element never get worse. Fixed nodes do not move; a mesh
// with an inverted hex is returned unchanged.
//
// Cost: per round, 9 closest-point and inside queries per boundary quad (AABB tree) and a quality check of
// the hexes around each moved node.
//
// Written by hand: CGAL's mesh processing smooths and fairs surfaces; it does not fit a hex mesh's boundary
// to the volume of another surface.
#pragma once

#include <string>
#include <vector>

#include "mesher/hex_mesh.h"
#include "mesher/surface_projector.h"

namespace hexbite {

struct BoundaryFitOptions {
  int rounds = 4;            // Jacobi rounds (each re-measures the gaps)
  double max_offset = 0.25;  // largest distance of a node from the surface, in its mean boundary edge lengths
  double max_scaled_jacobian_drop = 0.05;  // per hex and move
};

struct BoundaryFitReport {
  int boundary_nodes = 0;
  int moved_nodes = 0;         // nodes that moved in the last round
  int limited_moves = 0;       // moves shortened by the quality rule, over all rounds
  double mean_gap_before = 0;  // area-weighted mean signed distance of the boundary (outside positive), mm
  double mean_gap_after = 0;
  double max_node_offset = 0;  // largest distance of a boundary node from the surface afterwards, mm
  double seconds = 0;
};

BoundaryFitReport fit_boundary_to_volume(HexMesh& mesh, const SurfaceProjector& surface,
                                         const std::vector<char>& fixed,
                                         const BoundaryFitOptions& options = {});

// One line for the text reports: "2016 of 2144 boundary nodes moved along their normals (...)".
std::string describe(const BoundaryFitReport& fit);

}  // namespace hexbite
