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
//      edge length, falls below the tolerance, or when a sweep lowers E by less than 1e-5 of it. With
//      OptimizeOptions::reactivate, a node that hardly moved is skipped until a node of its hexes moves;
//   4. optionally (OptimizeOptions::worst_element_threshold), a worst-element pass in two stages. First the
//      nodes of the hexes whose scaled Jacobian or 3 / kappa (both 1 for a cube) is below the threshold,
//      worst hex first, ascend a soft minimum of both measures of the corners that depend on them (the
//      untangler's method on other measures), a step accepted only when the true minimum of those grows,
//      so the mesh's smallest min(scaled Jacobian, 3 / kappa) never falls. Then a few sweeps over every
//      node raise the scaled Jacobian alone, no corner's condition number growing beyond the mesh's
//      largest. Boundary nodes slide, never to a point farther from where the optimization found them
//      than worst_element_reach of an edge or than they already are. Optionally
//      (OptimizeOptions::condition_target), after the first stage a condition stage: the nodes of the hexes
//      whose kappa is above the target ascend a sharp soft minimum of the 3 / kappa of the corners around
//      them, never lowering the smallest of both measures there. Both stages (and the condition stage)
//      repeat worst_element_rounds times;
//   5. optionally (OptimizeOptions::mean_jacobian_sweeps), sweeps raising the mean element scaled Jacobian:
//      each node ascends the sum of soft minima of the corner scaled Jacobians of its hexes, no hex falling
//      below max(the mesh's smallest, mean_jacobian_floor or else worst_element_threshold) or its own
//      value, no condition number beyond the mesh's largest, boundary nodes sliding as in phase 4.
// Cost: one sweep is O(m) for m hexes (each corner is evaluated a few times per node that it depends on);
// the jaw at 2,500 hexes converges in about 70 sweeps (about 55 with reactivate = 0.01); each boundary
// trial costs one closest-point query, O(log t) for t surface triangles, started from the node's current
// closest point. The worst-element pass and the mean stage cost O(m) per sweep at most.
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
  // Nodes that moved less than this (relative to their edge length) in a sweep are skipped until a node of
  // one of their hexes moves more (0 = every movable node in every sweep).
  double reactivate = 0.0;
  // Worst-element pass after a valid optimization: the nodes of hexes whose scaled Jacobian or 3 / kappa
  // is below this threshold locally maximize a soft minimum of both measures of the corners around them
  // (0 = no pass).
  double worst_element_threshold = 0.0;
  int worst_element_sweeps = 20;  // sweeps of that stage
  // The pass never moves a sliding node to a point farther than this fraction of its edge length (or than
  // it already is) from where the optimization found it (optimize_hex_mesh) or the pass did
  // (improve_worst_elements without `home`).
  double worst_element_reach = 0.25;
  // Then sweeps over every node raising the soft minimum of the scaled Jacobian alone, no corner's
  // condition number growing beyond the mesh's largest (needs worst_element_threshold > 0).
  int scaled_jacobian_sweeps = 0;
  // Both stages of the pass run this many times in turn (the second stage's moves give the first room).
  int worst_element_rounds = 1;
  // After stage 1 (each round), the condition stage: the nodes of the hexes whose condition number (cube =
  // 3) is above this, worst hex first, ascend a sharp soft minimum (mu = 400 where stage 1 uses 30) of the
  // 3 / kappa of the corners that depend on them, a step accepted only when the smallest of those grows and
  // the smallest of both measures there does not fall; sliding nodes stay within condition_reach of an edge
  // from home; at most worst_element_sweeps sweeps (0 = no such stage; needs worst_element_threshold).
  // Stage 2 and the mean stage then keep the lower largest kappa as their cap.
  double condition_target = 0.0;
  double condition_reach = 1.2;
  // Last, sweeps over every node raising the sum of the element scaled Jacobians (each hex's smallest
  // corner value, whose mean the quality report gives) of the hexes around it (improve_mean_jacobian;
  // 0 = none).
  int mean_jacobian_sweeps = 0;
  // No hex falls below the smaller of its own value and max(this, the mesh's smallest scaled Jacobian) in
  // the mean stage (negative: worst_element_threshold).
  double mean_jacobian_floor = -1.0;
};

// One row of the per-phase table.
struct PhaseQuality {
  std::string phase;
  QualitySummary quality;
  double seconds = 0.0;  // time spent in this phase
};

struct OptimizeReport {
  std::vector<PhaseQuality> phases;  // "barycentric", "untangled", "final", each always (callers add)
  int untangle_sweeps = 0;           // over all untangling phases
  int iterations = 0;                // optimization sweeps (per-node Newton steps over all movable nodes)
  int rounds = 0;                    // untangle + optimize cycles
  int worst_element_sweeps = 0;      // sweeps of the worst-element pass (both stages)
  int mean_jacobian_sweeps = 0;      // sweeps of improve_mean_jacobian
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
// The worst-element pass (phase 4) on a valid mesh, both stages (and the condition stage with
// options.condition_target), worst_element_rounds times; returns the number of sweeps. Does
// nothing when a hex is inverted or options.worst_element_threshold is not positive.
// Sliding nodes never step farther from `home` (default: where the pass finds them) than
// options.worst_element_reach of an edge or than they already are; optimize_hex_mesh passes the positions on
// entry to the optimization, so that the pass and the tethered optimization together cannot walk a node away
// from a thin tip.
int improve_worst_elements(HexMesh& mesh, const std::vector<char>& movable, const std::vector<char>& sliding,
                           const SurfaceProjector* surface, const OptimizeOptions& options,
                           const std::vector<Vec3>* home = nullptr);
// Phase 5 on a valid mesh (options.mean_jacobian_sweeps sweeps; does nothing when a hex is inverted):
// each movable node in turn ascends the sum, over its hexes, of a soft minimum of each hex's eight corner
// scaled Jacobians, a step accepted only when the sum of their element values grows, no hex falls below the
// smaller of its value and max(mesh's smallest scaled Jacobian, options.mean_jacobian_floor, or
// options.worst_element_threshold where that floor is negative), and no
// corner's condition number grows beyond the mesh's largest, so the mesh's worst values never get worse.
// After the first sweep only the nodes of hexes in which a node moved are visited. Sliding nodes slide
// within options.worst_element_reach of `home` as in improve_worst_elements. Returns the number of sweeps.
int improve_mean_jacobian(HexMesh& mesh, const std::vector<char>& movable, const std::vector<char>& sliding,
                          const SurfaceProjector* surface, const OptimizeOptions& options,
                          const std::vector<Vec3>* home = nullptr);

}  // namespace hexbite
