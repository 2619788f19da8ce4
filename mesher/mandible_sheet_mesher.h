// The sheet mesher on a triangulated mandible: a quad surface placed from the mandible template, cycle
// elimination, a pillow layer and an optimization with the boundary sliding on the input (docs/
// mandible_quads.md, "Embedding"). Used by `hexbite mesh SURFACE --method sheets` (app/mesh_sheets_surface.h)
// and by `hexbite run` with `mesh: {method: sheets}` (app/run_pipeline.h).
//
// Input: a closed, outward triangle surface of a whole mandible in the built-in mandible's frame (+x
// subject's left, +y posterior, +z superior, mm), optionally its landmarks (mesher/landmarks.h; without them
// the surface's extreme points place the template), and a target number of hexes.
// Algorithm:
//   1. The quad surface: quad_surface_from_mandible() (mesher/quad_surface_placement.h) with
//      quads_for_target_hexes(target_hexes) quads, optionally refined around points (the bite point) by
//      refine_quads_locally() (mesher/quad_local_refinement.h), then check_quad_surface()
//      (mesher/quad_check.h).
//   2. Cycle elimination (mesher/cycle_elimination.h) in the given order, the ring chords of the bite-point
//      refinement and of the placement's fidelity refinement (MandibleQuadReport::ring_rungs) first; the
//      sheet mesher only smooths the interior (its own optimizer would hold the whole boundary fixed).
//   3. A pillow layer under the quad surface: every quad vertex gets an inner copy, which takes its place in
//      the hexes, and every quad a hex between it and the copies of its corners (copies start 40 % of the way
//      from the vertex to the mean centroid of its hexes). The boundary stays the quad surface; no hex keeps
//      two faces on it, which removes the hexes wrapped around thin rims and process tips.
//   4. optimize_hex_mesh() (mesher/hex_optimize.h) with the input's SurfaceProjector: the quad surface being
//      our own construction, its nodes slide on the input (tether a quarter edge), only the landmark nodes
//      (MandibleQuadReport::landmark_vertices) stay fixed; then the worst-element pass (threshold 0.3, 10
//      scaled-Jacobian sweeps, two rounds) and the mean stage (10 sweeps raising the mean scaled Jacobian
//      without lowering the worst).
//   5. Quality and fidelity (measure_fidelity, mesher/grid_mesher.h) of the final mesh against the input,
//      and the boundary quads that cross each other (mesher/quad_surface_crossings.h).
// Output: the mesh (vertices 0 .. quads' vertices - 1 are the boundary, in the quad surface's order) and a
// report. Hexes left inverted and a boundary that crosses itself are reported (MandibleSheetReport::inverted,
// boundary_crossings), not thrown: the caller decides.
// Failure: InputError "NAME: ..." when the landmarks lack the points the template needs, the surface is not
// mandible-like or the target is out of range; RunError when the quad surface fails its check (crossing
// itself included: the template folds over thin parts at high densities) or the cycle
// elimination gets stuck (a defect of the template or its placement, not of the input). NAME is
// MandibleSheetOptions::surface_name.
// Cost: the quad surface's (quad_surface_placement.h) plus elimination and optimization, O(m) per sweep
// for m hexes; about 2 to 2.5 s in all for the built-in mandible at 2,500 to 4,000 hexes.
// Deterministic: single-threaded, fixed orders.
#pragma once

#include <optional>

#include <string>
#include <vector>

#include "mesher/boundary_fit.h"
#include "mesher/cycle_elimination.h"
#include "mesher/grid_mesher.h"
#include "mesher/hex_mesh.h"
#include "mesher/input_terms.h"
#include "mesher/landmarks.h"
#include "mesher/quad_check.h"
#include "mesher/quad_local_refinement.h"
#include "mesher/quad_surface_crossings.h"
#include "mesher/quad_surface_placement.h"

namespace hexbite {

struct MandibleSheetOptions {
  long target_hexes = 2500;  // the quad surface gets quads_for_target_hexes(target_hexes) quads
  EliminationOrder order = EliminationOrder::kGeometric;
  std::string surface_name = "the surface";  // names the input in error messages
  std::string landmark_file;                 // names the landmarks in error messages
  LocalRefinementOptions refinement;         // around refinement.points; none by default
  // After the optimization, boundary nodes (the landmark nodes excepted) move off the surface until the
  // boundary quads straddle it (mesher/boundary_fit.h); off by default.
  bool fit_volume = false;
  InputTerms terms;  // how messages name the user's choices
};

struct MandibleSheetReport {
  MandibleQuadReport quad;           // the quad surface: placement, density, distance to the input
  QuadSurfaceReport quad_check;      // its check (usable, or the mesher throws)
  LocalRefinementReport refinement;  // empty sites when no refinement was asked for
  // Cycle elimination; hexes, interior_vertices, quality, optimize and seconds_embedding describe the final
  // mesh (pillow layer and sliding optimization included).
  SheetMeshReport sheets;
  int pillow_hexes = 0;   // one per quad of the quad surface
  MeshFidelity fidelity;  // the final (slid, and with fit_volume fitted) boundary against the input
  std::optional<BoundaryFitReport> volume_fit;  // with MandibleSheetOptions::fit_volume
  int inverted = 0;  // hexes left inverted; sheets.quality.inverted_hexes lists them
  // Pairs of boundary quads of the final mesh that cross each other (mesher/quad_surface_crossings.h), and
  // the message naming the first ("" when none): the hexes there overlap, so the mesh is invalid too.
  std::vector<std::array<int, 2>> boundary_crossings;
  std::string boundary_crossing_text;
};

// Step 1 alone (`hexbite quad from-mandible`): the quad surface of about target_quads quads, refined
// locally when `refinement` has points (the landmark nodes stay fixed), checked. `report` and `check` must
// not be null; report's quads, chords, max_chord_length and mean_edge_mm then describe the refined surface,
// its distances the surface before the refinement. Throws as described above.
QuadSurface checked_mandible_quads(const TriSurface& surface, const Landmarks* landmarks, int target_quads,
                                   const std::string& surface_name, const std::string& landmark_file,
                                   MandibleQuadReport* report, QuadSurfaceReport* check,
                                   const LocalRefinementOptions& refinement = {},
                                   LocalRefinementReport* refinement_report = nullptr,
                                   const InputTerms& terms = {});

// Steps 1 to 5. `landmarks` may be null (extreme points place the template); `report` may be null.
HexMesh mesh_mandible_by_sheets(const TriSurface& surface, const Landmarks* landmarks,
                                const MandibleSheetOptions& options, MandibleSheetReport* report = nullptr);

}  // namespace hexbite
