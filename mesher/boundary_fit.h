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

// Reaching the surface's tips: moves boundary nodes onto the surface points farthest from the boundary.
//
// Why: a coarse mesh's boundary nodes sample the surface only at its nodes; a knob narrower than a few edges
// (the condyle's lateral pole, the coronoid's tip) lies between them and the quads cut under it, and the
// optimizer's quality stages slide the nodes farther off (the swept core at 2,500 hexes: the built-in
// mandible's condyle poles 2.0 mm from the mesh after the pillow layer, 4-5 mm after the optimizer).
// Input: a hex mesh, the surface it fills, options.
// Output: moved nodes. Each round measures the distance of every surface vertex to the boundary (fan
// triangles of the quads); from the farthest down, each vertex farther than options.limit mean boundary
// edges moves its nearest boundary node (each node once a round) onto it; a move is halved up to four times
// until the hexes around the node pass the rule, else dropped. With keep_worst the rule is the volume fit's:
// every hex keeps its scaled Jacobian at least the smaller of its own and the mesh's minimum and its
// condition number at most the larger of its own and the mesh's maximum (a mesh with an inverted hex is left
// unchanged), or, with floor_scaled_jacobian / max_condition, at least the smaller of its own and
// min(mesh's minimum, floor) and at most the larger of its own and max(mesh's maximum, cap); without it
// (before the optimizer, which untangles and improves what the moves spoil) no hex falls below the smaller
// of its own scaled Jacobian and min_scaled_jacobian.
// Cost: in the first round one closest-point query per surface vertex against the boundary, in later rounds
// only for the far vertices and those whose closest quad has a moved node; and a scan of the boundary nodes
// per far vertex: O(V log Q + F B) for V surface vertices, Q quads, F far vertices, B boundary nodes.
struct FarSurfaceOptions {
  double limit = 0.5;  // surface vertices farther than this many mean boundary edges from the boundary pull
  int rounds = 5;      // rounds (stops early when no node moves)
  bool keep_worst = true;
  double min_scaled_jacobian = 0.05;  // without keep_worst
  // With keep_worst: hexes may fall to min(mesh's minimum, this) and rise to max(mesh's maximum,
  // max_condition), or stay where they are if already beyond (0: the mesh's worst, never worse).
  double floor_scaled_jacobian = 0.0;
  double max_condition = 0.0;
};

struct FarSurfaceReport {
  int far_vertices = 0;    // surface vertices farther than the limit in the first round
  int moved_nodes = 0;     // moves over all rounds
  std::vector<int> moved;  // the nodes that moved, each once
  double seconds = 0;
};

FarSurfaceReport reach_far_surface(HexMesh& mesh, const SurfaceProjector& surface,
                                   const FarSurfaceOptions& options = {});

// One line for the text reports: "2016 of 2144 boundary nodes moved along their normals (...)".
std::string describe(const BoundaryFitReport& fit);

}  // namespace hexbite
