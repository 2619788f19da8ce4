// From a triangulated mandible to a quad surface for the sheet mesher (seed paper section 2): the macro-
// element template (mesher/mandible_quad_template.h) placed on the surface and refined to a target density.
//
// Input: a closed, outward triangle surface of a mandible in the built-in mandible's frame (+x subject's
// left, +y posterior, +z superior, mm), optionally its landmark file (mesher/landmarks.h), and a target
// number of quads (even; about 1,300 is the paper's density).
// Output: a QuadSurface (counter-clockwise from outside) whose vertices all lie on the input surface, a ball
// with an even number of quads, a simple 3-connected graph and only simple chords, plus a report (macro
// quads, quads, chords, Hausdorff distance to the input, the points used for placement, landmark nodes).
// Algorithm:
//   1. Correspondence. Template reference points and target points with the same names: the landmarks and
//      "<muscle>.insertion" points of the file (the real jaw has 4 landmarks and 18 insertions; the
//      generator writes 11 and 18); without a file, the surface's extreme points along the frame axes
//      (mandible_quad_template.h: extreme_points) against the default mandible's.
//   2. Warp. A regularized thin-plate spline (mesher/thin_plate_spline.h) is fitted to those pairs
//      (landmarks nearly interpolated; insertions, whose definitions differ between sources, and extreme
//      points only guide it). Landmark files say nothing about the processes, so the first warp is
//      refined with points derived from the surface's shape near where it puts them: per side the top of
//      the condyle, the back of the condyle head, the top of the coronoid process and the bottom of the
//      sigmoid notch (whose depth varies most between mandibles), and the incisal top; the second warp,
//      fitted to all pairs, carries the template's macro nodes to the target.
//   3. Refinement keeping chords simple. Every macro chord c gets one subdivision count n_c, so that each
//      edge it crosses is cut into n_c pieces and each macro quad crossed by chords c1, c2 becomes an
//      n_c1 x n_c2 grid; counts agree across shared macro edges by construction, and the refined chords are
//      n_c parallel copies of simple chords, hence simple. n_c = max(1, round(L_c / h)) with L_c the mean
//      length of the warped rungs of c; h is found by bisection so that sum_q n_c1 n_c2 is closest to the
//      target (a documented per-chord rounding in place of the paper's weighted b-matching: on a polycube
//      template the b-value of every macro edge is 1, one chord per edge, and the matching decouples into
//      one rounding per chord). If the sum is odd, the single-chord change that makes it even with the
//      smallest deviation from the target is applied.
//   4. Placement. Fine nodes start at the bilinear interpolation of their macro quad's warped corners and
//      are projected onto the surface. Multi-patches: a node may only land on triangles whose normal agrees
//      with the node's normal in the quad mesh (dot > 0.2) and, once placed, never on a triangle whose
//      normal opposes the one it sat on, which keeps nodes of the thin coronoid and ramus plates on their
//      own side instead of the nearest point on the opposite face. (The paper splits triangles at macro-
//      quad boundaries and keeps each macro quad's triangles as its patch; the normal restriction gives the
//      same "no jumping" guarantee without cutting the input.)
//   5. Landmark nodes. For each named landmark (not the insertions) the nearest quad node is moved to the
//      landmark's closest surface point and kept fixed.
//   6. Relaxation. Sweeps that move each free node tangentially toward the mean of (a) the centroid of its
//      quads' centroids (Laplacian: even quads) and (b) the area centroid of its restricted Voronoi region
//      among the input vertices (Lloyd: tips and ridges keep their nodes), each followed by the restricted
//      projection; nodes move one at a time and a move that folds more quad corners around the node than
//      before (a corner normal against the input normal there) is undone, and a node that still has folded
//      corners around it tries the plain centroid of its quads (on whichever face suits it) instead.
//   7. Untangling. The nodes of the quads still folded (a corner normal against the input normal) take,
//      among positions around them on the surface, the one that raises the smallest corner agreement
//      (cosine of corner normal and input normal) over their quads the most, as long as no centre or edge
//      midpoint of their quads ends farther from the input than 0.2 of an edge and than before (no quad
//      comes to bridge a gap); this never lowers the surface's smallest agreement.
//   8. Feature snapping. The input vertices farther than snap_threshold_mm from the quads (cusp tips,
//      condyle poles, crests that the quads cut off), farthest first, pull a free node of their nearest quad
//      (nearest node first) exactly onto themselves, or failing that 3/4 or 1/2 of the way (restricted
//      projection); the move is kept only when it lowers the local error (the distance of that vertex and
//      of the input vertices nearest to the node's quads to those quads, and of the quads' inner sample
//      points to the input) and keeps the smallest corner scaled Jacobian of the node's quads (sine of the
//      corner angle, signed by the input normal) at least at 0.3 or at what it was; snapped nodes stay
//      fixed. Up to snap_rounds rounds, each re-measuring the distances.
//   9. Fidelity refinement. Where the input is still farther than snap_threshold_mm from the quads (or the
//      quads from it) within fidelity_band_mm of the largest such distance, one ring of quads is added by
//      nested surface pillowing around those points (refine_quads_locally, mesher/quad_local_refinement.h:
//      one level, a radius of 3/4 of the mean edge; existing vertex ids keep their meaning), its nodes
//      relaxed (step 6), untangled (step 7) and snapped (step 8). Points near which a quad folded or the
//      distance did not fall are dropped and the round redone; a round is kept only when it lowers the
//      Hausdorff distance without more folded quads. Up to fidelity_rounds rounds (rings may nest); when
//      they do not bring the quads within snap_threshold_mm, all of them are undone. The
//      ring chords' rungs are reported (MandibleQuadReport::ring_rungs) so that the sheet mesher
//      eliminates them first.
//  10. Fidelity. Vertex distance to the input, quad-to-surface distance sampled on each bilinear quad, and
//      surface-to-quads distance of every input vertex (CGAL AABB trees, mesher/surface_projector.h); folded
//      quads (a corner normal against the surface normal).
// Limitations (measured, docs/mandible_quads.md): at 1,300 quads the Hausdorff distance is 0.99 to 1.0 mm
// on the built-in mandible and 1.0 to 1.5 mm on the real jaw (1 mm is the goal; with its landmarks the
// real jaw's farthest points are a molar crown and the condyle tops, where no ring helps), and at 3,000
// quads a few quads still fold (3) and the distance is 3.3 to 6.6 mm (gaps on the lingual side of the body
// that the snapping does not close). Failure: InputError when a landmark file lacks the points the template
// needs (naming the file and the missing names), when the surface is not mandible-like (its Hausdorff
// distance to the placed template exceeds 10 mm, naming where), or when the target is out of range. Cost: O(T
// log T) for T input triangles plus O((Q + V) sweeps) for Q quads and V input vertices (the Lloyd
// assignment; in step 9's relaxation only for the input vertices that may fall to a moved node), plus
// about a thousand closest-point queries per node of a folded quad and untangling sweep, plus per snapping
// round O(V log Q + Q) closest-point queries (after the first round only for the vertices not within
// snap_threshold_mm of their previous quad and those near the quads the far vertices may pull) and local
// checks of the far vertices, and per fidelity pass one relaxation, untangling and snapping more; 1 to 3 s
// for 42,000 triangles and 1,300 quads, 7 to 9 s for 668,000 (the real jaw split 1:16; 64 s before these
// shortcuts), measured while other jobs shared the 2-core machine. The per-input-vertex loops run in
// MandibleQuadOptions::threads threads.
// Deterministic: fixed orders; the shortcuts skip only work whose result is not used or cannot change, and
// the threads' answers are combined in vertex order, so the quads are the same bit for bit with any number
// of threads and as without the shortcuts.
#pragma once

#include <array>
#include <string>
#include <utility>
#include <vector>

#include "mesher/hex_mesh.h"
#include "mesher/input_terms.h"
#include "mesher/landmarks.h"

namespace hexbite {

struct MandibleQuadOptions {
  int target_quads = 1300;  // 24 to 200,000
  int relax_sweeps = 40;
  int unfold_sweeps = 30;  // step 7
  // Thin-plate spline regularization per kind of point: landmarks are trusted, muscle insertions (whose
  // definitions differ between sources) and extreme points only guide.
  double landmark_smoothing_mm = 0.5;
  double insertion_smoothing_mm = 50.0;
  double extreme_smoothing_mm = 20.0;
  int snap_rounds = 8;             // step 8; 0 turns feature snapping off
  double snap_threshold_mm = 1.0;  // input vertices farther than this from the quads pull a node
  // Step 9, fidelity refinement (measured on the built-in mandible and the real jaw, docs/mandible_quads.md):
  int fidelity_rounds = 6;              // 0 turns it off
  double fidelity_band_mm = 0.1;        // far points within this of the Hausdorff distance get a ring
  double fidelity_join_edges = 0.5;     // at most one centre within this many mean edges
  double fidelity_radius_edges = 0.75;  // patch radius in mean edges
  int fidelity_relax_sweeps = 20;       // step 6 on the moved and new nodes
  int fidelity_passes = 3;              // tries per round, each without the centres that did not help
  double max_hausdorff_mm = 10.0;       // above this the surface is not taken for a mandible
  // Threads of the per-input-vertex loops (1 to 8; default 2, this machine's cores): each vertex's query
  // is answered on its own and the answers are combined in vertex order, so the quads do not depend on it.
  int threads = 2;
  InputTerms terms;  // how messages name the user's choices
};

struct MandibleQuadReport {
  int macro_quads = 0;
  int quads = 0;
  int chords = 0;
  int max_chord_length = 0;
  std::string placement;                    // "landmarks" or "extreme points"
  std::vector<std::string> matched_points;  // names used for the warp
  double warp_residual_mm = 0;              // largest |warp(reference) - target| over the matched points
  // Landmark nodes: name and distance from the landmark to the quad node placed for it (the landmark's
  // closest surface point).
  std::vector<std::pair<std::string, double>> landmark_nodes;
  std::vector<int> landmark_vertices;  // the quad vertex of each landmark node, in the same order
  double max_vertex_distance_mm = 0;   // quad vertices to the input surface
  double quads_to_surface_mm = 0;      // sampled bilinear quads to the input surface
  double surface_to_quads_mm = 0;      // input vertices to the quad surface
  double hausdorff_mm = 0;             // max of the two above
  Vec3 worst_quad_point{};             // where the quads are farthest from the surface
  Vec3 worst_surface_point{};          // the input vertex farthest from the quads
  double mean_edge_mm = 0;
  // Quads with a corner whose normal (cross product of its two edges) points against the input surface's
  // normal there: folded or twisted quads, which no valid hex mesh can have as boundary faces.
  int folded_quads = 0;
  // Step 9: rounds kept, quads added, and the rungs of the ring chords added (latest round first), which
  // the sheet mesher eliminates first (EliminationOptions::first_rungs) so that its elimination stays that
  // of the surface before step 9.
  int fidelity_rounds = 0;
  int fidelity_undone_rounds = 0;  // rounds undone because they did not reach snap_threshold_mm
  double fidelity_goal_mm = 0;     // that goal (MandibleQuadOptions::snap_threshold_mm)
  int fidelity_quads_added = 0;
  std::vector<std::array<int, 2>> ring_rungs;
  double seconds = 0;
};

// `landmarks` may be null (then extreme points place the template); `landmark_file` names it in messages.
QuadSurface quad_surface_from_mandible(const TriSurface& surface, const Landmarks* landmarks,
                                       const std::string& landmark_file, const MandibleQuadOptions& options,
                                       MandibleQuadReport* report = nullptr);

// The number of boundary quads used for a target number of hexes: 1,300 quads for 2,500 hexes (the
// paper's density), scaling with the 2/3 power, rounded to an even number.
int quads_for_target_hexes(long target_hexes);

// Unit area-weighted vertex normals of a quad surface (each quad split along both diagonals), as the
// placement uses them; mesher/quad_local_refinement.cc takes its fold reference from them.
std::vector<Vec3> quad_vertex_normals(const QuadSurface& quads);

}  // namespace hexbite
