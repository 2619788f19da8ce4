// Hex meshing of a ball-shaped quad surface by successive chord (dual cycle) elimination, the seed paper's
// combinatorial mesher (section 3; definitions in ../shared/DESIGN.md section 3 and mesher/quad_check.h).
//
// Input: a QuadSurface that check_quad_surface() finds usable (closed, manifold, consistently oriented
// outward, genus 0, even, simple, 3-connected, no self-intersecting chord).
// Algorithm (phase 1: single eliminations with external sheets):
//   1. Elimination. While the surface is not a cube (6 quads), pick a simple chord and collapse its strip:
//      every rung (an edge the chord crosses) shrinks to a point, so every strip quad shrinks to an edge and
//      the two rails of the strip merge. The elimination is feasible when both rails are disjoint simple
//      cycles (the rung endpoints are 2 L distinct vertices for a chord of length L), the strip separates the
//      other quads into exactly two sides, and the collapsed surface is again a closed manifold ball whose
//      graph is simple, planar and 3-connected. The elimination side (the quads that receive hexes) is the
//      smaller side.
//   2. Construction, in reverse order, starting from one hex on the final cube: for an elimination with side
//      A, one hex is placed on each quad of A between the quad as it was before the collapse (outer, on the
//      larger surface) and as it is after it (inner). The A-side rail vertices map onto their rung partners,
//      the other vertices of A get new interior vertices; the new sheet of hexes is bounded by the eliminated
//      chord (an external sheet), whose strip quads become the sheet's side faces.
//   The boundary of the result is therefore exactly the input surface: vertices 0..n-1 are the input's
//   vertices with the same coordinates, every input quad is a boundary face, and only interior vertices
//   (ids >= n) are new.
//   3. Embedding: new vertices start at the position of the vertex they were split from, then barycentric
//      smoothing to convergence and optimize_hex_mesh() with every boundary vertex fixed.
// Ordering strategies: kFewestHexes takes the feasible chord with the smallest elimination side (ties: the
// lower chord number); kLookAhead takes, in the same order, the first feasible chord after whose elimination
// the surface is a cube or still has a feasible chord, so that it does not walk into a dead end one step on.
// Not yet done (phase 2): k-step eliminations of node-disjoint chords, internal sheets, decomposition along a
// primal cycle, the geometric ordering rule. The Elimination record below keeps the sheet as a list of
// (outer quad, inner quad) hexes so that those kinds fit in without changing the construction.
// Failure: when no chord is feasible before the cube, RunError naming the remaining chords.
// Cost: per step, the chords and sides O(F), a feasibility test O(V (V + E)) (3-connectivity dominates);
// kFewestHexes usually tests one candidate per step, kLookAhead up to all candidates of the next step.
// Deterministic: fixed orders, no hashing, single-threaded.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "mesher/hex_mesh.h"
#include "mesher/hex_optimize.h"
#include "mesher/hex_quality.h"

namespace hexbite {

enum class EliminationOrder { kFewestHexes, kLookAhead };

// Parses "fewest-hexes" or "look-ahead"; InputError for anything else.
EliminationOrder parse_elimination_order(const std::string& name);
const char* elimination_order_name(EliminationOrder order);

enum class SheetKind { kExternal };

// One eliminated chord and the sheet of hexes that undoes it.
struct Elimination {
  SheetKind kind = SheetKind::kExternal;
  int chord_length = 0;      // quads in the eliminated strip
  int quads_before = 0;      // surface size before the collapse
  int other_side_quads = 0;  // quads of the side that got no hexes
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
  EliminationOrder order = EliminationOrder::kFewestHexes;
};

// Step 1. Throws InputError when the surface is not usable and RunError when no feasible chord is left.
EliminationScheme eliminate_chords(const QuadSurface& surface, const EliminationOptions& options = {});

// Step 2: the hex complex, with vertex coordinates for 0..input_vertices-1 copied from the surface and the
// interior ones placed at the vertex they were split from (not yet embedded).
HexMesh build_hex_complex(const QuadSurface& surface, const EliminationScheme& scheme);

struct SheetMeshOptions {
  EliminationOptions elimination;
  int smoothing_iterations = 500;  // barycentric sweeps before the optimizer
  bool optimize = true;
  OptimizeOptions optimizer;
};

struct SheetMeshReport {
  int quads = 0;
  int chords = 0;  // chords of the input surface
  int eliminations = 0;
  int external_sheets = 0;
  int hexes = 0;
  int interior_vertices = 0;
  EliminationOrder order = EliminationOrder::kFewestHexes;
  double seconds_elimination = 0.0;
  double seconds_embedding = 0.0;
  OptimizeReport optimize;  // empty phases when optimization is off
  QualitySummary quality;   // of the final mesh (node degrees inside)
};

// Steps 1 to 3.
HexMesh mesh_by_cycle_elimination(const QuadSurface& surface, const SheetMeshOptions& options,
                                  SheetMeshReport* report = nullptr);

}  // namespace hexbite
