#include "mesher/quad_local_refinement.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <deque>

#include "common/error.h"
#include "common/progress.h"
#include "mesher/quad_check.h"
#include "mesher/quad_surface_placement.h"
#include "mesher/units.h"
#include "mesher/vec3.h"

namespace hexbite {

using vec3::add;
using vec3::cross;
using vec3::dot;
using vec3::norm;
using vec3::scale;
using vec3::sub;

namespace {

constexpr double kConvergedMm = 1e-4;

Vec3 centroid(const QuadSurface& s, const std::array<int, 4>& quad) {
  Vec3 c{0, 0, 0};
  for (int v : quad) c = add(c, scale(s.vertices[v], 0.25));
  return c;
}

std::string mm(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f mm", x);
  return buf;
}

// Step 1's growth: fills the holes of the patch (every edge-connected part of the rest but the largest) and
// adds the quads around every vertex with more than two patch-boundary edges (the patch touches itself
// there) or with more than half of its quads in the patch (a concave rim corner, where step 3's Tutte
// placement folds quads: 2 on the built-in mandible before this rule), until nothing changes. Afterwards
// every component is a disk bounded by one simple loop (on a sphere, a patch whose complement is connected
// and whose boundary edges meet two at each vertex). Returns false when the patch swallowed the surface.
bool grow_to_disks(const QuadSurface& s, const QuadEdges& qe, std::vector<char>& in) {
  std::vector<std::vector<int>> vertex_quads(s.vertices.size());
  for (std::size_t q = 0; q < s.quads.size(); ++q)
    for (int v : s.quads[q]) vertex_quads[v].push_back(static_cast<int>(q));
  for (bool changed = true; changed;) {
    changed = false;
    std::vector<int> component;
    const int parts = quad_components(
        qe, [&](int q) { return !in[q]; }, [](int) { return true; }, component);
    if (parts == 0) return false;
    std::vector<int> size(parts, 0);
    for (int c : component)
      if (c >= 0) ++size[c];
    const int outside = static_cast<int>(std::max_element(size.begin(), size.end()) - size.begin());
    for (std::size_t q = 0; q < in.size(); ++q)
      if (!in[q] && component[q] != outside) in[q] = changed = true;
    std::vector<int> boundary_degree(s.vertices.size(), 0);
    for (std::size_t e = 0; e < qe.edges.size(); ++e) {
      int inside = 0;
      for (const auto& [q, local] : qe.edge_quads[e]) inside += in[q];
      if (inside == 1)
        for (int v : qe.edges[e]) ++boundary_degree[v];
    }
    for (std::size_t v = 0; v < s.vertices.size(); ++v) {
      if (boundary_degree[v] < 2) continue;
      const auto inside =
          std::count_if(vertex_quads[v].begin(), vertex_quads[v].end(), [&](int q) { return in[q] != 0; });
      if (boundary_degree[v] > 2 || 2 * inside > static_cast<long>(vertex_quads[v].size()))
        for (int q : vertex_quads[v])
          if (!in[q]) in[q] = changed = true;
    }
  }
  return std::find(in.begin(), in.end(), 0) != in.end();
}

// Step 2, one level: the patch-boundary vertices get copies (appended), which replace them in the patch
// quads, and every patch-boundary edge a -> b (as its patch quad runs it) a ring quad (a, b, b', a'), whose
// side a -> b is opposite to the outer quad's b -> a and whose side b' -> a' is opposite to the patch quad's
// a' -> b', so the orientation stays consistent. (*origin)[copy] = (*origin)[v] for every copy; the rungs
// (v, copy of v) of the new ring chords are appended to *rungs. Returns the number of ring quads.
int pillow_patch(QuadSurface& s, const std::vector<char>& in, std::vector<int>* origin,
                 std::vector<std::array<int, 2>>* rungs) {
  const QuadEdges qe = build_quad_edges(s.quads);
  std::vector<std::array<int, 2>> boundary;  // (a, b) in the patch quad's order
  for (std::size_t e = 0; e < qe.edges.size(); ++e) {
    int inside = 0, patch_quad = -1, local = -1;
    for (const auto& [q, k] : qe.edge_quads[e])
      if (q < static_cast<int>(in.size()) && in[q]) {
        ++inside;
        patch_quad = q;
        local = k;
      }
    if (inside == 1) boundary.push_back({s.quads[patch_quad][local], s.quads[patch_quad][(local + 1) % 4]});
  }
  std::vector<int> copy(s.vertices.size(), -1);
  for (const auto& edge : boundary)
    for (int v : edge)
      if (copy[v] < 0) {
        copy[v] = static_cast<int>(s.vertices.size());
        s.vertices.push_back(s.vertices[v]);
        origin->push_back((*origin)[v]);
        rungs->push_back({v, copy[v]});
      }
  for (std::size_t q = 0; q < in.size(); ++q)
    if (in[q])
      for (int& v : s.quads[q])
        if (copy[v] >= 0) v = copy[v];
  for (const auto& [a, b] : boundary) s.quads.push_back({a, b, copy[b], copy[a]});
  return static_cast<int>(boundary.size());
}

// A quad corner whose normal (cross product of its two edges) does not point along `reference`: folded,
// or collapsed while copies still lie on their originals.
bool corner_folded(const QuadSurface& s, const std::array<int, 4>& quad, int k, const Vec3& reference) {
  const Vec3& p = s.vertices[quad[k]];
  return dot(cross(sub(s.vertices[quad[(k + 1) % 4]], p), sub(s.vertices[quad[(k + 3) % 4]], p)),
             reference) <= 0;
}

// The direction a quad of the refined surface should face: the sum of the unrefined surface's vertex
// normals (quad_vertex_normals(), mesher/quad_surface_placement.h) at the vertices its corners were copied
// from. Per quad, not per corner: the coarse quads' normal
// at a node on a crest leans to one side (on the real jaw's lingual crest by up to 70 degrees from the
// occlusal corners there), and the input's normal turns by up to 90 degrees between neighbouring nodes on
// the bumpy crowns; against either, 1 to 3 sound ring quads there counted as folded.
std::vector<Vec3> quad_references(const QuadSurface& s, const std::vector<Vec3>& coarse_normal,
                                  const std::vector<int>& origin) {
  std::vector<Vec3> r(s.quads.size(), Vec3{0, 0, 0});
  for (std::size_t q = 0; q < s.quads.size(); ++q)
    for (int v : s.quads[q]) r[q] = add(r[q], coarse_normal[origin[v]]);
  return r;
}

// Step 3. Gauss-Seidel sweeps moving each vertex of `moved` to the mean of its edge neighbours, projected
// onto the surface. A move is refused when it lands on a face whose normal opposes the one the vertex sat
// on, or when it folds more quad corners around the vertex than before, measured against `reference` (per
// quad, quad_references()); then half and a quarter of the step are tried, else the vertex waits for the
// next sweep. Returns the sweeps run.
int relax(QuadSurface& s, const SurfaceProjector& surface, const std::vector<int>& moved,
          const std::vector<Vec3>& reference, int sweeps) {
  std::vector<std::vector<int>> neighbours(s.vertices.size()), vertex_quads(s.vertices.size());
  for (std::size_t q = 0; q < s.quads.size(); ++q)
    for (int k = 0; k < 4; ++k) {
      const auto& quad = s.quads[q];
      neighbours[quad[k]].push_back(quad[(k + 1) % 4]);
      neighbours[quad[(k + 1) % 4]].push_back(quad[k]);
      vertex_quads[quad[k]].push_back(static_cast<int>(q));
    }
  std::vector<SurfacePoint> at(s.vertices.size());
  for (int v : moved) at[v] = surface.closest(s.vertices[v]);
  const auto folded_around = [&](int v) {
    int n = 0;
    for (int q : vertex_quads[v])
      for (int k = 0; k < 4; ++k) n += corner_folded(s, s.quads[q], k, reference[q]);
    return n;
  };
  int sweep = 0;
  for (double largest = kConvergedMm; sweep < sweeps && largest >= kConvergedMm; ++sweep) {
    largest = 0;
    for (int v : moved) {
      Vec3 mean{0, 0, 0};
      for (int n : neighbours[v]) mean = add(mean, s.vertices[n]);
      const Vec3 old = s.vertices[v], step = sub(scale(mean, 1.0 / neighbours[v].size()), old);
      const int before = folded_around(v);
      // The full step, else half or a quarter of it (backtracking: a vertex next to a fold may still move).
      for (double t = 1.0; t >= 0.25; t *= 0.5) {
        const SurfacePoint p = surface.closest(add(old, scale(step, t)), at[v]);
        if (dot(p.normal, at[v].normal) < 0) continue;
        s.vertices[v] = p.point;
        if (folded_around(v) <= before) {
          largest = std::max(largest, norm(sub(p.point, old)));
          at[v] = p;
          break;
        }
        s.vertices[v] = old;
      }
    }
  }
  return sweep;
}

}  // namespace

double mean_edge_near(const QuadSurface& quads, const Vec3& center, double radius, int* count) {
  const QuadEdges qe = build_quad_edges(quads.quads);
  double sum = 0;
  int n = 0;
  for (const auto& [a, b] : qe.edges) {
    const Vec3 mid = scale(add(quads.vertices[a], quads.vertices[b]), 0.5);
    if (norm(sub(mid, center)) > radius) continue;
    sum += norm(sub(quads.vertices[b], quads.vertices[a]));
    ++n;
  }
  if (count) *count = n;
  return n > 0 ? sum / n : 0.0;
}

QuadSurface refine_quads_locally(const QuadSurface& quads, const SurfaceProjector& surface,
                                 const std::vector<int>& fixed_vertices, const LocalRefinementOptions& o,
                                 LocalRefinementReport* report_out) {
  const auto t0 = std::chrono::steady_clock::now();
  LocalRefinementReport report;
  if (!o.enabled()) {
    if (report_out) *report_out = report;
    return quads;
  }
  if (!(o.radius_mm >= kMinRefineRadiusMm && o.radius_mm <= kMaxRefineRadiusMm))
    throw LocalRefinementError("the local refinement radius " + mm(o.radius_mm) + " is out of range: give " +
                               mm(kMinRefineRadiusMm) + " to " + mm(kMaxRefineRadiusMm));
  if (o.levels < 1 || o.levels > kMaxRefineLevels)
    throw LocalRefinementError("the local refinement levels " + std::to_string(o.levels) +
                               " are out of range: give 1 to " + std::to_string(kMaxRefineLevels));

  // Step 1. Seeds and the patch grown by breadth-first search over quads within the radius.
  QuadSurface s = quads;
  const QuadEdges qe = build_quad_edges(s.quads);
  std::vector<Vec3> centre(s.quads.size());
  for (std::size_t q = 0; q < s.quads.size(); ++q) centre[q] = centroid(s, s.quads[q]);
  std::vector<char> in(s.quads.size(), 0);
  for (std::size_t i = 0; i < o.points.size(); ++i) {
    const SurfacePoint on = surface.closest(o.points[i]);
    const std::string name = i < o.point_names.size() ? o.point_names[i] : "the refinement point";
    if (on.distance > o.max_point_distance_mm)
      throw LocalRefinementError(
          name + " is " + mm(on.distance) + " from the surface (nearest surface point " +
          format_point_mm(on.point) + "); at most " + mm(o.max_point_distance_mm) +
          " is allowed: give a point on the bone surface, such as a bite-point landmark");
    LocalRefinementSite site;
    site.point = o.points[i];
    site.on_surface = on.point;
    site.mean_edge_before_mm = mean_edge_near(s, on.point, o.radius_mm, &site.edges_before);
    report.sites.push_back(site);
    std::size_t seed = 0;
    for (std::size_t q = 1; q < s.quads.size(); ++q)
      if (norm(sub(centre[q], on.point)) < norm(sub(centre[seed], on.point))) seed = q;
    std::deque<int> queue{static_cast<int>(seed)};
    in[seed] = 1;
    while (!queue.empty()) {
      const int q = queue.front();
      queue.pop_front();
      for (int e : qe.quad_edges[q])
        for (const auto& [r, local] : qe.edge_quads[e])
          if (!in[r] && norm(sub(centre[r], on.point)) <= o.radius_mm) {
            in[r] = 1;
            queue.push_back(r);
          }
    }
  }
  if (!grow_to_disks(s, qe, in))
    throw LocalRefinementError("the local refinement patches (radius " + mm(o.radius_mm) +
                               ") cover the whole surface: give a smaller radius");
  std::vector<int> component;
  report.patches = quad_components(
      qe, [&](int q) { return in[q] != 0; }, [](int) { return true; }, component);
  report.patch_quads = static_cast<int>(std::count(in.begin(), in.end(), 1));

  // Step 2. The same patch quads are pillowed `levels` times; ring quads and copies are appended.
  std::vector<int> origin(s.vertices.size());
  for (std::size_t v = 0; v < origin.size(); ++v) origin[v] = static_cast<int>(v);
  std::vector<std::vector<std::array<int, 2>>> rungs(o.levels);
  for (int level = 0; level < o.levels; ++level)
    report.patch_perimeter = pillow_patch(s, in, &origin, &rungs[level]);
  for (int level = o.levels - 1; level >= 0; --level)
    report.ring_rungs.insert(report.ring_rungs.end(), rungs[level].begin(), rungs[level].end());
  report.levels = o.levels;
  report.quads_added = static_cast<int>(s.quads.size() - quads.quads.size());
  report.vertices_added = static_cast<int>(s.vertices.size() - quads.vertices.size());

  // Step 3. Moved: the vertices of the patch quads and every copy, except the fixed ones. The original
  // boundary loop now lies in outer and ring quads only and holds the disk in place.
  std::vector<char> moved_flag(s.vertices.size(), 0), fixed(s.vertices.size(), 0);
  for (int v : fixed_vertices) fixed[v] = 1;
  for (std::size_t q = 0; q < in.size(); ++q)
    if (in[q])
      for (int v : s.quads[q]) moved_flag[v] = 1;
  std::fill(moved_flag.begin() + quads.vertices.size(), moved_flag.end(), 1);
  std::vector<int> moved;
  for (std::size_t v = 0; v < s.vertices.size(); ++v)
    if (moved_flag[v] && !fixed[v]) moved.push_back(static_cast<int>(v));
  report.moved_vertices = static_cast<int>(moved.size());
  const std::vector<Vec3> reference = quad_references(s, quad_vertex_normals(quads), origin);
  report.relax_sweeps = relax(s, surface, moved, reference, o.relax_sweeps);
  for (std::size_t q = 0; q < s.quads.size(); ++q)
    if (std::any_of(s.quads[q].begin(), s.quads[q].end(), [&](int v) { return moved_flag[v] != 0; }))
      for (int k = 0; k < 4; ++k)
        if (corner_folded(s, s.quads[q], k, reference[q])) {
          ++report.folded_quads;
          break;
        }
  for (LocalRefinementSite& site : report.sites)
    site.mean_edge_after_mm = mean_edge_near(s, site.on_surface, o.radius_mm, &site.edges_after);
  report.seconds = seconds_since(t0);
  if (report_out) *report_out = report;
  return s;
}

}  // namespace hexbite
