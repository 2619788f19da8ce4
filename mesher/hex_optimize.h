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
//      node, accepted only where the true minimum corner Jacobian grows; when a tangle resists every widening
//      of the region, the sliding nodes of its inverted hexes may leave the surface by up to a quarter edge;
//   3. optimization of E = sum over all hex corners of kappa(A)^2 (kappa = |A|_F |A^-1|_F) by sweeps of
//      per-node Newton steps: for each movable node in turn, the Hessian of its local terms (by finite
//      differences of the analytic gradient), a step capped at half an edge and backtracking until the local
//      objective decreases. The local objective is +infinity on any non-positive corner Jacobian of the
//      node's hexes, so every accepted step keeps every hex valid. Boundary nodes step in their tangent
//      plane and are projected back onto the surface at every trial, tethered to where they started so that
//      they do not abandon thin tips. Untangling and optimization repeat while hexes stay inverted.
//      Optimization stops when the largest node movement of a sweep, relative to the node's mean incident
//      edge length, falls below the tolerance, or when a sweep lowers E by less than 1e-5 of it.
// Cost: one sweep is O(m) for m hexes (each corner is evaluated a few times per node that it depends on);
// the jaw at 2,500 hexes converges in about 70 sweeps; each boundary trial costs one closest-point query,
// O(log t) for t surface triangles.
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
  int max_iterations = 200;         // sweeps of per-node Newton steps, over all repeats
  double tolerance = 1e-3;          // stop when max |node move| / local edge length < tolerance
  bool slide_boundary = true;       // boundary nodes slide on the surface (needs a projector)
  // Sliding nodes pay ((|x - x0| / r)^2)^2 for leaving their entry position x0, with r this fraction of the
  // local edge length, so that they cannot abandon thin tips and ridges of the surface (0 = no tether).
  double boundary_tether = 0.5;
  int max_repeats = 5;  // untangle + optimize cycles while hexes stay inverted
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
  int iterations = 0;                // optimization sweeps (per-node Newton steps over all movable nodes)
  int rounds = 0;                    // untangle + optimize cycles
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
// Returns the number of sweeps. Hexes that are inverted on entry are left out of the objective, and their
// nodes do not move. `rounds` (when not null) is set to 1.
int optimize_condition(HexMesh& mesh, const std::vector<char>& movable, const std::vector<char>& sliding,
                       const SurfaceProjector* surface, const OptimizeOptions& options,
                       int* rounds = nullptr);

}  // namespace hexbite
