// Hex meshing of a ball-shaped quad surface by successive chord (dual cycle) elimination, the seed paper's
// combinatorial mesher (section 3; definitions in ../shared/DESIGN.md section 3 and mesher/quad_check.h).
//
// Input: a QuadSurface that check_quad_surface() finds usable (closed, manifold, consistently oriented
// outward, genus 0, even, simple, 3-connected, no self-intersecting chord).
// Algorithm:
//   1. Elimination. While the surface is not a cube (6 quads), pick a step and collapse its strips: every
//      rung (an edge a chord crosses) shrinks to a point, so every strip quad shrinks to an edge and the two
//      rails of each strip merge. A single elimination takes one simple chord whose rung endpoints are 2 L
//      distinct vertices (both rails are disjoint simple cycles) and whose strip leaves exactly two sides;
//      its elimination side Q (the quads that receive hexes) is the smaller side. A k-step elimination takes
//      k >= 2 chords with pairwise vertex-disjoint strips and the seed's conditions: with Q_i the side of
//      chord i that holds the other chords and Q their intersection, (2) Q is edge-connected and (3) Q
//      union Q_i has more quads than Q for every i; also every Q-side rail bounds Q, so that one sheet
//      under Q meets the surface exactly in the k chords. Either is feasible when (1) the collapsed surface
//      is again a closed manifold ball whose graph is simple, planar and 3-connected
//      (is_polyhedral_ball(), mesher/elimination_feasibility.h: a face test, near-linear).
//   2. Construction, in reverse order, starting from one hex on the final cube: for an elimination with side
//      Q, one hex is placed on each quad of Q between the quad as it was before the collapse (outer, on the
//      larger surface) and as it is after it (inner). The Q-side rail vertices map onto their rung partners,
//      the other vertices of Q get new interior vertices; the new sheet of hexes is bounded by the eliminated
//      chords (an external sheet), whose strip quads become the sheet's side faces.
//   The boundary of the result is therefore exactly the input surface: vertices 0..n-1 are the input's
//   vertices with the same coordinates, every input quad is a boundary face, and only interior vertices
//   (ids >= n) are new.
//   3. Embedding: new vertices start at the position of the vertex they were split from, then barycentric
//      smoothing to convergence and optimize_hex_mesh() with every boundary vertex fixed.
//   4. Pillow rescue: where hexes stay inverted (typically hexes with two faces on the boundary at a flat
//      angle, or a complex without interior vertices), a pillow layer under the boundary (mesher/
//      hex_pillow.h) and step 3 again; the result with fewer inverted hexes is kept. The boundary is
//      still exactly the input.
// Ordering strategies (single eliminations first try the smallest side; ties: the lower chord number):
//   kFewestHexes takes the first feasible single elimination; kLookAhead the first after which the surface
//   is a cube or still has a feasible single elimination (no dead end one step on); kGeometric, the seed's
//   rule of preferring chords next to sharp primal cycles, puts single and 2-step eliminations whose Q-side
//   rails are sharp (mean angle between the normals of the strip quads and the Q quads across the rail of
//   45 degrees or more) before the others, then orders by fewest hexes, with the look-ahead test; 2-steps
//   only when both rails are sharp. Before all of them come pillows on flat patches (Q, the strip and the
//   quads across both rails within 15 degrees), whose internal sheet fits only early. The default. The
//   geometry is that of the current surface: merged rail vertices take their partners' positions, the other
//   vertices of Q follow by the harmonic extension of those moves.
// k-steps never rescue a surface on which no single elimination is feasible: the collapse of vertex-
// disjoint chords is the collapse of one followed by the others, and later collapses neither remove nor
// separate the quads of a defect made by the first. They change which hexes are built (one annular sheet
// instead of two disk sheets), which is why only the geometric order weighs them.
// Internal sheets (mesher/internal_sheet.h) replace external ones during the construction where their
// conditions hold (SheetMeshOptions::internal_sheets).
// Decomposition (mesh_by_cycle_elimination() only, mesher/primal_cycle_decomposition.h): when the
// elimination of a surface gets stuck, the surface is split along a short even primal cycle spanned by a
// quad disk into two balls (each side plus the disk); each part is meshed in the same way (elimination,
// construction, and a nested decomposition up to DecompositionOptions::max_depth), the first split whose
// two parts both mesh with the least nesting is taken, each part gets a pillow layer under its quads
// (DecompositionOptions::pillow_parts: its hexes then lie one layer inside and can move), and the two
// complexes are glued along the disk (the same vertices and quads, so the result is conforming; the disk's
// vertices are new interior vertices).
// Failure: when no elimination is feasible before the cube, RunError naming the remaining chords and some of
// their quads, suggesting --method grid; from mesh_by_cycle_elimination() only when no decomposition helps
// either, saying how many cycles and splits were tried. With the embedding (SheetMeshOptions::optimize,
// the boundary fixed), InputError before the elimination for a quad corner that is collinear or reflex
// (non_convex_corners_problem()): every hex on that quad has a corner Jacobian of 0 or below there, so no
// valid mesh with that boundary exists.
// Cost: per step, the chords and sides O(C F) for C chords and F quads, each feasibility test O(F log F);
// kFewestHexes usually tests one candidate per step, the look-ahead orders up to all candidates of the next
// step; the geometric order also measures the rail angles and the flatness of every candidate, O(C F) per
// step, and prepares the chord pairs whose facing rails are both sharp, O(F) each. The construction tries an
// internal sheet per elimination, O(m log m) for the m hexes built so far.
// Deterministic: fixed orders, no hashing, single-threaded.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "mesher/hex_mesh.h"
#include "mesher/hex_optimize.h"
#include "mesher/hex_quality.h"
#include "mesher/primal_cycle_decomposition.h"

namespace hexbite {

enum class EliminationOrder { kFewestHexes, kLookAhead, kGeometric };

// Parses "fewest-hexes", "look-ahead" or "geometric"; InputError for anything else.
EliminationOrder parse_elimination_order(const std::string& name);
const char* elimination_order_name(EliminationOrder order);

enum class SheetKind { kExternal, kInternal };

// One elimination step (one chord, or k chords at once) and the sheet of hexes that undoes it.
struct Elimination {
  SheetKind kind = SheetKind::kExternal;  // as eliminated; build_hex_complex() may place an internal one
  int chords = 1;                         // chords eliminated by this step (k)
  int chord_length = 0;                   // quads in the eliminated strips
  int quads_before = 0;                   // surface size before the collapse
  int other_side_quads = 0;               // quads of the side that got no hexes
  int first_new_vertex = 0;  // the interior vertices of the inner quads: ids first_new_vertex ...
  int new_vertices = 0;      // ... first_new_vertex + new_vertices - 1
  // hexes[i] = {outer quad, inner quad}: the outer quad is on the surface before the collapse (counter-
  // clockwise seen from outside), the inner one is the same quad after it, with matching corners.
  std::vector<std::array<std::array<int, 4>, 2>> hexes;
};

struct EliminationScheme {
  int input_vertices = 0;
  int total_vertices = 0;                 // input vertices plus the interior ones created by the eliminations
  std::vector<Elimination> eliminations;  // in elimination order
  std::array<std::array<int, 4>, 6> cube{};  // the final surface
  std::vector<int> split_from;  // for every interior vertex (id - input_vertices), the vertex it copies
};

struct EliminationOptions {
  // The best measured (docs/sheets.md): equal to the others on blocks, polycubes, box chains and spheres,
  // as good on the jaw's quad surface, valid where they leave inverted hexes (the O-grid disk).
  EliminationOrder order = EliminationOrder::kGeometric;
  // Where `order` runs into a dead end (no feasible chord left), mesh_by_cycle_elimination eliminates again
  // in the look-ahead order before it decomposes along a primal cycle
  // (SheetMeshReport::look_ahead_fallbacks).
  bool look_ahead_after_dead_end = true;
  // Chords to eliminate before the order chooses, each named by one of its rungs (an edge {a, b} of the
  // input surface), in this order: at its turn a rung still on a simple chord whose single elimination is
  // feasible (and, in the look-ahead orders, no dead end) is eliminated on its smaller side; rungs that a
  // collapse removed, and infeasible ones, are skipped (ids merged by a collapse are followed). Used for
  // the ring chords of a local refinement (mesher/quad_local_refinement.h).
  std::vector<std::array<int, 2>> first_rungs;
};

// Step 1. Throws InputError when the surface is not usable and RunError when no feasible chord is left.
EliminationScheme eliminate_chords(const QuadSurface& surface, const EliminationOptions& options = {});

// Step 2: the hex complex, with vertex coordinates for 0..input_vertices-1 copied from the surface and the
// interior ones placed at the vertex they were split from (not yet embedded).
HexMesh build_hex_complex(const QuadSurface& surface, const EliminationScheme& scheme);

// The same, placing an internal sheet (mesher/internal_sheet.h) instead of the external one wherever its
// conditions hold when internal_sheets is set; kinds (if not null) receives the kind of every elimination's
// sheet, in elimination order. Vertices no hex uses any more (the created vertices of an internal sheet's
// side, which take back the outer quads' ids) are dropped, the others keep their order.
HexMesh build_hex_complex(const QuadSurface& surface, const EliminationScheme& scheme, bool internal_sheets,
                          std::vector<SheetKind>* kinds);

struct SheetMeshOptions {
  EliminationOptions elimination;
  // Internal sheets where their conditions hold (build_hex_complex); never worse in the measured cases,
  // valid where the external sheet is flat (a pillowed patch of a face, docs/sheets.md).
  bool internal_sheets = true;
  // Splits along a primal cycle when the elimination is stuck; max_depth = 0 turns them off.
  DecompositionOptions decomposition;
  int smoothing_iterations = 500;  // barycentric sweeps before the optimizer
  bool optimize = true;
  OptimizeOptions optimizer;
  // When hexes stay inverted after the embedding (only with optimize): add a pillow layer under the
  // boundary (mesher/hex_pillow.h), embed again, and keep the result with fewer inverted hexes.
  bool pillow_if_inverted = true;
};

struct SheetMeshReport {
  int quads = 0;
  int chords = 0;                // chords of the input surface
  int eliminations = 0;          // steps
  int eliminations_single = 0;   // steps of one chord
  int eliminations_k_step = 0;   // steps of k >= 2 chords
  int chords_eliminated = 0;     // chords - 3 for a complete scheme without decomposition
  int decompositions = 0;        // splits along a primal cycle (nested ones included)
  int look_ahead_fallbacks = 0;  // surfaces (or parts) where the order was stuck and the look-ahead was not
  int external_sheets = 0;
  int internal_sheets = 0;
  int hexes = 0;
  int interior_vertices = 0;
  EliminationOrder order = EliminationOrder::kGeometric;
  double seconds_elimination = 0.0;
  double seconds_embedding = 0.0;
  OptimizeReport optimize;  // empty phases when optimization is off
  QualitySummary quality;   // of the final mesh (node degrees inside)
  // The pillow rescue (SheetMeshOptions::pillow_if_inverted): hexes it added to the final mesh (0 when it
  // did not run or did not help) and the inverted hexes of the embedding without it.
  int pillow_hexes = 0;
  int inverted_without_pillow = 0;
};

// Steps 1 to 3, with the look-ahead order and then decomposition where the elimination is stuck. The counts
// of eliminations and sheets add up over the parts of a decomposition. With options.optimize, InputError
// first when a quad corner is collinear or reflex (no valid hex mesh has that boundary). Quads that all face
// inward (a negative enclosed volume) are meshed with their corners reversed: the same solid, no inverted
// hexes.
HexMesh mesh_by_cycle_elimination(const QuadSurface& surface, const SheetMeshOptions& options,
                                  SheetMeshReport* report = nullptr);

}  // namespace hexbite
