// Checks and safe repairs of a triangle surface before it is meshed (CGAL Polygon_mesh_processing).
#pragma once

#include <string>
#include <vector>

#include "mesher/tri_surface.h"

namespace hexbite {

struct SurfaceReport {
  std::string file;
  std::size_t triangles = 0, vertices = 0, components = 0;
  std::size_t open_edges = 0, non_manifold_edges = 0, non_manifold_vertices = 0;
  std::size_t inconsistent_edges = 0;  // shared edges traversed in the same direction by both triangles
  std::size_t self_intersections = 0;  // pairs of intersecting triangles
  std::size_t degenerate_triangles = 0;
  bool closed = false, manifold = false, consistently_oriented = false, outward = false;
  long euler_characteristic = 0;
  long genus = -1;  // -1 when undefined (open or non-manifold)
  Vec3 bbox_min{}, bbox_max{};
  double volume_mm3 = 0.0;                       // enclosed volume, when volume_defined()
  double min_angle_deg = 0.0;                    // smallest triangle angle
  std::vector<std::size_t> min_angle_histogram;  // triangles per 5-degree bin of their minimum angle, 0..60
  std::vector<std::string> repairs;              // what was repaired, one sentence each
  std::vector<std::string> problems;  // what is wrong and where (index, coordinates), one sentence each
  bool usable() const { return problems.empty(); }
  // Closed, manifold and oriented (after a repair flip) so that it encloses a volume.
  bool volume_defined() const { return outward; }
};

// Applies the safe repairs (merge duplicate vertices, drop unreferenced ones, drop repeated triangles of the
// same orientation, flip a consistently
// inward surface outward) to `surface` in place and reports everything DESIGN/issue 2 asks for.
SurfaceReport check_surface(TriSurface& surface, const std::string& file_name = "");

// Reads, repairs and checks; throws InputError with the report's problems when the surface cannot
// bound a solid (open, non-manifold, inconsistent, self-intersecting, degenerate).
TriSurface load_closed_surface(const std::string& path, double scale_to_mm, SurfaceReport* report = nullptr);

}  // namespace hexbite
