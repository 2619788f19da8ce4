#include "mesher/quad_surface_crossings.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include <algorithm>
#include <cstdio>
#include <iterator>

#include "mesher/quad_check.h"

namespace hexbite {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;

// The quad pairs that cross when every quad is split along the diagonal from its corner `first` (0 or 1);
// `ok` is false when CGAL's Surface_mesh could not attach a triangle (a non-manifold or inconsistently
// oriented surface).
std::vector<std::array<int, 2>> crossings_split_at(const QuadSurface& surface, int first, bool& ok) {
  Mesh mesh;
  std::vector<Mesh::Vertex_index> vertex;
  vertex.reserve(surface.vertices.size());
  for (const Vec3& p : surface.vertices) vertex.push_back(mesh.add_vertex(Point(p[0], p[1], p[2])));
  std::vector<int> quad_of_face;
  for (std::size_t q = 0; q < surface.quads.size(); ++q) {
    const std::array<int, 4>& c = surface.quads[q];
    const int a = c[first], b = c[first + 1], d = c[(first + 2) % 4], e = c[(first + 3) % 4];
    for (const std::array<int, 3>& t : {std::array<int, 3>{a, b, d}, std::array<int, 3>{a, d, e}}) {
      if (mesh.add_face(vertex[t[0]], vertex[t[1]], vertex[t[2]]) == Mesh::null_face()) {
        ok = false;
        return {};
      }
      quad_of_face.push_back(static_cast<int>(q));
    }
  }
  std::vector<std::pair<Mesh::Face_index, Mesh::Face_index>> pairs;
  CGAL::Polygon_mesh_processing::self_intersections(mesh, std::back_inserter(pairs));
  std::vector<std::array<int, 2>> quads;
  for (const auto& [f, g] : pairs) {
    if (f == g) continue;  // a degenerate triangle (collinear corners: non_convex_corners_problem's case)
    const int p = quad_of_face[f.idx()], q = quad_of_face[g.idx()];
    quads.push_back({std::min(p, q), std::max(p, q)});
  }
  std::sort(quads.begin(), quads.end());
  quads.erase(std::unique(quads.begin(), quads.end()), quads.end());
  ok = true;
  return quads;
}

}  // namespace

std::vector<std::array<int, 2>> crossing_quads(const QuadSurface& surface) {
  bool ok = false;
  const std::vector<std::array<int, 2>> one = crossings_split_at(surface, 0, ok);
  if (!ok || one.empty()) return {};
  const std::vector<std::array<int, 2>> other = crossings_split_at(surface, 1, ok);
  std::vector<std::array<int, 2>> both;
  std::set_intersection(one.begin(), one.end(), other.begin(), other.end(), std::back_inserter(both));
  return both;
}

std::string crossing_quads_problem(const QuadSurface& surface, const std::vector<std::array<int, 2>>& pairs,
                                   const std::string& subject) {
  if (pairs.empty()) return "";
  const auto [a, b] = pairs.front();
  const Vec3 p = quad_centre(surface, a), r = quad_centre(surface, b);
  char first[256];
  if (a == b)
    std::snprintf(first, sizeof first, "quad %d (centre (%g, %g, %g)) is folded: its two halves cross", a,
                  p[0], p[1], p[2]);
  else
    std::snprintf(first, sizeof first,
                  "quads %d and %d cross each other (centres (%g, %g, %g) and (%g, %g, %g))", a, b, p[0],
                  p[1], p[2], r[0], r[1], r[2]);
  return subject + " crosses itself: " + first +
         (pairs.size() > 1 ? " (" + std::to_string(pairs.size()) + " crossing pairs in all)" : "") +
         "; the hexes on both sides of a crossing would overlap, so no valid hex mesh has this boundary";
}

}  // namespace hexbite
