// Cleanup of an input triangulation as in the seed paper: iterative edge contractions (and flips
// where a contraction cannot help) remove triangles with small angles and reduce the size, while
// the Hausdorff distance to the input stays below a bound. Uses CGAL's Euler operations
// (collapse_edge with the link condition, flip_edge) and an AABB tree of the input; see
// docs/cleanup.md for the algorithm and the measured results.
#pragma once

#include <string>
#include <vector>

#include "mesher/tri_surface.h"

namespace hexbite {

struct CleanOptions {
  double min_angle_deg = 5.0;        // triangles with a smaller angle are removed; 0..30
  std::size_t target_triangles = 0;  // 0: no size reduction beyond what the angle rule needs
  double max_deviation_mm = 0.1;     // bound on the Hausdorff distance to the input; > 0
};

// A triangle of the result that is still below the angle threshold.
struct UnfixedTriangle {
  std::size_t index = 0;  // index into the result's triangles
  double min_angle_deg = 0;
  Vec3 centroid{};
};

struct CleanReport {
  std::size_t triangles_before = 0, triangles_after = 0;
  std::size_t vertices_before = 0, vertices_after = 0;
  double min_angle_before_deg = 0, min_angle_after_deg = 0;
  std::size_t bad_before = 0;  // triangles below the threshold before
  std::size_t bad_after = 0;   // triangles below the threshold after (= unfixed.size())
  std::size_t collapses = 0, flips = 0;
  double hausdorff_mm = 0;  // measured symmetric Hausdorff distance to the input
  double max_deviation_mm = 0;
  double volume_before_mm3 = 0, volume_after_mm3 = 0;
  std::size_t target_triangles = 0;  // as requested (0: none)
  bool target_reached = true;        // false when target_triangles could not be reached
  std::string target_note;           // why not, in one sentence (empty when reached or not asked)
  double seconds = 0;
  // Triangles still below the threshold, each as "triangle 123 (min angle 3.2 deg) at (x, y, z)".
  std::vector<std::string> unfixed;
  std::vector<UnfixedTriangle> unfixed_triangles;  // the same, as data
};

// Throws InputError with a message naming the option when an option is out of range:
// min_angle_deg outside [0, 30], max_deviation_mm not positive and finite, or target_triangles
// in 1..3 (a closed surface has at least 4 triangles).
void validate_clean_options(const CleanOptions& options);

// `surface` must be closed, manifold and outward (check_surface). Returns the cleaned surface,
// still closed, manifold and outward with the same genus. Deterministic: the same input and options
// give the same output. Cost: about O(m log m) for m triangles (a few hundred ms for 40,000).
TriSurface clean_surface(const TriSurface& surface, const CleanOptions& options, CleanReport* report);

}  // namespace hexbite
