// Checks and safe repairs of a triangle surface.
//
// The work happens in two stages. The first stage runs on the polygon soup itself, because a soup
// may be anything (open, non-manifold, inconsistently oriented) and CGAL::Surface_mesh cannot even
// hold such input: duplicate vertices are merged, unused ones dropped, and a sorted list of
// undirected edges locates open, non-manifold and inconsistently oriented edges, each with its
// triangles. Only once the soup is combinatorially a manifold with a consistent orientation is it
// turned into a CGAL::Surface_mesh for the second stage, the geometric checks of CGAL's
// Polygon_mesh_processing: self-intersections, connected components, orientation and volume.
//
// Indices in messages are 0-based. Triangles keep the order of the file (after fanning polygons);
// vertex indices are those after duplicate merging, so every location also carries coordinates.
#include "mesher/surface_check.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/property_map.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <numeric>
#include <sstream>

#include "common/error.h"
#include "mesher/surface_io.h"
#include "mesher/union_find.h"

namespace hexbite {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;
namespace PMP = CGAL::Polygon_mesh_processing;

// Each problem lists this many locations, then how many more there are.
constexpr std::size_t kShownLocations = 5;
constexpr double kPi = 3.14159265358979323846;

std::string fmt(const Vec3& p) {
  std::ostringstream s;
  s.precision(6);
  s << '(' << p[0] << ", " << p[1] << ", " << p[2] << ')';
  return s.str();
}

std::string plural(std::size_t n, const std::string& one, const std::string& many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

// Builds "N things (explanation), e.g. loc; loc; ... and K more; advice".
std::string problem(std::size_t count, const std::string& what, const std::vector<std::string>& locations,
                    const std::string& advice) {
  if (locations.empty()) return what + ". " + advice;
  std::string s = what + ", e.g. ";
  for (std::size_t i = 0; i < locations.size(); ++i) s += (i ? "; " : "") + locations[i];
  if (count > locations.size()) s += "; and " + std::to_string(count - locations.size()) + " more";
  return s + ". " + advice;
}

// Merges vertices with exactly equal coordinates onto the first of them in file order (what CGAL's
// merge_duplicate_points_in_polygon_soup does, but keeping the file's vertex order, which makes
// the result and the messages predictable). Returns the number of vertices merged away.
std::size_t merge_duplicate_vertices(TriSurface& s) {
  const std::size_t n = s.vertices.size();
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return s.vertices[a] != s.vertices[b] ? s.vertices[a] < s.vertices[b] : a < b;
  });
  std::vector<int> representative(n);
  std::size_t merged = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const bool same = i > 0 && s.vertices[order[i]] == s.vertices[order[i - 1]];
    representative[order[i]] = same ? representative[order[i - 1]] : static_cast<int>(order[i]);
    merged += same;
  }
  for (auto& t : s.triangles)
    for (int& v : t) v = representative[v];
  return merged;
}

// Removes vertices no triangle uses (including those just merged away), keeping the order of the rest.
std::size_t drop_unreferenced_vertices(TriSurface& s) {
  std::vector<int> new_index(s.vertices.size(), -1);
  for (const auto& t : s.triangles)
    for (int v : t) new_index[v] = 0;
  std::size_t kept = 0;
  for (std::size_t i = 0; i < s.vertices.size(); ++i)
    if (new_index[i] == 0) {
      new_index[i] = static_cast<int>(kept);
      s.vertices[kept++] = s.vertices[i];
    }
  const std::size_t dropped = s.vertices.size() - kept;
  s.vertices.resize(kept);
  for (auto& t : s.triangles)
    for (int& v : t) v = new_index[v];
  return dropped;
}

// Removes triangles that repeat an earlier one with the same orientation (the same three vertices in the
// same cyclic order), a common artefact of STL exports that makes each of its edges non-manifold; keeps the
// order of the rest. A copy in the opposite orientation is no duplicate (it is reported as non-manifold or
// inconsistent). Returns the first removed triangle's index in the input (or -1) through `first`.
std::size_t drop_duplicate_triangles(TriSurface& s, long* first) {
  std::vector<std::array<int, 4>> keys;  // the rotation starting at the smallest vertex, and the index
  keys.reserve(s.triangles.size());
  for (std::size_t t = 0; t < s.triangles.size(); ++t) {
    const auto& tri = s.triangles[t];
    const int r = tri[0] <= std::min(tri[1], tri[2]) ? 0 : tri[1] <= tri[2] ? 1 : 2;
    keys.push_back({tri[r], tri[(r + 1) % 3], tri[(r + 2) % 3], static_cast<int>(t)});
  }
  std::sort(keys.begin(), keys.end());
  std::vector<char> drop(s.triangles.size(), 0);
  for (std::size_t i = 1; i < keys.size(); ++i)
    if (keys[i][0] == keys[i - 1][0] && keys[i][1] == keys[i - 1][1] && keys[i][2] == keys[i - 1][2])
      drop[static_cast<std::size_t>(keys[i][3])] = 1;  // the later one of the sorted pair: a larger index
  *first = -1;
  std::size_t kept = 0;
  for (std::size_t t = 0; t < s.triangles.size(); ++t) {
    if (drop[t]) {
      if (*first < 0) *first = static_cast<long>(t);
      continue;
    }
    s.triangles[kept++] = s.triangles[t];
  }
  const std::size_t dropped = s.triangles.size() - kept;
  s.triangles.resize(kept);
  return dropped;
}

bool has_repeated_corner(const std::array<int, 3>& t) {
  return t[0] == t[1] || t[1] == t[2] || t[0] == t[2];
}

double triangle_min_angle_deg(const Vec3& a, const Vec3& b, const Vec3& c) {
  // atan2(|u x v|, u . v) is accurate for small and large angles alike, unlike acos.
  auto angle = [](const Vec3& p, const Vec3& q, const Vec3& r) {
    const Vec3 u{q[0] - p[0], q[1] - p[1], q[2] - p[2]}, v{r[0] - p[0], r[1] - p[1], r[2] - p[2]};
    const Vec3 w{u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    const double cross = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    return std::atan2(cross, u[0] * v[0] + u[1] * v[1] + u[2] * v[2]);
  };
  const double m = std::min({angle(a, b, c), angle(b, c, a), angle(c, a, b)});
  return m * 180.0 / kPi;
}

// One use of an undirected edge {lo, hi} by a triangle; `forward` when the triangle runs lo -> hi.
struct EdgeUse {
  std::uint64_t key;
  int triangle;
  bool forward;
};

// Everything the soup stage finds about the edges and vertices.
struct SoupTopology {
  std::size_t edges = 0;
  std::vector<std::size_t> open_uses;                            // index into `uses` of each open edge
  std::vector<std::pair<std::size_t, std::size_t>> nonmanifold;  // [first, last) ranges of `uses`
  std::vector<std::pair<int, int>> inconsistent;                 // triangle pairs
  std::vector<std::uint64_t> inconsistent_keys;
  std::vector<int> nonmanifold_vertices;
  std::vector<EdgeUse> uses;
};

int edge_lo(std::uint64_t key) {
  return static_cast<int>(key >> 32);
}
int edge_hi(std::uint64_t key) {
  return static_cast<int>(key & 0xffffffffu);
}

SoupTopology analyse_edges(const TriSurface& s, const std::vector<char>& repeated) {
  SoupTopology topo;
  const std::size_t m = s.triangles.size();
  topo.uses.reserve(3 * m);
  for (std::size_t t = 0; t < m; ++t) {
    if (repeated[t]) continue;  // reported as degenerate; its "edges" are not edges of a surface
    for (int k = 0; k < 3; ++k) {
      const int a = s.triangles[t][k], b = s.triangles[t][(k + 1) % 3];
      const auto lo = static_cast<std::uint64_t>(std::min(a, b)),
                 hi = static_cast<std::uint64_t>(std::max(a, b));
      topo.uses.push_back({lo << 32 | hi, static_cast<int>(t), a < b});
    }
  }
  std::sort(topo.uses.begin(), topo.uses.end(), [](const EdgeUse& x, const EdgeUse& y) {
    return x.key != y.key ? x.key < y.key : x.triangle < y.triangle;
  });

  // Corners (triangle, vertex) joined across manifold edges: a vertex whose corners fall into more
  // than one group has several separate fans of triangles around it, i.e. it is non-manifold.
  UnionFind corners(3 * m);
  auto corner = [&](int t, int v) {
    const auto& tri = s.triangles[t];
    return 3 * std::size_t(t) + (tri[0] == v ? 0 : tri[1] == v ? 1 : 2);
  };
  std::vector<char> on_nonmanifold_edge(s.vertices.size(), 0);
  for (std::size_t i = 0; i < topo.uses.size();) {
    std::size_t j = i;
    while (j < topo.uses.size() && topo.uses[j].key == topo.uses[i].key) ++j;
    const std::uint64_t key = topo.uses[i].key;
    ++topo.edges;
    if (j - i == 1) {
      topo.open_uses.push_back(i);
    } else if (j - i > 2) {
      topo.nonmanifold.emplace_back(i, j);
      on_nonmanifold_edge[edge_lo(key)] = on_nonmanifold_edge[edge_hi(key)] = 1;
    } else if (topo.uses[i].forward == topo.uses[i + 1].forward) {
      topo.inconsistent.emplace_back(topo.uses[i].triangle, topo.uses[i + 1].triangle);
      topo.inconsistent_keys.push_back(key);
    } else {
      const int t0 = topo.uses[i].triangle, t1 = topo.uses[i + 1].triangle;
      corners.unite(corner(t0, edge_lo(key)), corner(t1, edge_lo(key)));
      corners.unite(corner(t0, edge_hi(key)), corner(t1, edge_hi(key)));
    }
    i = j;
  }

  // Inconsistent edges also join the fans: the surface is still a manifold there, only misoriented.
  for (std::size_t e = 0; e < topo.inconsistent.size(); ++e) {
    const auto [t0, t1] = topo.inconsistent[e];
    const std::uint64_t key = topo.inconsistent_keys[e];
    corners.unite(corner(t0, edge_lo(key)), corner(t1, edge_lo(key)));
    corners.unite(corner(t0, edge_hi(key)), corner(t1, edge_hi(key)));
  }
  std::vector<std::size_t> first_fan(s.vertices.size(), SIZE_MAX);
  std::vector<char> pinched(s.vertices.size(), 0);
  for (std::size_t t = 0; t < m; ++t) {
    if (repeated[t]) continue;
    for (int k = 0; k < 3; ++k) {
      const int v = s.triangles[t][k];
      const std::size_t fan = corners.find(3 * t + k);
      if (first_fan[v] == SIZE_MAX)
        first_fan[v] = fan;
      else if (first_fan[v] != fan)
        pinched[v] = 1;
    }
  }
  // Vertices on non-manifold edges are covered by those edges' messages.
  for (std::size_t v = 0; v < s.vertices.size(); ++v)
    if (pinched[v] && !on_nonmanifold_edge[v]) topo.nonmanifold_vertices.push_back(static_cast<int>(v));
  return topo;
}

std::string edge_text(const TriSurface& s, std::uint64_t key) {
  const int a = edge_lo(key), b = edge_hi(key);
  return "edge " + std::to_string(a) + "-" + std::to_string(b) + " from " + fmt(s.vertices[a]) + " to " +
         fmt(s.vertices[b]);
}

Vec3 centroid(const TriSurface& s, int t) {
  const auto& tri = s.triangles[t];
  Vec3 c{};
  for (int v : tri)
    for (int k = 0; k < 3; ++k) c[k] += s.vertices[v][k] / 3.0;
  return c;
}

// Builds the Surface_mesh with vertex i and face t of the soup as vertex i and face t of the mesh.
// Returns the first triangle CGAL refuses (-1 when all were accepted).
long build_mesh(const TriSurface& s, Mesh& mesh) {
  mesh.reserve(static_cast<Mesh::size_type>(s.vertices.size()),
               static_cast<Mesh::size_type>(3 * s.triangles.size() / 2),
               static_cast<Mesh::size_type>(s.triangles.size()));
  for (const Vec3& p : s.vertices) mesh.add_vertex(Point(p[0], p[1], p[2]));
  for (std::size_t t = 0; t < s.triangles.size(); ++t) {
    const auto& tri = s.triangles[t];
    if (mesh.add_face(Mesh::Vertex_index(tri[0]), Mesh::Vertex_index(tri[1]), Mesh::Vertex_index(tri[2])) ==
        Mesh::null_face())
      return static_cast<long>(t);
  }
  return -1;
}

// Orientation of a closed mesh: for a single component CGAL's test at the extreme vertex suffices.
// Several components must also be nested consistently (a cavity faces inward), which
// does_bound_a_volume decides when the surface does not intersect itself; it also accepts a surface
// that is inside out as a whole (it then bounds the unbounded outside), so the sign of the volume
// tells the two apart.
bool is_outward(const Mesh& mesh, std::size_t components, bool self_intersecting) {
  if (components == 1) return PMP::is_outward_oriented(mesh);
  if (!self_intersecting && !PMP::does_bound_a_volume(mesh)) return false;
  return PMP::volume(mesh) > 0;
}

// Names the components of a closed surface without self-intersections that no single flip orients: each
// component should face outward at an even nesting depth (an outer shell) and inward at an odd one (a
// cavity). Reversing either the components against that rule or all the others (the global flip then
// repairs the rest) fixes the surface, so the smaller group is named, each with where it is.
template <class ComponentMap>
std::string misoriented_components(const TriSurface& s, const Mesh& mesh, ComponentMap component,
                                   std::size_t components) {
  std::vector<std::size_t> nesting;
  std::vector<bool> outward;
  // Only the nesting and orientation of each component are needed, not the volume each face bounds.
  CGAL::Constant_property_map<Mesh::Face_index, std::size_t> volume(0);
  PMP::volume_connected_components(mesh, volume,
                                   CGAL::parameters::face_connected_component_map(component)
                                       .nesting_levels(std::ref(nesting))
                                       .is_cc_outward_oriented(std::ref(outward)));
  std::vector<std::size_t> against, along;
  for (std::size_t c = 0; c < components; ++c)
    (outward[c] == (nesting[c] % 2 == 0) ? along : against).push_back(c);
  const std::vector<std::size_t>& named = against.size() <= along.size() ? against : along;

  std::vector<std::size_t> triangles(components, 0), first(components, SIZE_MAX);
  std::vector<Vec3> lo(components, Vec3{HUGE_VAL, HUGE_VAL, HUGE_VAL}),
      hi(components, Vec3{-HUGE_VAL, -HUGE_VAL, -HUGE_VAL});
  for (Mesh::Face_index f : mesh.faces()) {
    const std::size_t c = component[f], t = f.idx();  // face t of the mesh is triangle t of the soup
    ++triangles[c];
    first[c] = std::min(first[c], t);
    for (int v : s.triangles[t])
      for (int k = 0; k < 3; ++k) {
        lo[c][k] = std::min(lo[c][k], s.vertices[v][k]);
        hi[c][k] = std::max(hi[c][k], s.vertices[v][k]);
      }
  }
  std::vector<std::string> where;
  for (std::size_t i = 0; i < std::min(kShownLocations, named.size()); ++i) {
    const std::size_t c = named[i];
    where.push_back("component " + std::to_string(c) + " of " +
                    plural(triangles[c], "triangle", "triangles") + " (the first is triangle " +
                    std::to_string(first[c]) + ") from " + fmt(lo[c]) + " to " + fmt(hi[c]) + ", " +
                    (nesting[c] % 2 == 0 ? "an outer shell" : "a cavity") + " facing " +
                    (outward[c] ? "outward" : "inward"));
  }
  return problem(named.size(),
                 "the closed components are oriented inconsistently with each other and no single flip makes "
                 "the surface bound a volume: " +
                     plural(named.size(), "component of ", "components of ") + std::to_string(components) +
                     (named.size() == 1 ? " faces" : " face") + " against the others",
                 where,
                 "Reverse the triangles of the components named (every outer shell must face outward and "
                 "every cavity inward).");
}

}  // namespace

SurfaceReport check_surface(TriSurface& surface, const std::string& file_name) {
  SurfaceReport r;
  r.file = file_name;
  TriSurface& s = surface;
  for (std::size_t t = 0; t < s.triangles.size(); ++t)
    for (int v : s.triangles[t])
      if (v < 0 || static_cast<std::size_t>(v) >= s.vertices.size())
        throw InputError("surface '" + file_name + "': triangle " + std::to_string(t) + " refers to vertex " +
                         std::to_string(v) + ", out of range (there are " +
                         std::to_string(s.vertices.size()) + " vertices)");

  // --- Safe repairs on the soup: duplicates and unused vertices.
  const std::size_t vertices_in = s.vertices.size();
  const std::size_t merged = merge_duplicate_vertices(s);
  if (merged)
    r.repairs.push_back("merged " + plural(merged, "duplicate vertex", "duplicate vertices") +
                        " (exactly equal coordinates) of " + std::to_string(vertices_in));
  // Merged-away vertices are unreferenced now as well; only the others count as unused.
  if (const std::size_t unused = drop_unreferenced_vertices(s) - merged)
    r.repairs.push_back("removed " + plural(unused, "vertex", "vertices") + " not used by any triangle");
  long first_duplicate = -1;
  if (const std::size_t duplicates = drop_duplicate_triangles(s, &first_duplicate))
    r.repairs.push_back(
        "removed " + plural(duplicates, "duplicated triangle", "duplicated triangles") +
        " (the same three vertices in the same order as an earlier one; the first was triangle " +
        std::to_string(first_duplicate) + " of the file)");
  r.triangles = s.triangles.size();
  r.vertices = s.vertices.size();
  if (s.triangles.empty()) {
    r.problems.push_back("the surface has no triangles");
    return r;
  }

  // --- Per-triangle measures: bounding box, degeneracy, minimum angles.
  r.bbox_min = r.bbox_max = s.vertices[0];
  for (const Vec3& p : s.vertices)
    for (int k = 0; k < 3; ++k) {
      r.bbox_min[k] = std::min(r.bbox_min[k], p[k]);
      r.bbox_max[k] = std::max(r.bbox_max[k], p[k]);
    }
  const std::size_t m = s.triangles.size();
  std::vector<char> repeated(m, 0);
  std::vector<int> degenerate;
  r.min_angle_histogram.assign(12, 0);
  r.min_angle_deg = 180.0;
  for (std::size_t t = 0; t < m; ++t) {
    const auto& tri = s.triangles[t];
    const Vec3 &a = s.vertices[tri[0]], &b = s.vertices[tri[1]], &c = s.vertices[tri[2]];
    repeated[t] = has_repeated_corner(tri);
    // Exact predicate: a triangle is degenerate when its corners are collinear, not when an
    // epsilon says so; tiny but valid triangles show up in the angle histogram instead.
    if (repeated[t] ||
        CGAL::collinear(Point(a[0], a[1], a[2]), Point(b[0], b[1], b[2]), Point(c[0], c[1], c[2])))
      degenerate.push_back(static_cast<int>(t));
    const double angle = repeated[t] ? 0.0 : triangle_min_angle_deg(a, b, c);
    r.min_angle_deg = std::min(r.min_angle_deg, angle);
    ++r.min_angle_histogram[std::min<std::size_t>(static_cast<std::size_t>(angle / 5.0), 11)];
  }
  r.degenerate_triangles = degenerate.size();

  // --- Combinatorial checks on the soup's edges.
  const SoupTopology topo = analyse_edges(s, repeated);
  r.open_edges = topo.open_uses.size();
  r.non_manifold_edges = topo.nonmanifold.size();
  r.non_manifold_vertices = topo.nonmanifold_vertices.size();
  r.inconsistent_edges = topo.inconsistent.size();
  r.closed = r.open_edges == 0;
  r.manifold = r.non_manifold_edges == 0 && r.non_manifold_vertices == 0;
  r.consistently_oriented = r.inconsistent_edges == 0;
  r.euler_characteristic =
      static_cast<long>(s.vertices.size()) - static_cast<long>(topo.edges) + static_cast<long>(m);

  if (r.open_edges) {
    std::vector<std::string> where;
    for (std::size_t i = 0; i < std::min(kShownLocations, topo.open_uses.size()); ++i) {
      const EdgeUse& u = topo.uses[topo.open_uses[i]];
      where.push_back(edge_text(s, u.key) + " of triangle " + std::to_string(u.triangle));
    }
    r.problems.push_back(
        problem(r.open_edges,
                plural(r.open_edges, "open edge", "open edges") +
                    " (used by only one triangle: the surface has holes or cracks and is not "
                    "closed)",
                where, "Fill the holes or stitch the cracks so that the surface is closed."));
  }
  if (r.non_manifold_edges) {
    std::vector<std::string> where;
    for (std::size_t i = 0; i < std::min(kShownLocations, topo.nonmanifold.size()); ++i) {
      const auto [first, last] = topo.nonmanifold[i];
      std::string tris;
      for (std::size_t k = first; k < last; ++k)
        tris += (k > first ? ", " : "") + std::to_string(topo.uses[k].triangle);
      where.push_back(edge_text(s, topo.uses[first].key) + " shared by triangles " + tris);
    }
    r.problems.push_back(
        problem(r.non_manifold_edges,
                plural(r.non_manifold_edges, "non-manifold edge", "non-manifold edges") +
                    " (shared by more than two triangles)",
                where, "Remove the extra triangles or separate the parts that touch along these edges."));
  }
  if (r.non_manifold_vertices) {
    std::vector<std::string> where;
    for (std::size_t i = 0; i < std::min(kShownLocations, topo.nonmanifold_vertices.size()); ++i) {
      const int v = topo.nonmanifold_vertices[i];
      where.push_back("vertex " + std::to_string(v) + " at " + fmt(s.vertices[v]));
    }
    r.problems.push_back(
        problem(r.non_manifold_vertices,
                plural(r.non_manifold_vertices, "non-manifold vertex", "non-manifold vertices") +
                    " (separate fans of triangles meet at a single point)",
                where, "Separate the parts that touch at these points or join them by triangles."));
  }
  if (r.inconsistent_edges) {
    std::vector<std::string> where;
    for (std::size_t i = 0; i < std::min(kShownLocations, topo.inconsistent.size()); ++i)
      where.push_back(edge_text(s, topo.inconsistent_keys[i]) + " between triangles " +
                      std::to_string(topo.inconsistent[i].first) + " and " +
                      std::to_string(topo.inconsistent[i].second));
    r.problems.push_back(
        problem(r.inconsistent_edges,
                "inconsistent orientation: " + plural(r.inconsistent_edges, "edge is", "edges are") +
                    " traversed in the same direction by both of their triangles (the normals "
                    "flip across them)",
                where, "Orient all triangles consistently (the same winding everywhere)."));
  }
  if (r.degenerate_triangles) {
    std::vector<std::string> where;
    for (std::size_t i = 0; i < std::min(kShownLocations, degenerate.size()); ++i) {
      const auto& tri = s.triangles[degenerate[i]];
      where.push_back("triangle " + std::to_string(degenerate[i]) + " with corners " +
                      fmt(s.vertices[tri[0]]) + ", " + fmt(s.vertices[tri[1]]) + ", " +
                      fmt(s.vertices[tri[2]]));
    }
    r.problems.push_back(
        problem(r.degenerate_triangles,
                plural(r.degenerate_triangles, "degenerate triangle", "degenerate triangles") +
                    " (zero area: coincident or collinear corners)",
                where, "Collapse or remove these triangles and close the surface again."));
  }

  // --- Geometric checks with CGAL, once the soup is a consistently oriented manifold.
  if (!r.manifold || !r.consistently_oriented ||
      std::any_of(repeated.begin(), repeated.end(), [](char c) { return c; })) {
    // Components of the soup, joined through shared vertices, still tell the user how many pieces there are.
    UnionFind pieces(s.vertices.size());
    for (const auto& tri : s.triangles) {
      pieces.unite(tri[0], tri[1]);
      pieces.unite(tri[0], tri[2]);
    }
    for (std::size_t v = 0; v < s.vertices.size(); ++v) r.components += pieces.find(v) == v;
    return r;
  }
  Mesh mesh;
  if (const long refused = build_mesh(s, mesh); refused >= 0) {
    r.problems.push_back("the triangles do not form a manifold surface: CGAL could not attach triangle " +
                         std::to_string(refused) + " at " + fmt(centroid(s, static_cast<int>(refused))) +
                         ". Remove the overlapping or duplicated triangles there.");
    return r;
  }

  std::vector<std::pair<Mesh::Face_index, Mesh::Face_index>> pairs;
  PMP::self_intersections(mesh, std::back_inserter(pairs));
  // CGAL lists each degenerate face as a pair (f, f); those are already reported above.
  pairs.erase(std::remove_if(pairs.begin(), pairs.end(), [](const auto& p) { return p.first == p.second; }),
              pairs.end());
  std::sort(pairs.begin(), pairs.end());
  r.self_intersections = pairs.size();
  if (r.self_intersections) {
    std::vector<std::string> where;
    for (std::size_t i = 0; i < std::min(kShownLocations, pairs.size()); ++i) {
      const int f = static_cast<int>(pairs[i].first.idx()), g = static_cast<int>(pairs[i].second.idx());
      where.push_back("triangles " + std::to_string(f) + " and " + std::to_string(g) + " near " +
                      fmt(centroid(s, f)));
    }
    r.problems.push_back(problem(
        r.self_intersections,
        "self-intersections: " + plural(r.self_intersections, "pair", "pairs") + " of triangles intersect",
        where, "The surface must not cross itself: remesh or repair it there."));
  }

  auto face_component = mesh.add_property_map<Mesh::Face_index, std::size_t>("f:component", 0).first;
  r.components = PMP::connected_components(mesh, face_component);
  if (!r.closed) return r;

  // Genus per component from its Euler characteristic V - E + F = 2 - 2 g.
  std::vector<long> chi(r.components, 0);
  for (Mesh::Face_index f : mesh.faces()) ++chi[face_component[f]];
  for (Mesh::Edge_index e : mesh.edges()) --chi[face_component[mesh.face(mesh.halfedge(e))]];
  for (Mesh::Vertex_index v : mesh.vertices()) ++chi[face_component[mesh.face(mesh.halfedge(v))]];
  r.genus = 0;
  for (long c : chi) r.genus += (2 - c) / 2;

  // Orientation: a consistently inward surface is flipped, which is safe because it changes no
  // geometry; a mixture that no global flip fixes is reported.
  const bool self_intersecting = r.self_intersections > 0;
  r.outward = is_outward(mesh, r.components, self_intersecting);
  if (!r.outward) {
    PMP::reverse_face_orientations(mesh);
    if (is_outward(mesh, r.components, self_intersecting)) {
      for (auto& tri : s.triangles) std::swap(tri[1], tri[2]);
      r.outward = true;
      r.repairs.push_back("reversed the orientation of all " + std::to_string(m) +
                          " triangles: the surface was consistently oriented inward, it now faces outward");
    } else {
      PMP::reverse_face_orientations(mesh);
      r.problems.push_back(misoriented_components(s, mesh, face_component, r.components));
      return r;  // the volume is undefined: the components do not bound one
    }
  }
  r.volume_mm3 = PMP::volume(mesh);
  return r;
}

TriSurface load_closed_surface(const std::string& path, double scale_to_mm, SurfaceReport* report) {
  TriSurface surface = read_surface(path, scale_to_mm);
  SurfaceReport r = check_surface(surface, path);
  if (report) *report = r;
  if (!r.usable()) {
    std::string message = "surface '" + path + "' cannot bound a solid: ";
    for (std::size_t i = 0; i < r.problems.size(); ++i) message += (i ? " Also: " : "") + r.problems[i];
    message += " Run 'hexbite surface check " + path + "' for the full report.";
    throw InputError(message);
  }
  return surface;
}

}  // namespace hexbite
