// Embedding and optimization of a hex mesh (seed paper section 4.4, with a faster optimizer).
//
// Input: a HexMesh whose boundary nodes already lie on (or near) the domain's surface, optionally a
// SurfaceProjector of that surface (lets boundary nodes slide on it and moves nodes that left the domain
// back inside) and a per-vertex mask of nodes that must not move.
// Output: the mesh with moved nodes, and a report with one quality row per phase (after barycentric
// smoothing, after the first untangling, final) like the paper's Table 1.
// Phases:
//   1. barycentric (Laplacian) smoothing of the interior nodes; interior nodes that left the domain are put
//      back inside;
//   2. untangling: node by node, a damped Newton ascent on a soft minimum of the corner Jacobians around the
//      node, accepted only where the true minimum corner Jacobian grows;
//   3. optimization of E = sum over all hex corners of kappa(A)^2 (kappa = |A|_F |A^-1|_F) with L-BFGS and
//      an Armijo backtracking line search. E is +infinity on any non-positive corner Jacobian, so every
//      accepted step keeps every corner of every hex valid (the validity test covers all hexes around every
//      moved node). Boundary nodes move in their tangent plane and are projected back onto the surface after
//      each round; hexes made invalid by the projection are returned to the last valid state. Untangling
//      and optimization repeat while hexes stay inverted. Optimization stops when the largest node movement
//      of an iteration, relative to the node's mean incident edge length, falls below the tolerance.
// Cost: one objective evaluation is O(m) for m hexes (8 corners each); the optimizer runs a few hundred
// evaluations; each boundary projection is O(b log t) for b boundary nodes and t surface triangles.
// Deterministic: single-threaded, fixed node and hex orders, no hashing.
#pragma once

#include <string>
#include <vector>

#include "mesher/hex_mesh.h"
#include "mesher/hex_quality.h"

namespace hexbite {

class SurfaceProjector;

struct OptimizeOptions {
  int barycentric_iterations = 10;  // Jacobi sweeps of Laplacian smoothing (0 skips the phase)
  int max_untangle_sweeps = 60;     // sweeps over the nodes of inverted hexes, per untangling phase
  int max_iterations = 1500;        // L-BFGS iterations over all rounds and repeats
  int iterations_per_round = 40;    // iterations between two projections of the sliding boundary nodes
  int lbfgs_memory = 8;             // correction pairs kept by L-BFGS
  double tolerance = 1e-3;          // stop when max |node move| / local edge length < tolerance
  bool slide_boundary = true;       // boundary nodes slide on the surface (needs a projector)
  int max_repeats = 5;              // untangle + optimize cycles while hexes stay inverted
};

// One row of the per-phase table.
struct PhaseQuality {
  std::string phase;
  QualitySummary quality;
  double seconds = 0.0;  // time spent in this phase
};

struct OptimizeReport {
  std::vector<PhaseQuality> phases;  // "barycentric", "untangled", "final" (the middle one only if needed)
  int untangle_sweeps = 0;           // over all untangling phases
  int iterations = 0;                // L-BFGS iterations
  int rounds = 0;                    // boundary projection rounds
  double energy_before = 0.0;        // sum of squared corner condition numbers, valid hexes only
  double energy_after = 0.0;
  int inverted = 0;  // inverted hexes at the end
};

// Sum over every corner of every hex of kappa(A)^2, and its gradient with respect to the vertex positions
// (when `gradient` is not null; resized to the vertex count). Returns +infinity when any corner Jacobian is
// <= 0 (the gradient is then not meaningful).
double condition_energy(const HexMesh& mesh, std::vector<Vec3>* gradient);

// The whole embedding pipeline. `fixed` may be empty (nothing fixed) or hold one flag per vertex.
// `surface` may be null: then boundary nodes stay where they are and outside nodes are not detected.
OptimizeReport optimize_hex_mesh(HexMesh& mesh, const SurfaceProjector* surface,
                                 const std::vector<char>& fixed, const OptimizeOptions& options = {});

// The individual phases, for callers that compose them differently. `movable[v]` != 0 for nodes that may
// move; `sliding[v]` != 0 for movable nodes that must stay on the surface (needs `surface`).
void barycentric_smoothing(HexMesh& mesh, const std::vector<char>& movable, int iterations);
int move_inside(HexMesh& mesh, const SurfaceProjector& surface, const std::vector<char>& movable);
// Returns the number of sweeps used; the mesh is untangled when no hex is inverted afterwards.
int untangle(HexMesh& mesh, const std::vector<char>& movable, const std::vector<char>& sliding,
             const SurfaceProjector* surface, int max_sweeps);
// Returns the number of L-BFGS iterations. Hexes that are inverted on entry are left out of the objective,
// and their nodes do not move.
int optimize_condition(HexMesh& mesh, const std::vector<char>& movable, const std::vector<char>& sliding,
                       const SurfaceProjector* surface, const OptimizeOptions& options,
                       int* rounds = nullptr);

}  // namespace hexbite
