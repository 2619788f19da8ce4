// Robust all-hex meshing of any closed triangulated solid: an overlay grid, a pillow layer, the optimizer.
//
// Input: a closed, outward oriented, manifold TriSurface in millimetres (as load_closed_surface returns it)
// and a target number of hexes.
// Output: a positively oriented HexMesh whose boundary nodes lie on the surface, and a report with the
// chosen cell size, the per-phase quality table, the geometric fidelity (two-sided sampled Hausdorff
// distance and volume difference) and the surface regions the cell size could not resolve, which
// name_unresolved_parts names by the nearest landmark and muscle insertion of a landmark file.
// Algorithm:
//   1. cell size h from the target, counting the pillow layer (core cells + core boundary quads), found by
//      a few secant steps on the actual counts;
//   2. core: the grid cells whose centre lies inside the surface at a distance of at least margin * h, or
//      with the default negative margin outside at most -margin * h (cells that reach well into the solid,
//      so that plates thinner than a cell, like the coronoid process, keep a sheet of cells); with fine
//      cells either fine_margin everywhere (the plain core: the cells whose centre lies inside) or margin
//      only where the solid is thinner than a cell and thick_margin elsewhere (the thick-margin core), on
//      different grids (step 5); inside by crossing parity along grid columns, distances from the AABB tree.
//      Cells are added until no two cells share only an edge or a vertex and the core boundary is a
//      2-manifold (this also joins parts that touch the rest only along an edge), the largest face-connected
//      component is kept and enclosed cavities are filled. With several shells the surface is grouped into
//      bodies (an outer shell with the inner shells, voids, nested in it): each body keeps its main component
//      (the one with the most cells whose centre lies inside that body; a body without one is reported as a
//      separate shell smaller than a cell), only other fragments are dropped as narrow necks, and an enclosed
//      cavity that holds a cell inside a void stays open (its boundary is pillowed onto the inner shell);
//   3. pillow layer: core boundary vertices outside or near the surface are pulled below it, then each gets
//      a copy on the surface (along the vertex normal, or the closest point), and each core boundary quad one
//      hex to it, so no hex has two boundary faces;
//   4. optimize_hex_mesh with the boundary sliding on the surface, resting nodes skipped, and its
//      worst-element pass (hexes with a scaled Jacobian or 3 / kappa below 0.5; both stages twice, each
//      first stage followed by the condition stage for the hexes of kappa above 9.9);
//   5. steps 1-4 again on the grid shifted by half a cell, then by a quarter; the mesh with the fewest
//      inverted hexes, then the largest worst-element measure min(scaled Jacobian, 3 / kappa), is kept
//      (with fine cells: the higher mean where both measures reach mean_tie_break). With fine cells four
//      attempts: the regular core (the plain core, shallower where the solid is thick, with fewer
//      irregular boundary vertices) unshifted, the plain core shifted by half a cell, the thick-margin core
//      shifted by half and by a quarter; where the best of them has a measure below 0.3, the two
//      shifted grids again with margin everywhere (attempts = 6); where another attempt reaches
//      mean_tie_break but the regular core does not, the regular core on the other two grids (attempts = 6);
//      With GridMeshOptions::swept_core the attempts are instead the core swept across the arch
//      (mesher/swept_core.h), unshifted and shifted by half a cell; where the better keeps an inverted hex,
//      both again with the optimizer's Newton sweeps and no tips pass (attempts = 4);
//   6. on the kept mesh only, improve_mean_jacobian raises the mean scaled Jacobian without lowering that
//      measure (no hex below the smaller of its own value and the mesh's smallest scaled Jacobian; boundary
//      nodes sliding within worst_element_reach of where the pillow layer put them).
// Cost: O(N) cells, O(N^(2/3)) segment queries for classification and a distance query per outside cell
// near a surface triangle (for the default negative margin) per trial size; the optimizer dominates. Each
// grid of step 5 repeats steps 1-4; step 6 runs once.
// Threads: the grids of step 5 run in up to GridMeshOptions::threads threads (default 2, this machine's
// cores); the calling thread shows progress, the others are quiet (QuietThread, common/progress.h).
// Deterministic: same surface and options, same mesh (bit for bit), whatever the number of threads.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "mesher/boundary_fit.h"
#include "mesher/hex_mesh.h"
#include "mesher/hex_optimize.h"
#include "mesher/landmarks.h"
#include "mesher/tri_surface.h"

namespace hexbite {

class SurfaceProjector;

// The range of a wanted hex count (`hexbite mesh --target-hexes`, a scenario's mesh.target_hexes): fewer
// than 8 hexes cannot form a grid, and above 5,000,000 the mesh and its solve outgrow a workstation.
constexpr long kMinTargetHexes = 8;
constexpr long kMaxTargetHexes = 5000000;

struct GridMeshOptions {
  long target_hexes = 2500;
  // Cells whose centre lies at least margin * h inside the surface form the core; a negative margin takes
  // cells whose centre lies up to -margin * h outside (cells reaching into the solid), so that parts
  // thinner than a cell stay in the core.
  double margin = -0.4;
  // Fine cells: the solid's mean thickness 2 V / A is at least thick_margin_cells cells. Coarser grids use
  // margin everywhere (with the solid 1 to 3 cells thick, every cell reaching into it counts). Fine grids
  // use either fine_margin everywhere (the plain core: fewer cells reach out of the solid, so the pillow
  // hexes are thicker; the better means) or the thick-margin core: an outside cell whose centre lies
  // farther out than thick_margin * h (but within -margin * h) is kept only where the solid is thinner than
  // a cell, so thin plates keep their cells. Between two fine grids whose min(scaled Jacobian, 3 / kappa)
  // are both at least mean_tie_break, the one with the higher mean scaled Jacobian is kept.
  double fine_margin = 0.0;
  double mean_tie_break = 0.5;
  // After the mean stage, boundary nodes move off the surface until the boundary quads straddle it
  // (mesher/boundary_fit.h; report.volume_fit, a phase "volume fit"); off by default.
  bool fit_volume = false;
  // Fine cells: when the best attempt's min(scaled Jacobian, 3 / kappa) is below this (a defect, not a
  // minimum merely short of 0.5), the shifted grids are meshed again with margin everywhere (attempts = 6).
  double retry_below = 0.3;
  double thick_margin = -0.2;
  // Fine cells: the first attempt's core is the regular core. It is the plain core (fine_margin) without
  // the cells whose centre lies less than regular_margin * h inside the surface where the solid is at least
  // regular_thin_cells cells thick (pillow hexes of more even thickness), then regularized: single boundary
  // cells are removed (centre at most regular_inside * h inside) or added (centre at most
  // regular_outside * h outside) where the solid is at least two cells thick, while that lowers the number
  // of irregular core boundary vertices (valence other than 4), whose pillow hexes are the worst.
  double regular_margin = 0.2;
  double regular_thin_cells = 1.0;
  double regular_inside = 0.4;
  double regular_outside = 0.15;
  double thick_margin_cells = 3.0;
  // Grid positions, each a full run: unshifted, shifted by half a cell, by a quarter (1 to 3; with fine cells
  // the regular core on the first, the plain core on the second, the thick-margin core on all but the
  // first). The mesh with the fewest inverted hexes, then the largest min(scaled Jacobian, 3 / kappa), is
  // kept.
  int grids = 3;
  // Grids meshed at once, each in its own thread (1 to 4); the mesh does not depend on it.
  int threads = 2;
  // Lay the grid along the dental arch (mesher/arch_frame.h: the core is selected in arch coordinates and
  // mapped back before the pillow layer) instead of along the axes; for a whole mandible in the mandible
  // frame (throws NotAnArchError, an InputError, for a surface that does not follow an arch).
  bool arch_frame = false;
  // Lay the grid along the solid's principal axes (mesher/principal_frame.h) instead of the coordinate
  // axes. When principal_retry is on and the axes' grids leave inverted hexes (a solid with flat faces at an
  // angle to the axes), the principal axes' grids are meshed too and the mesh with fewer inverted hexes is
  // kept (report.principal_retry). When that still leaves inverted hexes, the grids along the solid's
  // largest flat faces (face_frame in mesher/principal_frame.h: an L-shaped block's principal axes lie
  // along its diagonal) are tried the same way. None of this applies with arch_frame or swept_core.
  bool principal_frame = false;
  bool face_frame = false;  // the grid along the largest flat faces instead (the retry's third frame)
  bool principal_retry = true;
  // The core swept across the dental arch (mesher/swept_core.h) instead of the grid cores: a grid over the
  // bone's side view with swept_layers hexes across the bone in each column, unshifted and shifted by half
  // a cell (two attempts, the better kept as in step 5). Implies arch_frame. Meant for coarse meshes: with
  // one layer and the pillow layer every column is three hexes across the bone, at any size.
  bool swept_core = false;
  int swept_layers = 1;
  // The swept core's boundary tether (OptimizeOptions::boundary_tether, 0.5 for the grids): its thin
  // coronoid and condyle columns otherwise let the boundary slide off their tips (docs/meshing.md).
  double swept_tether = 0.25;
  // Newton sweeps of the swept core's condition-number optimization (OptimizeOptions::max_iterations; the
  // worst-element pass and the mean stage still run). 0: the swept core's hexes are already regular, and the
  // sweeps mostly slide boundary nodes off the condyles and the coronoids (at 2,500 hexes the built-in
  // mandible's Hausdorff distance 1.71 -> 1.38 mean edges, the real jaw's 1.49 -> 1.42, volume -4.5 ->
  // -4.0 / -3.8 %, the element targets kept; docs/meshing.md).
  int swept_newton_sweeps = 0;
  // The swept core's boundary nodes reach the surface's tips (reach_far_surface, mesher/boundary_fit.h):
  // surface vertices farther than this many mean boundary edges from the mesh pull their nearest boundary
  // node onto them, after the pillow layer (before the optimizer, validity only) and after the mean stage
  // (see swept_tips_*). 0: no such pass.
  double swept_reach_far = 0.5;
  // The pass after the mean stage: surface vertices farther than swept_tips_limit mean edges pull (below
  // swept_reach_far: the Hausdorff distance, measured between the vertices too, gets a margin); a move may
  // take a hex's scaled Jacobian down to swept_tips_floor and its condition number up to
  // swept_tips_condition (or leave it where it is, if already beyond; 0 and 0: the worst element never
  // worse); then swept_tips_relax_rounds times the interior nodes of the moved nodes' hexes get the
  // worst-element pass and the mean stage (the boundary held), and the tips pass again (a round that takes
  // the mesh's worst below that floor or above that cap is undone). At 2,500 hexes the built-in mandible's
  // Hausdorff distance 1.07 -> 0.51 mean edges, the real jaw's 0.88 -> 0.86 (its coronoid tips: a corner
  // node of a 1.7 mm plate, a quarter of the way there already takes kappa above 11); docs/meshing.md.
  double swept_tips_limit = 0.4;
  double swept_tips_floor = 0.35;
  double swept_tips_condition = 9.5;
  int swept_tips_relax_rounds = 3;
  // The optimizer's options; the grid mesher skips resting nodes and adds the worst-element pass, twice,
  // with the condition stage (kappa 9.9: the kappa <= 10 with a margin; on the real jaw at 2,500
  // hexes stage 1 stalls at 10.79 on the thin rami), and the mean stage (on the kept grid only) with the
  // mesh's smallest scaled Jacobian as its only floor (with the 0.5 floor the lower kappa cap cost the
  // jaw's mean at 2,500 hexes 0.007; without it 0.7548 against 0.7546 before; docs/meshing.md).
  OptimizeOptions optimize = [] {
    OptimizeOptions o;
    o.reactivate = 0.01;
    o.worst_element_threshold = 0.5;
    o.worst_element_reach = 0.8;
    o.scaled_jacobian_sweeps = 3;
    o.worst_element_rounds = 2;
    o.condition_target = 9.9;
    o.mean_jacobian_sweeps = 10;
    o.mean_jacobian_floor = 0.0;
    return o;
  }();
};

// A named point near an unresolved part: a landmark, or a muscle insertion ("<muscle>.insertion").
struct NearbyPoint {
  std::string name;
  double distance = 0;  // from the part's location, mm
};

// A region of the surface that the mesh does not reach (a part too thin for the cell size, a core
// component that was dropped because it is not face-connected to its body's main one, a separate shell
// smaller than a cell, or separate shells closer than a cell that the mesh joins).
struct UnresolvedPart {
  Vec3 location{};    // centroid of the region, mm
  double extent = 0;  // largest distance of the region's surface from the mesh boundary, mm
  int samples = 0;    // triangles in the region (a dropped core piece: its grid cells)
  // The solid's thickness under the region (the median inward ray through it), mm; 0 for a whole shell or
  // where no ray crosses the solid.
  double thickness = 0;
  std::string what;  // one sentence
  // Set by name_unresolved_parts: the nearest landmark and the nearest muscle insertion, nearest first
  // (empty without landmarks); `what` names those within 20 mm.
  std::vector<NearbyPoint> near;
};

struct MeshFidelity {
  double hausdorff_mesh_to_surface = 0;    // max over boundary samples of the distance to the surface, mm
  double hausdorff_surface_to_mesh = 0;    // max over surface samples of the distance to the mesh boundary
  double hausdorff = 0;                    // the larger of the two
  double mean_edge_length = 0;             // over all hex edges, mm
  double mesh_volume = 0;                  // mm^3 (exact for trilinear hexes)
  double surface_volume = 0;               // mm^3
  double volume_difference = 0;            // (mesh - surface) / surface
  std::vector<UnresolvedPart> unresolved;  // surface regions farther than half the mean edge length
};

// The principal axes' (and the flat faces') grids meshed after the axes' grids left inverted hexes
// (GridMeshOptions).
struct PrincipalRetry {
  int axes_inverted = 0;        // inverted hexes of the axes' best grid
  int principal_inverted = -1;  // and of the principal axes' best grid (-1: not tried, see below)
  int faces_inverted = -1;      // and of the flat faces' (-1: not tried, as the others left none or it has
                                // no such faces, or they lie along the axes already tried)
  bool kept = false;            // a retry's mesh was kept (it had fewer)
  std::string kept_frame = "axes";  // the frame kept: "axes", "principal" or "faces"
};

// "the grids along the coordinate axes left 2 inverted hexes; along the solid's principal axes 1; along its
// largest flat faces 0: kept those", for `mesh` and `run`.
std::string principal_retry_text(const PrincipalRetry& retry);

struct GridMeshReport {
  // Grids tried (GridMeshOptions::grids; with fine cells 4, or 6 with the mean or the defect retry).
  int attempts = 1;
  bool principal_frame = false;                   // the kept grid lies along the principal axes
  bool face_frame = false;                        // the kept grid lies along the largest flat faces
  std::optional<PrincipalRetry> principal_retry;  // when it was tried
  double cell_size = 0;                           // h, mm (this and the fields below describe the kept grid)
  std::array<int, 3> grid{};                      // grid cells per axis
  int core_hexes = 0;
  int pillow_hexes = 0;
  bool swept = false;  // the kept core is the swept core (grid: cells along s, layers across, cells along z)
  int cells_added_for_manifold = 0;
  int cells_in_dropped_components = 0;  // the swept core: columns dropped (SweptCore::dropped_columns)
  // Vertices of the core's boundary quad surface, and those of valence other than 4 among them.
  int core_boundary_vertices = 0;
  int irregular_core_boundary_vertices = 0;
  OptimizeReport optimize;
  std::optional<BoundaryFitReport> volume_fit;  // with GridMeshOptions::fit_volume and no inverted hex
  MeshFidelity fidelity;
  // The kept grid's phases; seconds_total covers every grid tried.
  double seconds_core = 0, seconds_pillow = 0, seconds_optimize = 0, seconds_fidelity = 0, seconds_total = 0;
};

// The worst-element measure by which meshes are compared (after the count of inverted hexes): the smaller
// of the smallest scaled Jacobian and 3 / the largest condition number (a cube scores 1).
double worst_element_measure(const QualitySummary& quality);

// Meshes the solid. Throws InputError when the target is not positive or when the surface encloses no
// cell at any size; the returned mesh may contain inverted hexes (report.optimize.inverted says how many).
HexMesh grid_mesh(const TriSurface& surface, const GridMeshOptions& options,
                  GridMeshReport* report = nullptr);

// Names each part by the nearest landmark point and the nearest muscle insertion of `landmarks` (each when
// there is one): fills `near` and starts `what` with "near left_coronoid_tip (3.2 mm), ...: ".
void name_unresolved_parts(const Landmarks& landmarks, std::vector<UnresolvedPart>& parts);

// What `hexbite mesh` and `hexbite run` print of the parts: the sentences of the first `shown` (dropped or
// joined bodies first, then the regions farthest from the mesh), and for the rest one line "... and N
// smaller regions". The full list is in the commands' JSON.
std::vector<std::string> unresolved_listing(const std::vector<UnresolvedPart>& parts, std::size_t shown = 10);

// Volume of a trilinear hex, and of a hex mesh (2 x 2 x 2 Gauss points, exact for trilinear maps).
double hex_volume(const HexMesh& mesh, int hex);
double hex_mesh_volume(const HexMesh& mesh);

// Geometric fidelity of a hex mesh against the surface it should fill.
MeshFidelity measure_fidelity(const HexMesh& mesh, const SurfaceProjector& surface);

}  // namespace hexbite
