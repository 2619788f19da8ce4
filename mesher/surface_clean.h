// Cleanup of an input triangulation as in the seed paper: iterative edge contractions (and flips
// where a contraction cannot help) remove triangles with small angles and reduce the size, while
// the Hausdorff distance to the input stays below a bound. Uses CGAL's edge-collapse machinery.
#pragma once

#include <string>
#include <vector>

#include "mesher/tri_surface.h"

namespace hexbite {

struct CleanOptions {
  double min_angle_deg = 5.0;       // triangles with a smaller angle are removed
  std::size_t target_triangles = 0;  // 0: no size reduction beyond what the angle rule needs
  double max_deviation_mm = 0.1;    // bound on the Hausdorff distance to the input
};

struct CleanReport {
  std::size_t triangles_before = 0, triangles_after = 0;
  std::size_t vertices_before = 0, vertices_after = 0;
  double min_angle_before_deg = 0, min_angle_after_deg = 0;
  std::size_t bad_before = 0;      // triangles below the threshold before
  std::size_t collapses = 0, flips = 0;
  double hausdorff_mm = 0;         // measured symmetric Hausdorff distance to the input
  double seconds = 0;
  // Triangles still below the threshold, each as "triangle 123 (min angle 3.2 deg) at (x, y, z)".
  std::vector<std::string> unfixed;
};

// `surface` must be closed, manifold and outward (check_surface). Returns the cleaned surface,
// still closed, manifold and outward with the same genus.
TriSurface clean_surface(const TriSurface& surface, const CleanOptions& options, CleanReport* report);

}  // namespace hexbite
