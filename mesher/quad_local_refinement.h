// Local refinement of a quad surface around points (the bite point), keeping every chord simple: nested
// surface pillowing of a disk of quads around each point (seed paper section 2 allows a local refinement
// at the biting point; docs/mandible_quads.md, "Local refinement").
//
// Input: a quad surface of a ball with only simple chords (the placed mandible quads, quad_surface_
// placement.h), the triangulated surface it lies on (its SurfaceProjector), the vertices that must not move
// (landmark nodes), the points, a radius and a number of levels.
// Output: the refined quad surface. Existing vertex ids keep their meaning (new vertices are appended;
// only vertices inside the patches move, the patch boundary and everything outside stay where they were),
// and a report (patch size, quads added, mean edge length near each point before and after).
// Algorithm:
//   1. Patch: the quads whose centroid lies within the radius of a point's closest surface point, reached
//      from the quad nearest to it through such quads. The union over the points is grown until every
//      component is a disk with one simple boundary loop: the quads cut off from the largest part of the
//      rest (holes) are added, and every rim vertex where the patch touches itself (more than two patch-
//      boundary edges) or that has more than half of its quads in the patch (a concave corner, where
//      step 3 would fold quads) gets all its quads, repeated until nothing changes.
//   2. Pillowing, `levels` times around the same patch: every patch-boundary vertex gets a copy, which takes
//      its place in the patch quads, and every boundary edge (a, b) a quad (a, b, b', a') between it and its
//      copy. Each level adds one closed chord per patch component, running once through its new ring of
//      quads, and the chords that crossed the boundary edge now cross the ring quad too, once: simple chords
//      stay simple, the surface stays a closed, oriented ball, and the count stays even (a disk of quads
//      has an even perimeter).
//   3. Placement: the moved vertices (patch interior and copies) start where their originals are and are
//      relaxed by Gauss-Seidel sweeps to the mean of their edge neighbours (a Tutte embedding of the disk
//      with its boundary loop fixed), each projected back onto the surface, never onto a face whose normal
//      opposes the one the vertex sat on nor so that more quad corners around it fold (against the
//      unrefined quads' normals; then half and a quarter of the step are tried). On nested rings of P
//      quads the uniform Laplacian spaces the rings geometrically (ratio about exp(-2 pi / P), near-square
//      quads), so the quads shrink toward the point: the refinement. Landmark vertices inside a patch stay
//      fixed.
// Hand-written: pillowing a disk of a quad surface is a few lines over our own QuadSurface (no library we
// use offers it), and the relaxation needs the restricted projection on the input triangles.
// Failure: LocalRefinementError (an InputError) when a point is farther than max_point_distance_mm from the
// surface (naming it by point_names), the radius or the levels are out of range, or the patches would cover
// the whole surface.
// Cost: O(Q) for the patch and the pillowing (Q quads), plus up to 3 relax_sweeps closest-point queries
// per moved vertex (O(log T) each for T triangles); 8 to 18 ms for one bite point on the mandibles
// (docs/mandible_quads.md, "Local refinement around the bite point").
// Deterministic: single-threaded, fixed orders.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "common/error.h"
#include "mesher/hex_mesh.h"
#include "mesher/surface_projector.h"

namespace hexbite {

// The input errors of refine_quads_locally(). Their message names the point (point_names), radius or levels
// at fault, so callers pass them on as they are instead of as a failure of what they refine.
class LocalRefinementError : public InputError {
 public:
  using InputError::InputError;
};

// Ranges of the radius and the levels (the CLI and the scenario reader check them with their own names).
inline constexpr double kMinRefineRadiusMm = 1.0;
inline constexpr double kMaxRefineRadiusMm = 30.0;
inline constexpr int kMaxRefineLevels = 6;

struct LocalRefinementOptions {
  std::vector<Vec3> points;              // centres (mm); empty: no refinement
  std::vector<std::string> point_names;  // how error messages name each point (e.g. the CLI option)
  double radius_mm = 8.0;                // patch: quads with their centroid within this of a point
  int levels = 3;                        // rings of quads added around each patch (1 to 6)
  int relax_sweeps = 300;                // step 3; stops earlier when no vertex moves 1e-4 mm
  double max_point_distance_mm = 5.0;    // a point farther from the surface is an input error
  bool enabled() const { return !points.empty(); }
};

struct LocalRefinementSite {
  Vec3 point{};       // as given
  Vec3 on_surface{};  // its closest surface point, the centre of the measurements
  // Mean length of the quad edges whose midpoint lies within the radius of on_surface, and their number.
  double mean_edge_before_mm = 0;
  double mean_edge_after_mm = 0;
  int edges_before = 0;
  int edges_after = 0;
};

struct LocalRefinementReport {
  std::vector<LocalRefinementSite> sites;
  int patches = 0;          // disk components of the grown patch
  int patch_quads = 0;      // quads in them
  int patch_perimeter = 0;  // patch-boundary edges: quads added per level
  int levels = 0;
  int quads_added = 0;
  int vertices_added = 0;
  int moved_vertices = 0;  // relaxed in step 3
  int relax_sweeps = 0;    // sweeps run
  int folded_quads = 0;    // quads with a moved vertex and a corner normal against the surface normal
  // The rungs (v, copy of v) of the ring chords, innermost level first: eliminating these chords first
  // (EliminationOptions::first_rungs) gives back the unrefined surface, so the rest of the cycle
  // elimination is that of the unrefined quads and the refinement adds pillow sheets under the patch.
  std::vector<std::array<int, 2>> ring_rungs;
  double seconds = 0;
};

// Steps 1 to 3. `fixed_vertices` (ids into quads.vertices) never move. `report` may be null.
QuadSurface refine_quads_locally(const QuadSurface& quads, const SurfaceProjector& surface,
                                 const std::vector<int>& fixed_vertices,
                                 const LocalRefinementOptions& options,
                                 LocalRefinementReport* report = nullptr);

// Mean length of the edges of `quads` whose midpoint lies within `radius` of `center`; *count (if not
// null) receives their number. 0 when there is none.
double mean_edge_near(const QuadSurface& quads, const Vec3& center, double radius, int* count = nullptr);

}  // namespace hexbite
