#include "mesher/surface_clean.h"

#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/distance.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/Euler_operations.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <queue>
#include <utility>

#include "common/error.h"
#include "common/progress.h"

namespace hexbite {

namespace {

namespace PMP = CGAL::Polygon_mesh_processing;
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;
using Vector = K::Vector_3;
using Triangle = K::Triangle_3;
using Mesh = CGAL::Surface_mesh<Point>;
using VI = Mesh::Vertex_index;
using HI = Mesh::Halfedge_index;
using EI = Mesh::Edge_index;
using FI = Mesh::Face_index;
// Distance queries against the input run on a plain double kernel: they compare distances with a
// bound, where the filtered kernel's exact fallback (frequent, as many query points lie exactly on
// the input) costs time and buys nothing. The same holds for the final Hausdorff measurement.
using Plain = CGAL::Simple_cartesian<double>;
using PlainMesh = CGAL::Surface_mesh<Plain::Point_3>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Plain, CGAL::AABB_face_graph_triangle_primitive<PlainMesh>>>;

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;

// An operation may turn a triangle's normal by at most this much. Anything below 90 degrees rules
// out a reversed (folded-over) triangle; 45 degrees also keeps the local shading of the surface.
constexpr double kMaxNormalChangeDeg = 45.0;
// The angle between the normals of two neighbouring triangles after an operation may not exceed
// this, unless the neighbourhood already had a sharper crease (which is then not made worse).
constexpr double kMaxCreaseDeg = 60.0;
// The per-operation deviation checks sample the surfaces (input vertices, edge thirds and triangle
// centroids one way, a barycentric grid on the new triangles the other way). The true distance between
// samples can be slightly larger, so the local checks use this fraction of the bound; the
// symmetric Hausdorff distance measured at the end is what the report states.
constexpr double kDeviationMargin = 0.75;
// When the measured deviation still exceeds the bound, the cleanup is repeated with the local
// bound multiplied by this, at most kMaxAttempts times in all.
constexpr double kMarginShrink = 0.7;
constexpr int kMaxAttempts = 3;
// The Hausdorff measurement is exact up to this fraction of the bound.
constexpr double kHausdorffErrorFraction = 0.05;
// Size reduction (--target-triangles) must not create triangles whose smallest angle is below
// this (or below the neighbourhood's previous minimum, when that was already smaller).
constexpr double kReductionMinAngleDeg = 20.0;
// Passes over the remaining bad triangles; each pass tries every one of them once.
constexpr int kMaxAnglePasses = 8;
// Rounds of (contraction sweep, flip sweep) in the size reduction.
constexpr int kMaxReductionRounds = 6;

double corner_angle(const Point& a, const Point& b, const Point& c) {
  const Vector u = b - a, v = c - a;
  return std::atan2(std::sqrt(CGAL::cross_product(u, v).squared_length()), u * v);
}

double min_angle(const Point& a, const Point& b, const Point& c) {
  return std::min({corner_angle(a, b, c), corner_angle(b, c, a), corner_angle(c, a, b)});
}

Vector unit_normal(const Point& a, const Point& b, const Point& c) {
  const Vector n = CGAL::cross_product(b - a, c - a);
  const double length = std::sqrt(n.squared_length());
  return length > 0 ? n / length : Vector(0, 0, 0);
}

Mesh to_mesh(const TriSurface& surface) {
  Mesh mesh;
  mesh.reserve(surface.vertices.size(), 3 * surface.triangles.size() / 2, surface.triangles.size());
  for (const Vec3& v : surface.vertices) mesh.add_vertex(Point(v[0], v[1], v[2]));
  for (const auto& t : surface.triangles) {
    if (mesh.add_face(VI(t[0]), VI(t[1]), VI(t[2])) == Mesh::null_face())
      throw InputError(
          "surface clean: the input is not an oriented 2-manifold (run 'hexbite surface check')");
  }
  return mesh;
}

PlainMesh to_plain_mesh(const TriSurface& surface) {
  PlainMesh mesh;
  for (const Vec3& v : surface.vertices) mesh.add_vertex(Plain::Point_3(v[0], v[1], v[2]));
  for (const auto& t : surface.triangles)
    mesh.add_face(PlainMesh::Vertex_index(t[0]), PlainMesh::Vertex_index(t[1]),
                  PlainMesh::Vertex_index(t[2]));
  return mesh;
}

std::array<VI, 3> face_vertices(const Mesh& mesh, FI f) {
  const HI h = mesh.halfedge(f);
  return {mesh.source(h), mesh.target(h), mesh.target(mesh.next(h))};
}

double face_min_angle(const Mesh& mesh, FI f) {
  const auto v = face_vertices(mesh, f);
  return min_angle(mesh.point(v[0]), mesh.point(v[1]), mesh.point(v[2]));
}

Vector face_normal(const Mesh& mesh, FI f) {
  const auto v = face_vertices(mesh, f);
  return unit_normal(mesh.point(v[0]), mesh.point(v[1]), mesh.point(v[2]));
}

// A local operation, planned but not yet applied: either the flip of the edge of `h`, or the
// contraction of the edge of `h` into its target `kept`, which moves to `p`. It replaces the
// triangles `old_faces` by `tris` (vertex ids after the operation).
struct Plan {
  bool flip = false;
  HI h;
  VI kept;
  Point p;
  std::vector<FI> old_faces;
  std::vector<std::array<VI, 3>> tris;
  std::vector<Vector> reference_normals;  // per new triangle: the normal it replaces
  double old_min = 0;                     // smallest angle among old_faces (radians)
  double score = 0;                       // smallest angle among tris (radians)
};

class Cleaner {
 public:
  Cleaner(const TriSurface& surface, const CleanOptions& options, double margin)
      : input_(to_plain_mesh(surface)),
        mesh_(to_mesh(surface)),
        tree_(faces(input_).first, faces(input_).second, input_),
        threshold_(options.min_angle_deg * kDeg),
        bound2_(std::pow(margin * options.max_deviation_mm, 2)),
        grid_spacing_(3 * options.max_deviation_mm) {
    tree_.accelerate_distance_queries();
    face_samples_ = mesh_.add_property_map<FI, std::vector<std::uint32_t>>("f:samples").first;
    // Every input vertex, the points at a third and two thirds of every input edge and every input
    // triangle centroid are samples that must stay within the bound of the cleaned surface; each
    // is attached to a triangle it lies on, and later to the new triangle it is closest to.
    for (VI v : mesh_.vertices()) {
      samples_.push_back(mesh_.point(v));
      face_samples_[mesh_.face(mesh_.halfedge(v))].push_back(std::uint32_t(samples_.size() - 1));
    }
    for (EI e : mesh_.edges()) {
      const HI h = mesh_.halfedge(e);
      const Point &a = mesh_.point(mesh_.source(h)), &b = mesh_.point(mesh_.target(h));
      for (double t : {1.0 / 3.0, 2.0 / 3.0}) {
        samples_.push_back(CGAL::barycenter(a, 1.0 - t, b, t));
        face_samples_[mesh_.face(h)].push_back(std::uint32_t(samples_.size() - 1));
      }
    }
    for (FI f : mesh_.faces()) {
      const auto v = face_vertices(mesh_, f);
      samples_.push_back(CGAL::centroid(mesh_.point(v[0]), mesh_.point(v[1]), mesh_.point(v[2])));
      face_samples_[f].push_back(std::uint32_t(samples_.size() - 1));
    }
  }

  const Mesh& mesh() const { return mesh_; }
  std::size_t collapses() const { return collapses_; }
  std::size_t flips() const { return flips_; }

  // Removes triangles whose smallest angle is below the threshold, worst first: for each, the best
  // valid operation among the flips of its three edges and the contractions of its three edges
  // (kept at either end or at the midpoint) that raises the local minimum angle.
  void remove_small_angles(Progress& progress) {
    for (int pass = 0; pass < kMaxAnglePasses; ++pass) {
      std::vector<std::pair<double, FI>> bad;
      for (FI f : mesh_.faces()) {
        const double a = face_min_angle(mesh_, f);
        if (a < threshold_) bad.emplace_back(a, f);
      }
      if (bad.empty()) return;
      std::sort(bad.begin(), bad.end());
      std::size_t changed = 0;
      for (std::size_t i = 0; i < bad.size(); ++i) {
        const FI f = bad[i].second;
        if (mesh_.is_removed(f) || face_min_angle(mesh_, f) >= threshold_) continue;
        if (fix_face(f)) ++changed;
        if (i % 64 == 0)
          progress.update((pass + double(i) / bad.size()) / kMaxAnglePasses,
                          "angle pass " + std::to_string(pass + 1));
      }
      if (changed == 0) return;
    }
  }

  // Contracts edges, shortest first, until the surface has at most `target` triangles or no
  // contraction keeps the deviation and the angles within their bounds; flips between sweeps
  // restore the angles so that further contractions become possible.
  void reduce(std::size_t target, Progress& progress) {
    const std::size_t start = mesh_.number_of_faces();
    for (int round = 0; round < kMaxReductionRounds && mesh_.number_of_faces() > target; ++round) {
      using Entry = std::pair<double, std::uint32_t>;
      std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> queue;
      for (EI e : mesh_.edges()) queue.emplace(edge_length2(e), std::uint32_t(e));
      std::size_t done = 0;
      while (!queue.empty() && mesh_.number_of_faces() > target) {
        const auto [length2, index] = queue.top();
        queue.pop();
        const EI e(index);
        if (mesh_.is_removed(e) || edge_length2(e) != length2) continue;
        const VI kept = contract_for_size(e);
        if (kept == Mesh::null_vertex()) continue;
        ++done;
        for (HI h : CGAL::halfedges_around_target(mesh_.halfedge(kept), mesh_)) {
          const EI around = mesh_.edge(h);
          queue.emplace(edge_length2(around), std::uint32_t(around));
        }
        if (done % 256 == 0)
          progress.update(double(start - mesh_.number_of_faces()) / double(start - target),
                          "reduction round " + std::to_string(round + 1));
      }
      const std::size_t flipped = improve_by_flips();
      if (done == 0 && flipped == 0) break;
    }
  }

  // Flips every edge whose flip raises the smaller angle of its two triangles (within the
  // deviation and normal bounds). Returns the number of flips.
  std::size_t improve_by_flips() {
    std::size_t count = 0;
    for (EI e : mesh_.edges()) {
      Plan plan;
      if (!plan_flip(mesh_.halfedge(e), plan) || plan.score <= plan.old_min + 1e-9) continue;
      if (check(plan)) {
        apply(plan);
        ++count;
      }
    }
    return count;
  }

 private:
  double edge_length2(EI e) const {
    const HI h = mesh_.halfedge(e);
    return CGAL::squared_distance(mesh_.point(mesh_.source(h)), mesh_.point(mesh_.target(h)));
  }

  Point position(const Plan& plan, VI v) const {
    return (!plan.flip && v == plan.kept) ? plan.p : mesh_.point(v);
  }

  Triangle new_triangle(const Plan& plan, std::size_t i) const {
    const auto& t = plan.tris[i];
    return Triangle(position(plan, t[0]), position(plan, t[1]), position(plan, t[2]));
  }

  void score(Plan& plan) const {
    plan.old_min = std::numeric_limits<double>::max();
    for (FI f : plan.old_faces) plan.old_min = std::min(plan.old_min, face_min_angle(mesh_, f));
    plan.score = std::numeric_limits<double>::max();
    for (std::size_t i = 0; i < plan.tris.size(); ++i) {
      const Triangle t = new_triangle(plan, i);
      plan.score = std::min(plan.score, min_angle(t[0], t[1], t[2]));
    }
  }

  // Plans the contraction of the edge of h into target(h), placed at p. False when the link
  // condition fails (the contraction would make the surface non-manifold or change its genus).
  bool plan_collapse(HI h, const Point& p, Plan& plan) const {
    if (mesh_.number_of_faces() <= 4 || !CGAL::Euler::does_satisfy_link_condition(mesh_.edge(h), mesh_))
      return false;
    plan = Plan();
    plan.h = h;
    plan.kept = mesh_.target(h);
    plan.p = p;
    const VI removed = mesh_.source(h);
    for (VI v : {removed, plan.kept}) {
      for (FI f : CGAL::faces_around_target(mesh_.halfedge(v), mesh_)) {
        if (std::find(plan.old_faces.begin(), plan.old_faces.end(), f) == plan.old_faces.end())
          plan.old_faces.push_back(f);
      }
    }
    const FI gone1 = mesh_.face(h), gone2 = mesh_.face(mesh_.opposite(h));
    for (FI f : plan.old_faces) {
      if (f == gone1 || f == gone2) continue;
      auto t = face_vertices(mesh_, f);
      for (VI& v : t)
        if (v == removed) v = plan.kept;
      plan.tris.push_back(t);
      plan.reference_normals.push_back(face_normal(mesh_, f));
    }
    score(plan);
    return true;
  }

  // Plans the flip of the edge of h. False when the flip is impossible: an end vertex would be left
  // with two triangles, or the new edge exists already (the surface would become non-manifold).
  bool plan_flip(HI h, Plan& plan) const {
    const HI o = mesh_.opposite(h);
    const VI s = mesh_.source(h), t = mesh_.target(h);
    const VI a = mesh_.target(mesh_.next(h)), b = mesh_.target(mesh_.next(o));
    if (mesh_.degree(s) <= 3 || mesh_.degree(t) <= 3 || a == b ||
        mesh_.halfedge(a, b) != Mesh::null_halfedge())
      return false;
    plan = Plan();
    plan.flip = true;
    plan.h = h;
    plan.old_faces = {mesh_.face(h), mesh_.face(o)};
    // The quad s -> b -> t -> a is split along a-b instead of s-t, keeping its orientation.
    plan.tris = {{s, b, a}, {b, t, a}};
    const Vector n = CGAL::cross_product(mesh_.point(t) - mesh_.point(s), mesh_.point(a) - mesh_.point(s)) +
                     CGAL::cross_product(mesh_.point(s) - mesh_.point(t), mesh_.point(b) - mesh_.point(t));
    const double length = std::sqrt(n.squared_length());
    if (length == 0) return false;
    plan.reference_normals = {n / length, n / length};
    score(plan);
    return true;
  }

  // Geometric validity of a planned operation: no degenerate or turned-over triangle, no new sharp
  // crease, and both one-sided distances to the input within the bound (input samples attached to
  // the replaced triangles against the new triangles; a grid on the new triangles against the
  // input's AABB tree). Leaves the nearest new triangle of each attached sample in nearest_.
  bool check(const Plan& plan) {
    const std::size_t n = plan.tris.size();
    normals_.resize(n);
    triangles_.resize(n);
    const double cos_normal = std::cos(kMaxNormalChangeDeg * kDeg);
    for (std::size_t i = 0; i < n; ++i) {
      triangles_[i] = new_triangle(plan, i);
      normals_[i] = unit_normal(triangles_[i][0], triangles_[i][1], triangles_[i][2]);
      if (normals_[i] == CGAL::NULL_VECTOR || normals_[i] * plan.reference_normals[i] < cos_normal)
        return false;
    }
    if (!creases_acceptable(plan)) return false;

    pool_.clear();
    for (FI f : plan.old_faces) pool_.insert(pool_.end(), face_samples_[f].begin(), face_samples_[f].end());
    nearest_.resize(pool_.size());
    for (std::size_t k = 0; k < pool_.size(); ++k) {
      const Point& q = samples_[pool_[k]];
      double best = std::numeric_limits<double>::max();
      for (std::size_t i = 0; i < n; ++i) {
        const double d = CGAL::squared_distance(q, triangles_[i]);
        if (d < best) {
          best = d;
          nearest_[k] = std::uint32_t(i);
        }
      }
      if (best > bound2_) return false;
    }

    for (std::size_t i = 0; i < n; ++i) {
      const Triangle& t = triangles_[i];
      const double longest =
          std::sqrt(std::max({CGAL::squared_distance(t[0], t[1]), CGAL::squared_distance(t[1], t[2]),
                              CGAL::squared_distance(t[2], t[0])}));
      const int steps = std::clamp(int(std::ceil(longest / grid_spacing_)), 3, 6);
      for (int a = 0; a <= steps; ++a) {
        for (int b = 0; a + b <= steps; ++b) {
          const int c = steps - a - b;
          // Corners that keep their place were checked when they got there.
          const bool corner = (a == steps || b == steps || c == steps);
          if (corner) {
            const VI v = plan.tris[i][a == steps ? 0 : (b == steps ? 1 : 2)];
            if (plan.flip || v != plan.kept) continue;
          }
          const Point q = CGAL::barycenter(t[0], double(a) / steps, t[1], double(b) / steps, t[2]);
          const Plain::Point_3 p(q.x(), q.y(), q.z());
          // CGAL tests the sphere's surface, not the ball: input lying wholly inside the ball (a bound
          // larger than the solid) misses it, so then the distance decides.
          if (!tree_.do_intersect(Plain::Sphere_3(p, bound2_)) && tree_.squared_distance(p) > bound2_)
            return false;
        }
      }
    }
    return true;
  }

  // The largest angle between neighbouring normals among the new triangles must not exceed
  // kMaxCreaseDeg, or the largest one among the replaced triangles if that was larger.
  bool creases_acceptable(const Plan& plan) const {
    double old_worst = 1.0;
    for (FI f : plan.old_faces) {
      const Vector nf = face_normal(mesh_, f);
      for (HI h : CGAL::halfedges_around_face(mesh_.halfedge(f), mesh_))
        old_worst = std::min(old_worst, nf * face_normal(mesh_, mesh_.face(mesh_.opposite(h))));
    }
    const double limit = std::min(old_worst, std::cos(kMaxCreaseDeg * kDeg));
    const std::size_t n = plan.tris.size();
    for (std::size_t i = 0; i < n; ++i) {
      for (int k = 0; k < 3; ++k) {
        const VI a = plan.tris[i][k], b = plan.tris[i][(k + 1) % 3];
        Vector neighbour = CGAL::NULL_VECTOR;
        for (std::size_t j = 0; j < n && neighbour == CGAL::NULL_VECTOR; ++j) {
          const auto& t = plan.tris[j];
          for (int l = 0; l < 3; ++l)
            if (t[l] == b && t[(l + 1) % 3] == a) neighbour = normals_[j];
        }
        if (neighbour == CGAL::NULL_VECTOR) {
          // An edge on the rim of the changed region: its other triangle is unchanged.
          const HI across = mesh_.halfedge(b, a);
          if (across == Mesh::null_halfedge()) return false;
          const FI f = mesh_.face(across);
          if (std::find(plan.old_faces.begin(), plan.old_faces.end(), f) != plan.old_faces.end())
            return false;
          neighbour = face_normal(mesh_, f);
        }
        if (normals_[i] * neighbour < limit) return false;
      }
    }
    return true;
  }

  // Applies a plan that passed check() (immediately before, so pool_ and nearest_ belong to it)
  // and attaches the pooled samples to their nearest new triangle.
  void apply(Plan& plan) {
    for (FI f : plan.old_faces) face_samples_[f].clear();
    std::vector<FI> faces_after;
    if (plan.flip) {
      CGAL::Euler::flip_edge(plan.h, mesh_);
      faces_after = {mesh_.face(plan.h), mesh_.face(mesh_.opposite(plan.h))};
      ++flips_;
    } else {
      const VI kept = CGAL::Euler::collapse_edge(mesh_.edge(plan.h), mesh_);
      mesh_.point(kept) = plan.p;
      if (kept != plan.kept) {
        for (auto& t : plan.tris)
          for (VI& v : t)
            if (v == plan.kept) v = kept;
        plan.kept = kept;
      }
      for (FI f : CGAL::faces_around_target(mesh_.halfedge(kept), mesh_)) faces_after.push_back(f);
      ++collapses_;
    }
    face_of_tri_.assign(plan.tris.size(), Mesh::null_face());
    for (std::size_t i = 0; i < plan.tris.size(); ++i) {
      auto wanted = plan.tris[i];
      std::sort(wanted.begin(), wanted.end());
      for (FI f : faces_after) {
        auto have = face_vertices(mesh_, f);
        std::sort(have.begin(), have.end());
        if (have == wanted) face_of_tri_[i] = f;
      }
      if (face_of_tri_[i] == Mesh::null_face())
        throw RunError("surface clean: internal error, an edge operation produced unexpected triangles");
    }
    for (std::size_t k = 0; k < pool_.size(); ++k)
      face_samples_[face_of_tri_[nearest_[k]]].push_back(pool_[k]);
  }

  // Tries the flips and contractions around a bad triangle, best resulting minimum angle first,
  // and applies the first one that is valid and raises the local minimum angle.
  bool fix_face(FI f) {
    std::vector<Plan> plans;
    Plan plan;
    for (HI h : CGAL::halfedges_around_face(mesh_.halfedge(f), mesh_)) {
      if (plan_flip(h, plan)) plans.push_back(plan);
      const Point& s = mesh_.point(mesh_.source(h));
      const Point& t = mesh_.point(mesh_.target(h));
      if (plan_collapse(h, t, plan)) plans.push_back(plan);
      if (plan_collapse(h, CGAL::midpoint(s, t), plan)) plans.push_back(plan);
      if (plan_collapse(mesh_.opposite(h), s, plan)) plans.push_back(plan);
    }
    // Stable sort keeps the generation order on ties, so the choice is deterministic.
    std::stable_sort(plans.begin(), plans.end(),
                     [](const Plan& x, const Plan& y) { return x.score > y.score; });
    for (Plan& candidate : plans) {
      if (candidate.score <= candidate.old_min + 1e-9) continue;
      if (check(candidate)) {
        apply(candidate);
        return true;
      }
    }
    return false;
  }

  // One contraction for the size reduction: the best valid placement (either end or the
  // midpoint) that keeps the angles above kReductionMinAngleDeg. Returns the kept vertex or null.
  VI contract_for_size(EI e) {
    const HI h = mesh_.halfedge(e), o = mesh_.opposite(h);
    const Point s = mesh_.point(mesh_.source(h)), t = mesh_.point(mesh_.target(h));
    std::vector<Plan> plans;
    Plan plan;
    if (plan_collapse(h, t, plan)) plans.push_back(plan);
    if (plan_collapse(o, s, plan)) plans.push_back(plan);
    if (plan_collapse(h, CGAL::midpoint(s, t), plan)) plans.push_back(plan);
    std::stable_sort(plans.begin(), plans.end(),
                     [](const Plan& x, const Plan& y) { return x.score > y.score; });
    const double floor = std::max(threshold_, kReductionMinAngleDeg * kDeg);
    for (Plan& candidate : plans) {
      if (candidate.score < std::min(floor, candidate.old_min)) break;
      if (check(candidate)) {
        apply(candidate);
        return candidate.kept;
      }
    }
    return Mesh::null_vertex();
  }

  PlainMesh input_;
  Mesh mesh_;
  Tree tree_;
  double threshold_;
  double bound2_;
  // New triangles are sampled with about one grid step per this length (3 to 6 steps).
  double grid_spacing_;
  std::vector<Point> samples_;
  Mesh::Property_map<FI, std::vector<std::uint32_t>> face_samples_;
  std::size_t collapses_ = 0, flips_ = 0;
  // Scratch space of check() and apply(), kept to avoid allocations.
  std::vector<Vector> normals_;
  std::vector<Triangle> triangles_;
  std::vector<std::uint32_t> pool_, nearest_;
  std::vector<FI> face_of_tri_;
};

double triangle_min_angle_deg(const TriSurface& s, const std::array<int, 3>& t) {
  const Vec3 &a = s.vertices[t[0]], &b = s.vertices[t[1]], &c = s.vertices[t[2]];
  return min_angle(Point(a[0], a[1], a[2]), Point(b[0], b[1], b[2]), Point(c[0], c[1], c[2])) / kDeg;
}

double surface_min_angle(const TriSurface& s) {
  double result = 180.0;
  for (const auto& t : s.triangles) result = std::min(result, triangle_min_angle_deg(s, t));
  return result;
}

// The live part of the working mesh as plain arrays, vertices and triangles in index order.
TriSurface to_surface(const Mesh& mesh) {
  TriSurface out;
  std::vector<int> index(mesh.number_of_vertices() + mesh.number_of_removed_vertices(), -1);
  for (VI v : mesh.vertices()) {
    index[v] = int(out.vertices.size());
    const Point& p = mesh.point(v);
    out.vertices.push_back({p.x(), p.y(), p.z()});
  }
  for (FI f : mesh.faces()) {
    const auto v = face_vertices(mesh, f);
    out.triangles.push_back({index[v[0]], index[v[1]], index[v[2]]});
  }
  return out;
}

// The measured deviation: an upper bound on the symmetric Hausdorff distance (CGAL's estimate,
// which is a lower bound, plus its error bound), independent of the samples used by the local
// checks.
double measure_hausdorff(const TriSurface& a, const TriSurface& b, double error_bound) {
  return PMP::bounded_error_symmetric_Hausdorff_distance<CGAL::Sequential_tag>(
             to_plain_mesh(a), to_plain_mesh(b), error_bound) +
         error_bound;
}

std::string format_unfixed(const UnfixedTriangle& u) {
  char buffer[160];
  std::snprintf(buffer, sizeof buffer, "triangle %zu (min angle %.2f deg) at (%.3f, %.3f, %.3f)", u.index,
                u.min_angle_deg, u.centroid[0], u.centroid[1], u.centroid[2]);
  return buffer;
}

}  // namespace

void validate_clean_options(const CleanOptions& options) {
  if (!(options.min_angle_deg >= 0.0 && options.min_angle_deg <= 30.0))
    throw InputError("--min-angle must be between 0 and 30 degrees (got " +
                     std::to_string(options.min_angle_deg) + "); the seed paper uses 5");
  if (!(options.max_deviation_mm > 0.0 && std::isfinite(options.max_deviation_mm)))
    throw InputError("--max-deviation must be a positive distance in mm (got " +
                     std::to_string(options.max_deviation_mm) + ")");
  if (options.target_triangles > 0 && options.target_triangles < 4)
    throw InputError(
        "--target-triangles must be at least 4 (a closed surface has at least 4 triangles), got " +
        std::to_string(options.target_triangles));
}

TriSurface clean_surface(const TriSurface& surface, const CleanOptions& options, CleanReport* report) {
  validate_clean_options(options);
  const auto start = std::chrono::steady_clock::now();
  Progress progress("cleaning surface");
  const double error_bound = kHausdorffErrorFraction * options.max_deviation_mm;

  // The local checks sample the surfaces, so in rare cases the measured deviation can exceed what
  // they allowed; then the whole cleanup is repeated with a tighter local bound.
  double margin = kDeviationMargin;
  TriSurface result;
  double hausdorff = 0;
  std::size_t collapses = 0, flips = 0;
  for (int attempt = 0; attempt < kMaxAttempts; ++attempt, margin *= kMarginShrink) {
    Cleaner cleaner(surface, options, margin);
    cleaner.remove_small_angles(progress);
    if (options.target_triangles > 0 && cleaner.mesh().number_of_faces() > options.target_triangles) {
      cleaner.reduce(options.target_triangles, progress);
      // The reduction never creates new bad triangles, but its flips may have made room to fix
      // some that the first passes could not.
      cleaner.remove_small_angles(progress);
    }
    result = to_surface(cleaner.mesh());
    collapses = cleaner.collapses();
    flips = cleaner.flips();
    hausdorff = measure_hausdorff(surface, result, error_bound);
    if (hausdorff <= options.max_deviation_mm) break;
  }
  if (hausdorff > options.max_deviation_mm) {
    char buffer[200];
    std::snprintf(
        buffer, sizeof buffer,
        "surface clean: the cleaned surface deviates %.4f mm from the input, more than --max-deviation "
        "%g mm, even with tightened local checks",
        hausdorff, options.max_deviation_mm);
    throw RunError(buffer);
  }
  progress.finish();

  if (report) {
    CleanReport& r = *report;
    r = CleanReport();
    r.triangles_before = surface.triangles.size();
    r.vertices_before = surface.vertices.size();
    r.triangles_after = result.triangles.size();
    r.vertices_after = result.vertices.size();
    r.min_angle_before_deg = surface_min_angle(surface);
    r.min_angle_after_deg = surface_min_angle(result);
    r.collapses = collapses;
    r.flips = flips;
    r.hausdorff_mm = hausdorff;
    r.max_deviation_mm = options.max_deviation_mm;
    r.target_triangles = options.target_triangles;
    for (const auto& t : surface.triangles)
      if (triangle_min_angle_deg(surface, t) < options.min_angle_deg) ++r.bad_before;
    for (std::size_t i = 0; i < result.triangles.size(); ++i) {
      const auto& t = result.triangles[i];
      const double angle = triangle_min_angle_deg(result, t);
      if (angle >= options.min_angle_deg) continue;
      UnfixedTriangle u;
      u.index = i;
      u.min_angle_deg = angle;
      for (int k = 0; k < 3; ++k)
        u.centroid[k] =
            (result.vertices[t[0]][k] + result.vertices[t[1]][k] + result.vertices[t[2]][k]) / 3.0;
      r.unfixed.push_back(format_unfixed(u));
      r.unfixed_triangles.push_back(u);
    }
    r.bad_after = r.unfixed_triangles.size();
    if (options.target_triangles > 0 && r.triangles_after > options.target_triangles) {
      r.target_reached = false;
      char buffer[256];
      std::snprintf(
          buffer, sizeof buffer,
          "stopped at %zu triangles: no further contraction keeps the deviation within %g mm and the "
          "smallest angle at or above %g degrees",
          r.triangles_after, options.max_deviation_mm,
          std::max(options.min_angle_deg, kReductionMinAngleDeg));
      r.target_note = buffer;
    }
    r.volume_before_mm3 = PMP::volume(to_mesh(surface));
    r.volume_after_mm3 = PMP::volume(to_mesh(result));
    r.seconds = seconds_since(start);
  }
  return result;
}

}  // namespace hexbite
