// Uniform 8-way refinement of a hex mesh, for coarse-against-fine validation of the solver.
//
// Input: a HexMesh (VTK node order) and, for refine_to_surface, the SurfaceProjector of the surface the mesh
// fills.
// Output: the refined mesh. Every hex is split into 8 at its edge midpoints, face centres and centre, the
// points of its own trilinear map, so a refinement without a surface has exactly the coarse volume and keeps
// every hex positively oriented wherever the trilinear map is. New nodes are shared between the hexes around
// an edge or a face, so the refined mesh is conforming; every boundary quad becomes 4 boundary quads, so the
// refined boundary is a submesh of the coarse one.
// Numbering: fine vertex v < coarse vertex count IS coarse vertex v (same id, same position: the map from
// coarse to fine vertices is the identity, also over several levels); then the edge midpoints, the face
// centres and the hex centres, each in the order of RefinementMap below. Fine hex 8 h + c is the child of
// coarse hex h that holds its corner c, so fine hex f lies in coarse hex f / 8 (f / 8^L after L levels).
// Cost: sorts the 12 m edges and 6 m faces, O(m log m) for m hexes; refine_to_surface adds one closest-point
// query per new boundary node and, when the projection damaged hexes, one optimizer run on the region
// around them (its cost grows with the region, not with the whole mesh).
// Deterministic: sorted keys, no hashing, single-threaded.
#pragma once

#include <array>
#include <optional>
#include <vector>

#include "mesher/boundary_fit.h"
#include "mesher/hex_mesh.h"
#include "mesher/hex_optimize.h"
#include "mesher/hex_quality.h"

namespace hexbite {

class SurfaceProjector;

// Where every new fine vertex comes from, in coarse vertex ids (each key sorted ascending).
//   fine vertex coarse_vertices + i                       midpoint of coarse edge edges[i]
//   fine vertex coarse_vertices + E + j                   centre of coarse face faces[j] (E = edges.size())
//   fine vertex coarse_vertices + E + F + h               centre of coarse hex h (F = faces.size())
// Edges and faces are listed in ascending order of their keys.
struct RefinementMap {
  int coarse_vertices = 0;
  int coarse_hexes = 0;
  std::vector<std::array<int, 2>> edges;
  std::vector<std::array<int, 4>> faces;
};

// One level of plain parametric refinement (no surface); refine_to_surface runs it once per level.
HexMesh refine_uniform(const HexMesh& coarse, RefinementMap* map = nullptr);

// The map that refine_uniform (and each level of refine_to_surface) numbers the new vertices by.
RefinementMap refinement_map(const HexMesh& coarse);

// The 4 fine quads that a face of a coarse hex (coarse vertex ids, in cyclic order) is split into, in fine
// vertex ids and in the face's own cyclic order (so an outward face has outward children): child k runs
// from corner k through the midpoint of edge k, k + 1, the face's centre and the midpoint of edge k - 1, k.
// Throws std::invalid_argument when `quad` is no face of the coarse mesh.
std::array<std::array<int, 4>, 4> child_quads(const RefinementMap& map, const std::array<int, 4>& quad);

struct RefineOptions {
  int levels = 1;
  // Coarse vertices keep their positions (the optimizer may not move them), so that the fine mesh contains
  // every coarse node where the coarse solution was computed.
  bool keep_coarse_vertices = true;
  // Re-optimize a level when projecting its new boundary nodes damaged a hex: inverted it, lowered its scaled
  // Jacobian by more than `damage` (relative to the split hex), or had to back a node off. Only the damaged
  // hexes and `optimize_rings` layers of hexes around them move; the rest keeps the exact split positions.
  bool optimize = true;
  double damage = 0.1;
  int optimize_rings = 2;
  // Barycentric smoothing is off: the refined mesh is already smooth, and Laplacian smoothing would pull
  // the fine mesh away from the coarse one that it is meant to validate.
  OptimizeOptions optimizer = [] {
    OptimizeOptions o;
    o.barycentric_iterations = 0;
    return o;
  }();
  // With a surface, after the last level: the new boundary nodes, which the projection put on the surface,
  // are moved off it until the boundary quads straddle it (mesher/boundary_fit.h), the input's nodes held;
  // for a coarse mesh fitted the same way (GridMeshOptions::fit_volume). Skipped when a hex is inverted.
  bool fit_volume = false;
};

struct RefineLevelReport {
  int hexes = 0;
  int nodes = 0;
  int projected_nodes = 0;            // new boundary nodes moved onto the surface
  int backed_off_nodes = 0;           // of those, nodes left short of the surface because the hexes around
                                      // them would have inverted (before the optimizer tried again)
  double max_projection = 0.0;        // largest distance a new boundary node moved onto the surface, mm
  double max_surface_distance = 0.0;  // largest distance of a new boundary node from the surface at the end
  QualitySummary parametric;          // after splitting, before projection
  QualitySummary projected;           // after projection and back-off
  int damaged_hexes = 0;              // hexes the projection damaged (see RefineOptions::damage)
  int optimized_hexes = 0;            // hexes in the re-optimized region, 0 when the optimizer did not run
  int off_surface_nodes = 0;          // new boundary nodes farther than 1e-6 mm from the surface at the end
  bool optimized = false;             // whether the optimizer ran on this level
  OptimizeReport optimize;            // its report (qualities over the region only), when it ran
  QualitySummary final_quality;       // the whole mesh at the end of the level
  double seconds_split = 0.0, seconds_project = 0.0, seconds_optimize = 0.0;
};

struct RefineReport {
  QualitySummary before;  // the input mesh
  QualitySummary after;   // the final mesh
  std::vector<RefineLevelReport> levels;
  std::optional<BoundaryFitReport> volume_fit;  // with RefineOptions::fit_volume
  double seconds_total = 0.0;
};

// `levels` rounds of refine_uniform; with a surface, after each round the new boundary nodes are projected
// onto it (closest point). Where a projection would invert a hex, the node backs off toward its parametric
// position (halving the step, down to the parametric position itself). Where that damaged hexes, the
// optimizer runs on the region around them (a submesh whose cut nodes are fixed) with the new boundary
// nodes sliding on the surface. `surface` may be null: then this is
// plain parametric refinement with a report. The result may still hold inverted hexes (report.after says
// which): callers decide whether that is an error.
HexMesh refine_to_surface(const HexMesh& coarse, const SurfaceProjector* surface,
                          const RefineOptions& options, RefineReport* report = nullptr);

}  // namespace hexbite
