#include "mesher/quad_surface_placement.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <map>
#include <thread>
#include <tuple>

#include "common/error.h"
#include "common/helper_threads.h"
#include "common/progress.h"
#include "mesher/hex_boundary.h"
#include "mesher/mandible_quad_template.h"
#include "mesher/quad_check.h"
#include "mesher/quad_local_refinement.h"
#include "mesher/surface_projector.h"
#include "mesher/thin_plate_spline.h"
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

constexpr double kMinNormalAgreement = 0.2;
constexpr double kSnapQuality = 0.3;  // feature snapping may lower a quad corner's scaled Jacobian to this

// Calls f(i) for i in [0, n) in up to `threads` threads, each on a contiguous range. f must write only
// what belongs to i (results are combined afterwards in index order, so they do not depend on threads).
template <class F>
void parallel_for(std::size_t n, int threads, const F& f, std::size_t min_chunk = 1024) {
  const std::size_t t =
      std::min<std::size_t>(std::clamp(threads, 1, 8), std::max<std::size_t>(1, n / min_chunk));
  if (t <= 1) {
    for (std::size_t i = 0; i < n; ++i) f(i);
    return;
  }
  std::vector<std::thread> helpers;
  std::vector<std::size_t> refused;  // chunks whose thread the system refused: the caller does them
  for (std::size_t k = 1; k < t; ++k) {
    const auto chunk = [&, k] {
      for (std::size_t i = n * k / t; i < n * (k + 1) / t; ++i) f(i);
    };
    if (!start_helper_thread(helpers, chunk)) refused.push_back(k);
  }
  for (std::size_t i = 0; i < n / t; ++i) f(i);
  for (std::size_t k : refused)
    for (std::size_t i = n * k / t; i < n * (k + 1) / t; ++i) f(i);
  for (std::thread& h : helpers) h.join();
}

Vec3 unit(const Vec3& a) {
  const double n = norm(a);
  return n > 0 ? scale(a, 1.0 / n) : Vec3{0, 0, 0};
}

// Closest point of triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5).
Vec3 closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = sub(b, a), ac = sub(c, a), ap = sub(p, a);
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = sub(p, b);
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return add(a, scale(ab, d1 / (d1 - d3)));
  const Vec3 cp = sub(p, c);
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return add(a, scale(ac, d2 / (d2 - d6)));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return add(b, scale(sub(c, b), (d4 - d3) / ((d4 - d3) + (d5 - d6))));
  const double denom = 1.0 / (va + vb + vc);
  return add(a, add(scale(ab, vb * denom), scale(ac, vc * denom)));
}

// An axis-aligned box and whether it lies farther than `best` from p, with a margin far above the rounding
// of the distances compared with best: a point in the box (a triangle's closest point to p, a grid point)
// is then not closer to p than best, so a search keeping the first strictly closer candidate may skip it.
struct Box {
  Vec3 lo{}, hi{};
};

bool farther(const Box& b, const Vec3& p, double best) {
  double d2 = 0;
  for (int k = 0; k < 3; ++k) {
    const double d = std::max({b.lo[k] - p[k], p[k] - b.hi[k], 0.0});
    d2 += d * d;
  }
  const double limit = best + 1e-6 * (1.0 + best);
  return d2 > limit * limit;
}

// The bounding box of triangle abc when closest_on_triangle() returns points on it to far better than
// farther()'s margin; for a sliver (twice its area below 1e-3 of its longest edge squared), whose rounding
// could put the point elsewhere, the whole space, so that it is never skipped.
Box triangle_box(const Vec3& a, const Vec3& b, const Vec3& c) {
  const double longest =
      std::max({dot(sub(b, a), sub(b, a)), dot(sub(c, b), sub(c, b)), dot(sub(a, c), sub(a, c))});
  if (!(norm(cross(sub(b, a), sub(c, a))) >= 1e-3 * longest))
    return Box{{-1e300, -1e300, -1e300}, {1e300, 1e300, 1e300}};
  Box box;
  for (int k = 0; k < 3; ++k) {
    box.lo[k] = std::min({a[k], b[k], c[k]});
    box.hi[k] = std::max({a[k], b[k], c[k]});
  }
  return box;
}

// Closest surface point among the triangles whose outward normal agrees with a given direction: the
// multi-patch restriction that keeps a node on its own side of a thin plate. A uniform grid of triangle
// bounding boxes, searched in growing rings until no closer triangle can remain. Hand-written, with the
// closest-point routine above: SurfaceProjector's CGAL AABB tree answers closest-point queries over all
// triangles only, and a filtered search would need custom traversal traits on it.
class OrientedProjector {
 public:
  explicit OrientedProjector(const TriSurface& s) : s_(s) {
    lo_ = {1e300, 1e300, 1e300};
    Vec3 hi{-1e300, -1e300, -1e300};
    for (const Vec3& v : s.vertices)
      for (int a = 0; a < 3; ++a) {
        lo_[a] = std::min(lo_[a], v[a]);
        hi[a] = std::max(hi[a], v[a]);
      }
    for (int a = 0; a < 3; ++a) {
      lo_[a] -= kMargin;
      dims_[a] = std::max(1, static_cast<int>(std::ceil((hi[a] + kMargin - lo_[a]) / kCell)));
    }
    cells_.resize(static_cast<std::size_t>(dims_[0]) * dims_[1] * dims_[2]);
    normals_.resize(s.triangles.size());
    boxes_.resize(s.triangles.size());
    for (std::size_t t = 0; t < s.triangles.size(); ++t) {
      const Vec3 &a = s.vertices[s.triangles[t][0]], &b = s.vertices[s.triangles[t][1]],
                 &c = s.vertices[s.triangles[t][2]];
      normals_[t] = unit(cross(sub(b, a), sub(c, a)));
      std::array<int, 3> i0, i1;
      for (int k = 0; k < 3; ++k) {
        i0[k] = cell_index(std::min({a[k], b[k], c[k]}), k);
        i1[k] = cell_index(std::max({a[k], b[k], c[k]}), k);
      }
      boxes_[t] = triangle_box(a, b, c);
      for (int z = i0[2]; z <= i1[2]; ++z)
        for (int y = i0[1]; y <= i1[1]; ++y)
          for (int x = i0[0]; x <= i1[0]; ++x) cells_[flat(x, y, z)].push_back(static_cast<int>(t));
    }
    // The bounding box of each cell's triangles.
    cell_boxes_.resize(cells_.size());
    for (std::size_t i = 0; i < cells_.size(); ++i) {
      Box& box = cell_boxes_[i];
      box.lo = {1e300, 1e300, 1e300};
      box.hi = {-1e300, -1e300, -1e300};
      for (int t : cells_[i])
        for (int k = 0; k < 3; ++k) {
          box.lo[k] = std::min(box.lo[k], boxes_[t].lo[k]);
          box.hi[k] = std::max(box.hi[k], boxes_[t].hi[k]);
        }
    }
  }

  // Closest point on a triangle with normal . direction > kMinNormalAgreement and normal . previous > 0
  // (previous: the normal where the node sat before this move, or zero; it keeps a node whose quad-mesh
  // normal points along a thin rim from crossing over to the rim's other face). triangle = -1 when no such
  // triangle lies within the search range.
  SurfacePoint closest(const Vec3& p, const Vec3& direction, const Vec3& previous) const {
    std::array<int, 3> c;
    double outside = 0;  // distance from p to the grid box
    for (int k = 0; k < 3; ++k) {
      c[k] = cell_index(p[k], k);
      const double lo = lo_[k], hi = lo_[k] + dims_[k] * kCell;
      const double d = std::max({lo - p[k], p[k] - hi, 0.0});
      outside += d * d;
    }
    outside = std::sqrt(outside);
    double best = std::numeric_limits<double>::infinity();
    SurfacePoint best_point;
    const int max_ring = std::max({dims_[0], dims_[1], dims_[2]});
    for (int r = 0; r <= max_ring; ++r) {
      if (best <= (r - 1) * kCell - outside) break;  // every unvisited cell is farther than best
      if (r * kCell - outside > kSearchRange) break;
      for (int z = c[2] - r; z <= c[2] + r; ++z)
        for (int y = c[1] - r; y <= c[1] + r; ++y)
          for (int x = c[0] - r; x <= c[0] + r; ++x) {
            if (std::max({std::abs(x - c[0]), std::abs(y - c[1]), std::abs(z - c[2])}) != r) continue;
            if (x < 0 || y < 0 || z < 0 || x >= dims_[0] || y >= dims_[1] || z >= dims_[2]) continue;
            // A triangle whose bounding box is farther than best cannot be strictly closer: skipping it
            // (or a cell whose triangles all are) leaves the answer, ties included, as the full scan's.
            if (farther(cell_boxes_[flat(x, y, z)], p, best)) continue;
            for (int t : cells_[flat(x, y, z)]) {
              if (dot(normals_[t], direction) <= kMinNormalAgreement || dot(normals_[t], previous) < 0)
                continue;
              if (farther(boxes_[t], p, best)) continue;
              const auto& tri = s_.triangles[t];
              const Vec3 q =
                  closest_on_triangle(p, s_.vertices[tri[0]], s_.vertices[tri[1]], s_.vertices[tri[2]]);
              const double d = norm(sub(q, p));
              if (d < best) {
                best = d;
                best_point = {q, normals_[t], t, d};
              }
            }
          }
    }
    if (!std::isfinite(best)) return SurfacePoint{};
    return best_point;
  }

 private:
  static constexpr double kCell = 3.0;
  static constexpr double kMargin = 1.0;
  static constexpr double kSearchRange = 25.0;
  int cell_index(double v, int axis) const {
    return std::clamp(static_cast<int>(std::floor((v - lo_[axis]) / kCell)), 0, dims_[axis] - 1);
  }
  std::size_t flat(int x, int y, int z) const {
    return (static_cast<std::size_t>(z) * dims_[1] + y) * dims_[0] + x;
  }
  const TriSurface& s_;
  Vec3 lo_{};
  std::array<int, 3> dims_{};
  std::vector<std::vector<int>> cells_;
  std::vector<Vec3> normals_;
  std::vector<Box> boxes_;       // per triangle
  std::vector<Box> cell_boxes_;  // per cell, of its triangles
};

// Nearest point of a fixed point set (the quad nodes of one relaxation sweep) among those a predicate
// accepts: a uniform grid searched in growing rings.
class PointGrid {
 public:
  PointGrid(const std::vector<Vec3>& points, double cell) : points_(points), cell_(cell) {
    lo_ = {1e300, 1e300, 1e300};
    Vec3 hi{-1e300, -1e300, -1e300};
    for (const Vec3& p : points)
      for (int a = 0; a < 3; ++a) {
        lo_[a] = std::min(lo_[a], p[a]);
        hi[a] = std::max(hi[a], p[a]);
      }
    for (int a = 0; a < 3; ++a)
      dims_[a] = std::max(1, static_cast<int>(std::ceil((hi[a] - lo_[a]) / cell)) + 1);
    const std::size_t n = static_cast<std::size_t>(dims_[0]) * dims_[1] * dims_[2];
    // The points of cell k are items_[first_[k]] .. items_[first_[k + 1] - 1], in index order.
    std::vector<std::size_t> cell_of(points.size());
    first_.assign(n + 1, 0);
    for (std::size_t i = 0; i < points.size(); ++i) {
      std::array<int, 3> c;
      for (int a = 0; a < 3; ++a) c[a] = index(points[i][a], a);
      cell_of[i] = flat(c[0], c[1], c[2]);
      ++first_[cell_of[i] + 1];
    }
    for (std::size_t k = 0; k < n; ++k) first_[k + 1] += first_[k];
    items_.resize(points.size());
    std::vector<std::size_t> next(first_.begin(), first_.end() - 1);
    for (std::size_t i = 0; i < points.size(); ++i) items_[next[cell_of[i]]++] = static_cast<int>(i);
    boxes_.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      boxes_[k].lo = {1e300, 1e300, 1e300};
      boxes_[k].hi = {-1e300, -1e300, -1e300};
      for (std::size_t j = first_[k]; j < first_[k + 1]; ++j)
        for (int a = 0; a < 3; ++a) {
          boxes_[k].lo[a] = std::min(boxes_[k].lo[a], points_[items_[j]][a]);
          boxes_[k].hi[a] = std::max(boxes_[k].hi[a], points_[items_[j]][a]);
        }
    }
    // Per cell, bit (dz + 1) * 9 + (dy + 1) * 3 + (dx + 1) for each non-empty neighbour within the grid: the
    // first ring visited in the same (z, y, x) order without the empty cells, which hold nothing.
    neighbours_.assign(n, 0);
    for (int z = 0; z < dims_[2]; ++z)
      for (int y = 0; y < dims_[1]; ++y)
        for (int x = 0; x < dims_[0]; ++x) {
          std::uint32_t mask = 0;
          for (int dz = -1; dz <= 1; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
              for (int dx = -1; dx <= 1; ++dx) {
                const int u = x + dx, v = y + dy, w = z + dz;
                if (u < 0 || v < 0 || w < 0 || u >= dims_[0] || v >= dims_[1] || w >= dims_[2]) continue;
                const std::size_t k = flat(u, v, w);
                if (first_[k + 1] > first_[k]) mask |= 1u << ((dz + 1) * 9 + (dy + 1) * 3 + (dx + 1));
              }
          neighbours_[flat(x, y, z)] = mask;
        }
  }

  // Calls f(i) for every point i in the box [lo, hi], in no particular order.
  template <class F>
  void for_each_in_box(const Vec3& lo, const Vec3& hi, const F& f) const {
    std::array<int, 3> c0, c1;
    for (int a = 0; a < 3; ++a) {
      c0[a] = index(lo[a], a);
      c1[a] = index(hi[a], a);
    }
    for (int z = c0[2]; z <= c1[2]; ++z)
      for (int y = c0[1]; y <= c1[1]; ++y)
        for (int x = c0[0]; x <= c1[0]; ++x) {
          const std::size_t k = flat(x, y, z);
          for (std::size_t j = first_[k]; j < first_[k + 1]; ++j) {
            const Vec3& p = points_[items_[j]];
            if (p[0] >= lo[0] && p[0] <= hi[0] && p[1] >= lo[1] && p[1] <= hi[1] && p[2] >= lo[2] &&
                p[2] <= hi[2])
              f(items_[j]);
          }
        }
  }

  // -1 when no accepted point lies within `range`.
  template <class Accept>
  int nearest(const Vec3& p, double range, const Accept& accept) const {
    std::array<int, 3> c;
    double outside = 0;
    for (int a = 0; a < 3; ++a) {
      c[a] = index(p[a], a);
      const double d = std::max({lo_[a] - p[a], p[a] - (lo_[a] + dims_[a] * cell_), 0.0});
      outside += d * d;
    }
    outside = std::sqrt(outside);
    double best = range;
    int best_i = -1;
    if (outside > best + 1e-6 * (1.0 + best)) return -1;  // every point is farther than range
    auto visit = [&](std::size_t cell) {
      if (farther(boxes_[cell], p, best)) return;  // no point of it is strictly nearer
      for (std::size_t j = first_[cell]; j < first_[cell + 1]; ++j) {
        const int i = items_[j];
        const double d = norm(sub(points_[i], p));
        if (d < best && accept(i)) {
          best = d;
          best_i = i;
        }
      }
    };
    const int max_ring = std::max({dims_[0], dims_[1], dims_[2]});
    const std::size_t centre = flat(c[0], c[1], c[2]);
    for (int r = 0; r <= max_ring; ++r) {
      if (best <= (r - 1) * cell_ - outside) break;
      if (r == 0) {
        visit(centre);
        continue;
      }
      if (r == 1) {
        for (std::uint32_t mask = neighbours_[centre] & ~(1u << 13); mask != 0; mask &= mask - 1) {
          const int b = __builtin_ctz(mask);
          visit(flat(c[0] + b % 3 - 1, c[1] + b / 3 % 3 - 1, c[2] + b / 9 - 1));
        }
        continue;
      }
      for (int z = std::max(0, c[2] - r); z <= std::min(dims_[2] - 1, c[2] + r); ++z)
        for (int y = std::max(0, c[1] - r); y <= std::min(dims_[1] - 1, c[1] + r); ++y)
          for (int x = std::max(0, c[0] - r); x <= std::min(dims_[0] - 1, c[0] + r); ++x) {
            if (std::max({std::abs(x - c[0]), std::abs(y - c[1]), std::abs(z - c[2])}) != r) continue;
            visit(flat(x, y, z));
          }
    }
    return best_i;
  }

 private:
  int index(double v, int a) const {
    return std::clamp(static_cast<int>(std::floor((v - lo_[a]) / cell_)), 0, dims_[a] - 1);
  }
  std::size_t flat(int x, int y, int z) const {
    return (static_cast<std::size_t>(z) * dims_[1] + y) * dims_[0] + x;
  }
  const std::vector<Vec3>& points_;
  double cell_;
  Vec3 lo_{};
  std::array<int, 3> dims_{};
  std::vector<std::size_t> first_;
  std::vector<int> items_;
  std::vector<Box> boxes_;                 // per cell, of its points
  std::vector<std::uint32_t> neighbours_;  // per cell, its non-empty neighbours
};

// Area-weighted vertex normals of a quad surface (each quad split along both diagonals).
std::vector<Vec3> vertex_normals(const QuadSurface& q) {
  std::vector<Vec3> n(q.vertices.size(), Vec3{0, 0, 0});
  for (const auto& quad : q.quads) {
    const Vec3 d =
        cross(sub(q.vertices[quad[2]], q.vertices[quad[0]]), sub(q.vertices[quad[3]], q.vertices[quad[1]]));
    for (int v : quad) n[v] = add(n[v], d);
  }
  for (Vec3& v : n) v = unit(v);
  return n;
}

struct Correspondence {
  std::vector<std::string> names;
  std::vector<Vec3> sources, targets;
};

Correspondence correspond(const MandibleQuadTemplate& t, const TriSurface& surface,
                          const Landmarks* landmarks, const std::string& file, const InputTerms& terms) {
  Correspondence c;
  if (!landmarks) {
    const auto target = extreme_points(surface.vertices);
    for (const auto& [name, p] : t.extremes) {
      const auto it = target.find(name);
      if (it == target.end())
        throw InputError(
            "the surface has no points on both sides of x = 0, so it is not a mandible in the "
            "generator's frame (+x subject's left): placed by extreme points, the template needs the "
            "bone's midline at x = 0. Move the bone so that its midline is x = 0, give " +
            terms.landmarks + " (which place it wherever the bone lies), or use " + terms.grid_method);
      c.names.push_back(name);
      c.sources.push_back(p);
      c.targets.push_back(it->second);
    }
    return c;
  }
  std::vector<std::string> missing;
  for (const auto& [name, p] : t.reference) {
    const auto q = landmarks->find(name);
    if (!q) {
      missing.push_back(name);
      continue;
    }
    c.names.push_back(name);
    c.sources.push_back(p);
    c.targets.push_back(*q);
  }
  // Both condyles and the front must be pinned for the warp to place the rami and the body.
  bool left = false, right = false, front = false;
  for (const Vec3& p : c.sources) {
    left = left || (p[0] > 20 && p[1] > 10);
    right = right || (p[0] < -20 && p[1] > 10);
    front = front || p[1] < -10;
  }
  if (c.names.size() < 6 || !left || !right || !front) {
    std::string list;
    for (const auto& m : missing) list += (list.empty() ? "" : ", ") + m;
    // Name what is lacking: a file of one side only has enough points, but none on the other ramus.
    std::string unpinned;
    for (const auto& [pinned, where] : {std::pair<bool, const char*>{left, "on the left ramus"},
                                        {right, "on the right ramus"},
                                        {front, "at the front"}})
      if (!pinned) unpinned += std::string(unpinned.empty() ? "" : " or ") + where;
    const std::string count = std::to_string(c.names.size());
    throw InputError(
        "landmark file " + file + ": " + (c.names.size() < 6 ? "only " + count : count) +
        " of the points that place the mandible template are in it" +
        (unpinned.empty() ? "" : (c.names.size() < 6 ? ", and" : ", but") + (" no point " + unpinned)) +
        " (at least 6 are needed, on both rami and at the front); missing: " + list +
        ". Write them as 'hexbite generate mandible --landmarks' does, or leave out " + terms.landmarks +
        " to place the template by extreme points");
  }
  return c;
}

// The x of the bone's midline by its landmarks: the mean of the midpoints of the left_<name> and
// right_<name> points and muscle insertions, so that a bone placed anywhere along x (not only about x = 0,
// as the built-in mandible and the real jaw are) gets its points derived on the right sides. 0 without
// landmarks (extreme points need the midline at x = 0) or pairs. Exactly 0 for a file mirrored in x.
double landmark_midline_x(const Landmarks* landmarks) {
  if (!landmarks) return 0;
  const std::vector<LeftRightPair> pairs = left_right_pairs(*landmarks);
  double sum = 0;
  for (const LeftRightPair& p : pairs) sum += 0.5 * (p.left[0] + p.right[0]);
  return pairs.empty() ? 0.0 : sum / pairs.size();
}

// Points derived from the surface's shape where landmark files have none but the template needs guidance:
// per side the top of the condyle, the top of the coronoid process and the bottom of the sigmoid notch
// between them (the notch depth varies much between mandibles). Searched among the surface vertices near
// where the first warp puts the default mandible's points, the sides told apart by the midline at
// `midline_x`; names as in MandibleQuadTemplate::derived.
std::map<std::string, Vec3> derive_points(const TriSurface& surface, const MandibleQuadTemplate& t,
                                          const ThinPlateSpline& warp, double midline_x) {
  std::map<std::string, Vec3> out;
  // The highest vertex on one side (beyond 20 mm from the midline) within dy of around's y.
  auto highest = [&](const Vec3& around, double side, double dy) {
    const Vec3* best = nullptr;
    for (const Vec3& v : surface.vertices)
      if (side * (v[0] - midline_x) > 20.0 && std::abs(v[1] - around[1]) < dy && (!best || v[2] > (*best)[2]))
        best = &v;
    return best;
  };
  for (const auto& [side, sign] : {std::pair<std::string, double>{"left_", 1.0}, {"right_", -1.0}}) {
    const Vec3* condyle = highest(warp(t.derived.at(side + "condyle_top")), sign, 10.0);
    const Vec3* coronoid = highest(warp(t.derived.at(side + "coronoid_top")), sign, 20.0);
    if (!condyle || !coronoid || (*condyle)[1] - (*coronoid)[1] < 12.0) continue;
    // The notch: the lowest of the per-millimetre highest points between the two processes.
    const double y0 = (*coronoid)[1] + 4.0, y1 = (*condyle)[1] - 4.0;
    const double xm = 0.5 * ((*condyle)[0] + (*coronoid)[0]);
    const int bins = static_cast<int>(std::ceil(y1 - y0));
    std::vector<const Vec3*> top(static_cast<std::size_t>(bins), nullptr);
    for (const Vec3& v : surface.vertices) {
      if (sign * (v[0] - midline_x) <= 0 || std::abs(v[0] - xm) > 12.0 || v[1] < y0 || v[1] >= y1) continue;
      const int b = std::min(bins - 1, static_cast<int>(v[1] - y0));
      if (!top[b] || v[2] > (*top[b])[2]) top[b] = &v;
    }
    const Vec3* notch = nullptr;
    for (const Vec3* p : top)
      if (p && (!notch || (*p)[2] < (*notch)[2])) notch = p;
    if (!notch) continue;
    const Vec3* back = nullptr;  // the back of the condyle head: the most posterior point near its top
    for (const Vec3& v : surface.vertices)
      if (std::abs(v[0] - (*condyle)[0]) < 10.0 && std::abs(v[2] - (*condyle)[2] + 5.0) < 5.0 &&
          std::abs(v[1] - (*condyle)[1]) < 12.0 && (!back || v[1] > (*back)[1]))
        back = &v;
    out[side + "condyle_back"] = *back;
    out[side + "condyle_top"] = *condyle;
    out[side + "coronoid_top"] = *coronoid;
    out[side + "sigmoid_notch"] = *notch;
  }
  // The incisal top: the highest point near the midline at the front.
  const Vec3 incisal = warp(t.derived.at("incisal_top"));
  const Vec3* top = nullptr;
  for (const Vec3& v : surface.vertices)
    if (std::abs(v[0] - midline_x) < 4.0 && std::abs(v[1] - incisal[1]) < 10.0 && (!top || v[2] > (*top)[2]))
      top = &v;
  if (top) out["incisal_top"] = *top;
  return out;
}

// Per-chord subdivision counts n_c = max(1, round(L_c / h)) with h chosen so that the refined quad count
// is closest to the target and even. A chord marked `odd` gets the odd count nearest to L_c / h, at least 3.
std::vector<int> chord_counts(const std::vector<Chord>& chords, const std::vector<double>& chord_length,
                              const std::vector<std::array<int, 2>>& quad_chords, int target,
                              const std::vector<char>& odd) {
  auto counts_for = [&](double h) {
    std::vector<int> n(chords.size());
    for (std::size_t c = 0; c < chords.size(); ++c) {
      const double x = chord_length[c] / h;
      n[c] = odd[c] ? std::max(3, 2 * static_cast<int>(std::lround((x - 1.0) / 2.0)) + 1)
                    : std::max(1, static_cast<int>(std::lround(x)));
    }
    return n;
  };
  auto total = [&](const std::vector<int>& n) {
    long s = 0;
    for (const auto& qc : quad_chords) s += static_cast<long>(n[qc[0]]) * n[qc[1]];
    return s;
  };
  double lo = 1e-3, hi = 1e3;  // total(lo) >= target >= total(hi)
  for (int it = 0; it < 100; ++it) {
    const double mid = std::sqrt(lo * hi);
    (total(counts_for(mid)) > target ? lo : hi) = mid;
  }
  std::vector<int> n = counts_for(hi);
  if (std::abs(total(counts_for(lo)) - target) < std::abs(total(n) - target)) n = counts_for(lo);
  if (total(n) % 2 != 0) {
    // The single +-1 change of one chord's count that makes the total even and closest to the target (the
    // odd chords keep theirs).
    long best_dev = std::numeric_limits<long>::max();
    int best_c = -1, best_delta = 0;
    for (std::size_t c = 0; c < chords.size(); ++c)
      for (int delta : {-1, 1}) {
        if (odd[c] || n[c] + delta < 1) continue;
        n[c] += delta;
        const long t = total(n);
        n[c] -= delta;
        if (t % 2 == 0 && std::abs(t - target) < best_dev) {
          best_dev = std::abs(t - target);
          best_c = static_cast<int>(c);
          best_delta = delta;
        }
      }
    if (best_c < 0) throw RunError("mandible quad mesh: no chord subdivision gives an even number of quads");
    n[best_c] += best_delta;
  }
  return n;
}

// The refined quad surface: macro edge e gets n(e) - 1 interior nodes, each macro quad an n0 x n1 grid.
QuadSurface refine(const QuadSurface& macro, const QuadEdges& edges, const std::vector<int>& edge_count) {
  QuadSurface fine;
  fine.vertices = macro.vertices;
  std::vector<int> first_edge_node(edges.edges.size());
  for (std::size_t e = 0; e < edges.edges.size(); ++e) {
    first_edge_node[e] = static_cast<int>(fine.vertices.size());
    const Vec3 &a = macro.vertices[edges.edges[e][0]], &b = macro.vertices[edges.edges[e][1]];
    for (int k = 1; k < edge_count[e]; ++k) {
      const double t = static_cast<double>(k) / edge_count[e];
      fine.vertices.push_back(add(scale(a, 1 - t), scale(b, t)));
    }
  }
  // Node k (0..n) of edge e walked from vertex `from`.
  auto edge_node = [&](int e, int from, int k) {
    const int n = edge_count[e];
    const bool forward = edges.edges[e][0] == from;
    const int j = forward ? k : n - k;
    if (j == 0) return edges.edges[e][0];
    if (j == n) return edges.edges[e][1];
    return first_edge_node[e] + j - 1;
  };
  for (std::size_t q = 0; q < macro.quads.size(); ++q) {
    const auto& c = macro.quads[q];
    const auto& qe = edges.quad_edges[q];
    const int nu = edge_count[qe[0]], nv = edge_count[qe[1]];
    std::vector<int> grid(static_cast<std::size_t>(nu + 1) * (nv + 1));
    auto at = [&](int i, int j) -> int& { return grid[static_cast<std::size_t>(j) * (nu + 1) + i]; };
    for (int i = 0; i <= nu; ++i) {
      at(i, 0) = edge_node(qe[0], c[0], i);
      at(nu - i, nv) = edge_node(qe[2], c[2], i);
    }
    for (int j = 0; j <= nv; ++j) {
      at(nu, j) = edge_node(qe[1], c[1], j);
      at(0, nv - j) = edge_node(qe[3], c[3], j);
    }
    for (int j = 1; j < nv; ++j)
      for (int i = 1; i < nu; ++i) {
        const double u = static_cast<double>(i) / nu, v = static_cast<double>(j) / nv;
        Vec3 p{0, 0, 0};
        const double w[4] = {(1 - u) * (1 - v), u * (1 - v), u * v, (1 - u) * v};
        for (int k = 0; k < 4; ++k) p = add(p, scale(macro.vertices[c[k]], w[k]));
        at(i, j) = static_cast<int>(fine.vertices.size());
        fine.vertices.push_back(p);
      }
    for (int j = 0; j < nv; ++j)
      for (int i = 0; i < nu; ++i)
        fine.quads.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
  }
  return fine;
}

Vec3 bilinear(const QuadSurface& q, const std::array<int, 4>& quad, double u, double v) {
  Vec3 p{0, 0, 0};
  const double w[4] = {(1 - u) * (1 - v), u * (1 - v), u * v, (1 - u) * v};
  for (int k = 0; k < 4; ++k) p = add(p, scale(q.vertices[quad[k]], w[k]));
  return p;
}

// The input surface with what placement needs: closest-point queries (plain and restricted) and, per
// input vertex, its area share and normal for the Lloyd step.
struct PlacementSurface {
  PlacementSurface(const TriSurface& s, int threads)
      : surface(s),
        projector(s),
        oriented(s),
        area(s.vertices.size(), 0.0),
        normal(s.vertices.size()),
        threads(threads) {
    for (const auto& t : s.triangles) {
      const Vec3 n = cross(sub(s.vertices[t[1]], s.vertices[t[0]]), sub(s.vertices[t[2]], s.vertices[t[0]]));
      for (int v : t) {
        area[v] += norm(n) / 6.0;
        normal[v] = add(normal[v], n);
      }
    }
    for (Vec3& n : normal) n = unit(n);
  }
  const TriSurface& surface;
  SurfaceProjector projector;
  OrientedProjector oriented;
  std::vector<double> area;
  std::vector<Vec3> normal;
  int threads;  // of the per-input-vertex loops
};

// Restricted projection of every node (normal agreement with the quad mesh's vertex normal); returns the
// input normal where each node landed.
std::vector<Vec3> project(QuadSurface& q, const PlacementSurface& s) {
  const std::vector<Vec3> normals = vertex_normals(q);
  std::vector<Vec3> landed(q.vertices.size());
  for (std::size_t v = 0; v < q.vertices.size(); ++v) {
    SurfacePoint sp = s.oriented.closest(q.vertices[v], normals[v], Vec3{0, 0, 0});
    if (sp.triangle < 0) sp = s.projector.closest(q.vertices[v]);  // nothing facing its way nearby
    q.vertices[v] = sp.point;
    landed[v] = sp.normal;
  }
  return landed;
}

// Relaxation sweeps: each free node moves tangentially toward the mean of the centroid of its quads'
// centroids (Laplacian, for even quads) and the centroid of its restricted Voronoi region among the input
// vertices (Lloyd, so that tips and ridges keep nodes), then back onto the surface with the restricted
// projection, never onto a face whose normal opposes the one it left (*surface_normal, updated); nodes
// move one at a time, and a move that folds more quad corners around the node than before is undone.
void relax(QuadSurface& fine, const PlacementSurface& s, const std::vector<char>& fixed, int sweeps,
           std::vector<Vec3>* surface_normal) {
  std::vector<std::vector<int>> vertex_quads(fine.vertices.size());
  for (std::size_t q = 0; q < fine.quads.size(); ++q)
    for (int v : fine.quads[q]) vertex_quads[v].push_back(static_cast<int>(q));
  // Only the regions of the free nodes are used. When few nodes are free (step 9 relaxes the rings only),
  // an input vertex whose nearest node was a fixed one (fixed nodes stay put), w, is not searched again
  // while w is still accepted and no free node is as near as w: the search would give a fixed node.
  std::size_t free_count = 0;
  for (char f : fixed) free_count += !f;
  const bool witnesses = 2 * free_count < fixed.size();
  std::vector<int> witness(witnesses ? s.surface.vertices.size() : 0, -1);
  for (int sweep = 0; sweep < sweeps; ++sweep) {
    const std::vector<Vec3> normals = vertex_normals(fine);
    std::vector<Vec3> centroid(fine.quads.size());
    for (std::size_t q = 0; q < fine.quads.size(); ++q) centroid[q] = bilinear(fine, fine.quads[q], 0.5, 0.5);
    std::vector<Vec3> region(fine.vertices.size(), Vec3{0, 0, 0});
    std::vector<double> region_area(fine.vertices.size(), 0.0);
    const PointGrid grid(fine.vertices, 4.0);
    std::vector<Vec3> free_points;
    for (std::size_t v = 0; v < fine.vertices.size(); ++v)
      if (witnesses && !fixed[v]) free_points.push_back(fine.vertices[v]);
    const PointGrid free_grid(free_points, 4.0);
    std::vector<int> nearest(s.surface.vertices.size());
    parallel_for(nearest.size(), s.threads, [&](std::size_t i) {
      const Vec3& p = s.surface.vertices[i];
      auto accept = [&](int j) { return dot(normals[j], s.normal[i]) > kMinNormalAgreement; };
      if (witnesses && witness[i] >= 0 && accept(witness[i])) {
        // The same distance as the search computes for w; a free node counts when not farther.
        const double d = norm(sub(fine.vertices[witness[i]], p));
        if (free_grid.nearest(p, std::nextafter(d, 1e300), [](int) { return true; }) < 0) {
          nearest[i] = -1;  // a fixed node, whose region is not used
          return;
        }
      }
      nearest[i] = grid.nearest(p, 20.0, accept);
      if (witnesses) witness[i] = nearest[i] >= 0 && fixed[nearest[i]] ? nearest[i] : -1;
    });
    for (std::size_t i = 0; i < s.surface.vertices.size(); ++i) {
      const int v = nearest[i];
      if (v < 0) continue;
      region[v] = add(region[v], scale(s.surface.vertices[i], s.area[i]));
      region_area[v] += s.area[i];
    }
    // Folded corners of the quads around v (corner normal against the input normal where that corner sits).
    auto folded_around = [&](std::size_t v) {
      int n = 0;
      for (int q : vertex_quads[v]) {
        const auto& quad = fine.quads[q];
        for (int k = 0; k < 4; ++k) {
          const Vec3& p = fine.vertices[quad[k]];
          const Vec3 c =
              cross(sub(fine.vertices[quad[(k + 1) % 4]], p), sub(fine.vertices[quad[(k + 3) % 4]], p));
          if (dot(c, (*surface_normal)[quad[k]]) <= 0) ++n;
        }
      }
      return n;
    };
    for (std::size_t v = 0; v < fine.vertices.size(); ++v) {
      if (fixed[v] || vertex_quads[v].empty()) continue;
      Vec3 target{0, 0, 0};
      for (int q : vertex_quads[v]) target = add(target, centroid[q]);
      target = scale(target, 1.0 / vertex_quads[v].size());
      if (region_area[v] > 0) target = scale(add(target, scale(region[v], 1.0 / region_area[v])), 0.5);
      Vec3 d = sub(target, fine.vertices[v]);
      d = sub(d, scale(normals[v], dot(d, normals[v])));
      const SurfacePoint sp =
          s.oriented.closest(add(fine.vertices[v], scale(d, 0.8)), normals[v], (*surface_normal)[v]);
      if (sp.triangle < 0) continue;  // no admissible move: the node stays this sweep
      // Gauss-Seidel with a veto: a move that folds more corners around the node than before is undone.
      const int before = folded_around(v);
      const Vec3 old_point = fine.vertices[v], old_normal = (*surface_normal)[v];
      fine.vertices[v] = sp.point;
      (*surface_normal)[v] = sp.normal;
      if (folded_around(v) > before) {
        fine.vertices[v] = old_point;
        (*surface_normal)[v] = old_normal;
      }
      if (before == 0 || folded_around(v) == 0) continue;
      // Still folded: try the plain centroid of its quads, on whichever face suits the quad mesh, and keep
      // it if it folds fewer corners.
      const int still = folded_around(v);
      const Vec3 kept_point = fine.vertices[v], kept_normal = (*surface_normal)[v];
      Vec3 plain{0, 0, 0};
      for (int q : vertex_quads[v]) plain = add(plain, centroid[q]);
      const SurfacePoint untangled =
          s.oriented.closest(scale(plain, 1.0 / vertex_quads[v].size()), normals[v], Vec3{0, 0, 0});
      if (untangled.triangle < 0) continue;
      fine.vertices[v] = untangled.point;
      (*surface_normal)[v] = untangled.normal;
      if (folded_around(v) >= still) {
        fine.vertices[v] = kept_point;
        (*surface_normal)[v] = kept_normal;
      }
    }
  }
}

// Agreement of a quad corner with the input: the cosine between the corner normal (cross product of its
// two edges) and the input normal where the corner node sits; <= 0 is a folded corner.
double corner_agreement(const QuadSurface& q, const std::array<int, 4>& quad, int k,
                        const std::vector<Vec3>& surface_normal) {
  const Vec3& p = q.vertices[quad[k]];
  const Vec3 c = cross(sub(q.vertices[quad[(k + 1) % 4]], p), sub(q.vertices[quad[(k + 3) % 4]], p));
  return dot(unit(c), surface_normal[quad[k]]);
}

// Untangling of the quad surface on the input: the nodes of folded quads (a corner agreement <= 0, the input
// normal at a node being that of the triangle closest() names, as in the report) try positions around them
// on the surface (8 tangent directions at 3 step lengths, the centroid of their quads, each placed by the
// restricted projection or the plain one) and take the one that raises the smallest agreement over every
// corner of their quads the most, unless it moves a centre of their quads farther from the input than both
// 0.2 of their mean edge and the farthest one before (no quad may come to bridge a gap); sweeps repeat
// while some node improves. The smallest agreement of the surface therefore never falls.
void unfold(QuadSurface& fine, const PlacementSurface& s, const std::vector<char>& fixed, int sweeps,
            std::vector<Vec3>* surface_normal) {
  constexpr double kUnfoldGap = 0.2;  // of the node's mean edge length
  std::vector<std::vector<int>> vertex_quads(fine.vertices.size());
  for (std::size_t q = 0; q < fine.quads.size(); ++q)
    for (int v : fine.quads[q]) vertex_quads[v].push_back(static_cast<int>(q));
  // The input normal at a node: that of the triangle closest() names, as in the folded-quad count (at a
  // crease of the input the triangle the node was projected onto may be another one).
  for (std::size_t v = 0; v < fine.vertices.size(); ++v)
    (*surface_normal)[v] = s.projector.closest(fine.vertices[v]).normal;
  auto local_min = [&](std::size_t v) {
    double m = 1.0;
    for (int q : vertex_quads[v])
      for (int k = 0; k < 4; ++k) m = std::min(m, corner_agreement(fine, fine.quads[q], k, *surface_normal));
    return m;
  };
  // The largest distance of the centres and edge midpoints of v's quads from the input: a move may not make
  // a quad bridge a gap.
  auto gap = [&](std::size_t v) {
    double g = 0;
    for (int q : vertex_quads[v])
      for (const auto& [a, b] : {std::pair{0.5, 0.5}, {0.5, 0.0}, {1.0, 0.5}, {0.5, 1.0}, {0.0, 0.5}})
        g = std::max(g, s.projector.distance(bilinear(fine, fine.quads[q], a, b)));
    return g;
  };
  for (int sweep = 0; sweep < sweeps; ++sweep) {
    const std::vector<Vec3> normals = vertex_normals(fine);
    std::vector<char> active(fine.vertices.size(), 0);
    for (const auto& quad : fine.quads) {
      bool bad = false;
      for (int k = 0; k < 4; ++k) bad = bad || corner_agreement(fine, quad, k, *surface_normal) <= 0;
      if (bad)
        for (int v : quad) active[v] = 1;
    }
    bool improved = false;
    for (std::size_t v = 0; v < fine.vertices.size(); ++v) {
      if (!active[v] || fixed[v]) continue;
      const Vec3 start = fine.vertices[v], start_normal = (*surface_normal)[v];
      double edge = 0, best = local_min(v);
      Vec3 centroid{0, 0, 0};
      for (int q : vertex_quads[v])
        for (int w : fine.quads[q]) {
          centroid = add(centroid, scale(fine.vertices[w], 0.25 / vertex_quads[v].size()));
          edge += norm(sub(fine.vertices[w], start)) / (3.0 * vertex_quads[v].size());
        }
      const double allowed_gap = std::max(gap(v), kUnfoldGap * edge);
      Vec3 best_point = start, best_normal = start_normal;
      const Vec3 n = normals[v];
      const Vec3 t1 = unit(cross(n, std::abs(n[0]) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0}));
      const Vec3 t2 = cross(n, t1);
      std::vector<Vec3> candidates{centroid};
      for (double step : {0.5, 0.25, 0.1})
        for (int a = 0; a < 8; ++a) {
          const double angle = a * std::acos(-1.0) / 4;
          candidates.push_back(
              add(start, scale(add(scale(t1, std::cos(angle)), scale(t2, std::sin(angle))), step * edge)));
        }
      for (const Vec3& c : candidates)
        for (int restricted = 0; restricted < 2; ++restricted) {
          const SurfacePoint sp =
              restricted ? s.oriented.closest(c, n, Vec3{0, 0, 0}) : s.projector.closest(c);
          if (sp.triangle < 0) continue;
          fine.vertices[v] = sp.point;
          (*surface_normal)[v] = s.projector.closest(sp.point).normal;
          const double m = local_min(v);
          if (m > best + 1e-9 && gap(v) <= allowed_gap) {
            best = m;
            best_point = sp.point;
            best_normal = (*surface_normal)[v];
          }
        }
      fine.vertices[v] = best_point;
      (*surface_normal)[v] = best_normal;
      improved = improved || norm(sub(best_point, start)) > 0;
    }
    if (!improved) break;
  }
}

// Scaled Jacobian of a quad corner against the input: the sine of the corner angle, negative when the
// corner normal opposes the input normal where the corner node sits.
double corner_jacobian(const QuadSurface& q, const std::array<int, 4>& quad, int k,
                       const std::vector<Vec3>& surface_normal) {
  const Vec3& p = q.vertices[quad[k]];
  const Vec3 a = sub(q.vertices[quad[(k + 1) % 4]], p), b = sub(q.vertices[quad[(k + 3) % 4]], p);
  const double l = norm(a) * norm(b);
  return l > 0 ? dot(cross(a, b), surface_normal[quad[k]]) / l : -1.0;
}

// Feature snapping (step 8): the input vertices farther than threshold_mm from the quads (cusp tips,
// condyle poles, crests that the quads cut off), farthest first, pull a free node of their nearest quad
// (nearest node first) onto themselves. A move is kept when it keeps the smallest corner scaled Jacobian of
// the node's quads above kSnapQuality or above what it was, and lowers the local error: the largest
// distance of the vertex and of the input vertices charged to those quads (nearest to them) to them, and
// of their inner sample points to the input. Snapped nodes stay fixed. Each round re-measures; up to
// `rounds` rounds, stopping when a round moves nothing.
// *settled: the distances of the input vertices to the quads as returned, when the last round measured them
// on these quads (it moved nothing), -1 for those only known to lie nearer than threshold_mm; else empty.
void snap_features(QuadSurface& fine, const PlacementSurface& s, std::vector<char>& fixed, int rounds,
                   double threshold_mm, std::vector<Vec3>* surface_normal, std::vector<double>* settled) {
  settled->clear();
  std::vector<std::vector<int>> vertex_quads(fine.vertices.size());
  for (std::size_t q = 0; q < fine.quads.size(); ++q)
    for (int v : fine.quads[q]) vertex_quads[v].push_back(static_cast<int>(q));
  // The fan triangles of some quads (corner, next corner, centre), with their bounding boxes.
  struct Fan {
    std::vector<std::array<Vec3, 3>> triangles;
    std::vector<Box> boxes;
  };
  auto fan_of = [&](const std::vector<int>& quads) {
    Fan f;
    for (int q : quads) {
      const auto& quad = fine.quads[q];
      const Vec3 centre = bilinear(fine, quad, 0.5, 0.5);
      for (int k = 0; k < 4; ++k) {
        f.triangles.push_back({fine.vertices[quad[k]], fine.vertices[quad[(k + 1) % 4]], centre});
        f.boxes.push_back(triangle_box(f.triangles.back()[0], f.triangles.back()[1], centre));
      }
    }
    return f;
  };
  // The distance of p to those quads: the smallest over the triangles (a triangle whose box lies farther
  // than the smallest so far cannot lower it, so skipping it leaves the same value).
  auto distance_to_fan = [&](const Vec3& p, const Fan& f) {
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t t = 0; t < f.triangles.size(); ++t) {
      if (farther(f.boxes[t], p, best)) continue;
      const auto& tri = f.triangles[t];
      best = std::min(best, norm(sub(p, closest_on_triangle(p, tri[0], tri[1], tri[2]))));
    }
    return best;
  };
  // The largest distance of a quad's inner sample points to the input.
  auto sampled_error = [&](int q) {
    double e = 0;
    for (int b = 1; b <= 3; ++b)
      for (int a = 1; a <= 3; ++a)
        e = std::max(e, s.projector.distance(bilinear(fine, fine.quads[q], a / 4.0, b / 4.0)));
    return e;
  };
  // The part of a node's local error and quality that does not depend on the input vertex pulling it (the
  // charged vertices' distances, the smallest corner scaled Jacobian), cached per node: valid while no move
  // has been kept since (a rejected move restores every value it changed).
  std::vector<double> cached_charged(fine.vertices.size()), cached_quality(fine.vertices.size());
  std::vector<long> cached_at(fine.vertices.size(), -1);
  long state = 0;  // bumped by every kept move and every round
  // Per input vertex: its quad (the closest-point query's triangle / 4) and distance, from the latest
  // round that queried it.
  std::vector<int> nearest_quad(s.surface.vertices.size(), -1);
  std::vector<double> distance(s.surface.vertices.size());
  // The input vertices in a uniform grid, to find those near a quad.
  const PointGrid vertex_grid(s.surface.vertices, 2.0);
  constexpr double kBoundMargin = 1e-6;  // mm, far above the rounding of the distances compared
  // The sampled error of each quad, kept up to date by the kept moves (the only changes of the quads), so
  // measured once rather than every round.
  std::vector<double> sample_error(fine.quads.size());
  parallel_for(
      fine.quads.size(), s.threads,
      [&](std::size_t q) { sample_error[q] = sampled_error(static_cast<int>(q)); }, 64);
  for (int round = 0; round < rounds; ++round) {
    ++state;
    const TriSurface fan = fan_triangles(fine);
    const SurfaceProjector quad_projector(fan);
    std::vector<std::vector<int>> charged(fine.quads.size());
    std::vector<std::pair<double, int>> far;
    // Only two things of the queries are used: which input vertices are far (farther than threshold_mm),
    // and the charged lists of the quads around the nodes those far vertices may pull. A vertex within
    // threshold_mm - kBoundMargin of the quad it had last round (an upper bound of its distance to the
    // quads) is not far; and it can be charged to a quad only if it lies within that bound of the quad's
    // bounding box. So only the other vertices, and those near the quads whose lists are read, are queried
    // (the first round queries all); the queried answers, far list and lists read are the full scan's.
    // Slivers among the fan triangles (a degenerate quad) could put a closest point off its triangle by
    // more than the margin: then every vertex is queried.
    bool bounded = true;
    for (const auto& t : fan.triangles)
      bounded =
          bounded && triangle_box(fan.vertices[t[0]], fan.vertices[t[1]], fan.vertices[t[2]]).lo[0] > -1e300;
    std::vector<char> queried(s.surface.vertices.size(), 0);
    // The distance of p to the fan triangles of quad q (to well within kBoundMargin when bounded).
    auto quad_distance = [&](const Vec3& p, int q) {
      double d = std::numeric_limits<double>::infinity();
      for (int k = 0; k < 4; ++k) {
        const auto& t = fan.triangles[4 * q + k];
        d = std::min(
            d,
            norm(sub(p, closest_on_triangle(p, fan.vertices[t[0]], fan.vertices[t[1]], fan.vertices[t[2]]))));
      }
      return d;
    };
    std::vector<double> bound(s.surface.vertices.size());  // of the unqueried vertices' distances
    parallel_for(s.surface.vertices.size(), s.threads, [&](std::size_t i) {
      const Vec3& p = s.surface.vertices[i];
      if (bounded && nearest_quad[i] >= 0) {
        bound[i] = quad_distance(p, nearest_quad[i]);
        if (bound[i] <= threshold_mm - kBoundMargin) return;
      }
      const SurfacePoint sp = quad_projector.closest(p);
      nearest_quad[i] = sp.triangle / 4;
      distance[i] = sp.distance;
      queried[i] = 1;
    });
    // The quads whose charged lists may be read: those around the free nodes of the far vertices' quads.
    std::vector<char> read(fine.quads.size(), 0);
    for (std::size_t i = 0; i < s.surface.vertices.size(); ++i)
      if (queried[i] && distance[i] > threshold_mm)
        for (int v : fine.quads[nearest_quad[i]])
          for (int q : vertex_quads[v]) read[q] = 1;
    std::vector<char> near_read(s.surface.vertices.size(), 0);
    for (std::size_t q = 0; q < fine.quads.size(); ++q) {
      if (!read[q]) continue;
      Box box{{1e300, 1e300, 1e300}, {-1e300, -1e300, -1e300}};
      for (int k = 0; k < 4; ++k)
        for (int c : fan.triangles[4 * q + k])
          for (int a = 0; a < 3; ++a) {
            box.lo[a] = std::min(box.lo[a], fan.vertices[c][a]);
            box.hi[a] = std::max(box.hi[a], fan.vertices[c][a]);
          }
      for (int a = 0; a < 3; ++a) {
        box.lo[a] -= threshold_mm + kBoundMargin;
        box.hi[a] += threshold_mm + kBoundMargin;
      }
      vertex_grid.for_each_in_box(box.lo, box.hi, [&](int i) {
        // Its closest point lies on quad q only if q is within its distance bound.
        if (!queried[i] && !near_read[i] &&
            quad_distance(s.surface.vertices[i], static_cast<int>(q)) <= bound[i] + kBoundMargin)
          near_read[i] = 1;
      });
    }
    parallel_for(s.surface.vertices.size(), s.threads, [&](std::size_t i) {
      if (queried[i] || !near_read[i]) return;
      const SurfacePoint sp = quad_projector.closest(s.surface.vertices[i]);
      nearest_quad[i] = sp.triangle / 4;
      distance[i] = sp.distance;
      queried[i] = 1;
    });
    bool all = true;
    for (std::size_t i = 0; i < s.surface.vertices.size(); ++i) {
      if (!queried[i]) {
        all = false;
        continue;
      }
      charged[nearest_quad[i]].push_back(static_cast<int>(i));
      if (distance[i] > threshold_mm) far.push_back({-distance[i], static_cast<int>(i)});
    }
    std::sort(far.begin(), far.end());
    std::vector<char> touched(fine.quads.size(), 0);
    int moved = 0;
    for (const auto& [negative_distance, i] : far) {
      const Vec3& p = s.surface.vertices[i];
      const int q0 = nearest_quad[i];  // the same query as above, on the same quads
      if (touched[q0]) continue;       // its quads changed this round: the distances are stale
      // Moves v to goal if that keeps the local quality and lowers the local error (then v is fixed).
      auto try_move = [&](int v, const Vec3& goal) {
        const std::vector<int>& quads = vertex_quads[v];
        // Local error: the largest distance of p and of the input vertices charged to v's quads to those
        // quads, and of the quads' sampled points to the input (cached per quad); local quality: the
        // smallest corner scaled Jacobian of v's quads.
        // The largest distance of the charged vertices; once it reaches `stop`, that value (a larger one
        // does not matter to the caller).
        auto charged_max = [&](double stop) {
          const Fan fan = fan_of(quads);
          double e = 0;
          for (int q : quads)
            for (int j : charged[q]) {
              e = std::max(e, distance_to_fan(s.surface.vertices[j], fan));
              if (e >= stop) return e;
            }
          return e;
        };
        auto quality = [&]() {
          double m = 1.0;
          for (int q : quads)
            for (int k = 0; k < 4; ++k)
              m = std::min(m, corner_jacobian(fine, fine.quads[q], k, *surface_normal));
          return m;
        };
        if (cached_at[v] != state) {
          cached_charged[v] = charged_max(std::numeric_limits<double>::infinity());
          cached_quality[v] = quality();
          cached_at[v] = state;
        }
        // The maximum is exact in any order: the same value as p's distance, then the charged ones.
        double before = std::max(distance_to_fan(p, fan_of(quads)), cached_charged[v]);
        for (int q : quads) before = std::max(before, sample_error[q]);
        const double before_quality = cached_quality[v];
        const Vec3 old_point = fine.vertices[v], old_normal = (*surface_normal)[v];
        fine.vertices[v] = goal;
        (*surface_normal)[v] = s.projector.closest(goal).normal;
        auto lowers_error = [&]() {
          const double limit = before - 1e-6;
          return distance_to_fan(p, fan_of(quads)) < limit && charged_max(limit) < limit;
        };
        if (quality() >= std::min(before_quality, kSnapQuality) && lowers_error()) {
          std::vector<double> after_samples;
          double after = 0;
          for (int q : quads) {
            after_samples.push_back(sampled_error(q));
            after = std::max(after, after_samples.back());
          }
          if (after < before - 1e-6) {
            for (std::size_t k = 0; k < quads.size(); ++k) {
              sample_error[quads[k]] = after_samples[k];
              touched[quads[k]] = 1;
            }
            fixed[v] = 1;
            ++moved;
            ++state;
            return true;
          }
        }
        fine.vertices[v] = old_point;
        (*surface_normal)[v] = old_normal;
        return false;
      };
      // The free nodes of that quad, nearest first, each moved all the way onto p, then 3/4 and 1/2 of the
      // way (restricted projection); the first move kept ends the search.
      std::array<int, 4> nodes = fine.quads[q0];
      std::sort(nodes.begin(), nodes.end(), [&](int x, int y) {
        return std::pair{norm(sub(fine.vertices[x], p)), x} < std::pair{norm(sub(fine.vertices[y], p)), y};
      });
      bool kept = false;
      for (int v : nodes) {
        for (double fraction : {1.0, 0.75, 0.5}) {
          if (kept || fixed[v]) break;
          Vec3 goal = p;
          if (fraction < 1.0) {
            const SurfacePoint partial =
                s.oriented.closest(add(fine.vertices[v], scale(sub(p, fine.vertices[v]), fraction)),
                                   (*surface_normal)[v], Vec3{0, 0, 0});
            if (partial.triangle < 0) continue;
            goal = partial.point;
          }
          kept = try_move(v, goal);
        }
      }
    }
    if (moved == 0) {
      // The vertices not queried this round are nearer than threshold_mm: -1 stands for their distance.
      for (std::size_t i = 0; i < distance.size(); ++i)
        if (!queried[i]) distance[i] = -1;
      settled->swap(distance);
      break;
    }
  }
}

// What step 9 measures of a placed surface: the far points (input vertices farther than threshold_mm from
// the quads, and the closest surface points of quad sample points (5 x 5 per quad, as step 10) farther
// than that from the input, each with its distance; farthest first), the Hausdorff distance and the
// centres of the folded quads (as step 10 counts them).
// Whether distances of the input vertices to the quads, -1 for those only known to lie nearer than
// threshold_mm, give the largest distance and its first vertex: when one of them is farther than that.
bool complete_enough(const std::vector<double>& distance, double threshold_mm) {
  if (distance.empty()) return false;
  double largest = 0;
  bool unknown = false;
  for (double d : distance) {
    largest = std::max(largest, d);
    unknown = unknown || d < 0;
  }
  return !unknown || largest > threshold_mm;
}

struct FarPoints {
  std::vector<std::pair<double, Vec3>> far;  // (-distance, point)
  std::vector<double> input_distance;        // of each input vertex to the quads
  double hausdorff = 0;
  std::vector<Vec3> folded;
  // The largest distance of the far points within `radius` of p (0 when there is none).
  double near(const Vec3& p, double radius) const {
    double d = 0;
    for (const auto& [negative_distance, q] : far)
      if (norm(sub(q, p)) <= radius) d = std::max(d, -negative_distance);
    return d;
  }
};

// known: the distances of the input vertices to these quads when snap_features() measured them (the same
// closest-point queries on the same tree: SurfaceProjector::distance() is closest().distance, bit for bit;
// -1 for a vertex nearer than threshold_mm), or empty. Measured afresh unless complete_enough().
FarPoints measure_far(const QuadSurface& fine, const PlacementSurface& s, double threshold_mm,
                      std::vector<double> known) {
  FarPoints r;
  r.input_distance = std::move(known);
  if (!complete_enough(r.input_distance, threshold_mm)) {
    const SurfaceProjector quad_projector(fan_triangles(fine));
    r.input_distance.resize(s.surface.vertices.size());
    parallel_for(s.surface.vertices.size(), s.threads, [&](std::size_t i) {
      r.input_distance[i] = quad_projector.distance(s.surface.vertices[i]);
    });
  }
  for (std::size_t i = 0; i < s.surface.vertices.size(); ++i) {
    const double d = r.input_distance[i];
    r.hausdorff = std::max(r.hausdorff, d);
    if (d > threshold_mm) r.far.push_back({-d, s.surface.vertices[i]});
  }
  // The 25 sample points of each quad and the input normals at its corners, then in quad order.
  std::vector<SurfacePoint> samples(fine.quads.size() * 25);
  std::vector<Vec3> corner_normal(fine.quads.size() * 4);
  parallel_for(fine.quads.size() * 29, s.threads, [&](std::size_t n) {
    const auto& quad = fine.quads[n / 29];
    const int m = static_cast<int>(n % 29);
    if (m < 25)
      samples[n / 29 * 25 + m] = s.projector.closest(bilinear(fine, quad, (m % 5) / 4.0, (m / 5) / 4.0));
    else
      corner_normal[n / 29 * 4 + (m - 25)] = s.projector.closest(fine.vertices[quad[m - 25]]).normal;
  });
  for (std::size_t q = 0; q < fine.quads.size(); ++q) {
    const auto& quad = fine.quads[q];
    for (int m = 0; m < 25; ++m) {
      const SurfacePoint& sp = samples[q * 25 + m];
      r.hausdorff = std::max(r.hausdorff, sp.distance);
      if (sp.distance > threshold_mm) r.far.push_back({-sp.distance, sp.point});
    }
    for (int k = 0; k < 4; ++k) {
      const Vec3& p = fine.vertices[quad[k]];
      const Vec3 n =
          cross(sub(fine.vertices[quad[(k + 1) % 4]], p), sub(fine.vertices[quad[(k + 3) % 4]], p));
      if (dot(n, corner_normal[q * 4 + k]) <= 0) {
        r.folded.push_back(bilinear(fine, quad, 0.5, 0.5));
        break;
      }
    }
  }
  std::sort(r.far.begin(), r.far.end(), [](const auto& x, const auto& y) {
    return std::tie(x.first, x.second) < std::tie(y.first, y.second);
  });
  return r;
}

// Fidelity refinement (step 9). Each round: the far points within fidelity_band_mm of the current
// Hausdorff distance, thinned so that no two lie within fidelity_join_edges mean edges, are the centres of
// one refine_quads_locally() call (mesher/quad_local_refinement.h: one level, radius fidelity_radius_edges
// mean edges; the fixed nodes, landmark and snapped ones, stay); the refined surface is relaxed on the
// moved and new nodes (fidelity_relax_sweeps, as step 6), untangled (step 7) and snapped (step 8). The
// centres where a quad folded within radius + 1 edge, or where the far points within that reach did not
// get nearer, are dropped and the round is redone from the surface before it (up to fidelity_passes
// times); a round whose centres all stay is kept when it lowers the Hausdorff distance without more folded
// quads, else the refinement stops. The rungs of kept rings go to report->ring_rungs, latest first.
// settled: as snap_features() gives it for `fine`; on return, the distances of the input vertices to the
// returned quads.
void refine_for_fidelity(QuadSurface& fine, const PlacementSurface& s, std::vector<char>& fixed,
                         std::vector<Vec3>* surface_normal, const MandibleQuadOptions& o,
                         MandibleQuadReport* report, std::vector<double>* settled) {
  report->fidelity_goal_mm = o.snap_threshold_mm;
  FarPoints current = measure_far(fine, s, o.snap_threshold_mm, std::move(*settled));
  *settled = current.input_distance;
  if (current.hausdorff > o.max_hausdorff_mm) return;  // not a mandible: step 10 rejects it
  const int quads_before = static_cast<int>(fine.quads.size());
  const QuadSurface fine_before = fine;
  const std::vector<char> fixed_before = fixed;
  const std::vector<Vec3> normal_before = *surface_normal;
  for (int round = 0; round < o.fidelity_rounds && !current.far.empty(); ++round) {
    const QuadEdges edges = build_quad_edges(fine.quads);
    double edge = 0;
    for (const auto& e : edges.edges) edge += norm(sub(fine.vertices[e[1]], fine.vertices[e[0]]));
    edge /= edges.edges.size();
    LocalRefinementOptions refinement;
    for (const auto& [negative_distance, p] : current.far)
      if (-negative_distance >= current.hausdorff - o.fidelity_band_mm &&
          std::none_of(refinement.points.begin(), refinement.points.end(),
                       [&](const Vec3& c) { return norm(sub(p, c)) <= o.fidelity_join_edges * edge; }))
        refinement.points.push_back(p);
    refinement.radius_mm = std::clamp(o.fidelity_radius_edges * edge, kMinRefineRadiusMm, kMaxRefineRadiusMm);
    refinement.levels = 1;
    const double reach = refinement.radius_mm + edge;
    std::vector<int> held;
    for (std::size_t v = 0; v < fixed.size(); ++v)
      if (fixed[v]) held.push_back(static_cast<int>(v));
    bool kept_round = false;
    for (int pass = 0; pass < o.fidelity_passes && !refinement.points.empty(); ++pass) {
      LocalRefinementReport refined;
      QuadSurface trial;
      try {
        trial = refine_quads_locally(fine, s.projector, held, refinement, &refined);
      } catch (const InputError&) {
        break;  // the patches would cover the whole surface (a very coarse target): no ring
      }
      std::vector<char> trial_fixed = fixed, frozen(trial.vertices.size(), 0);
      for (std::size_t v = 0; v < fine.vertices.size(); ++v)
        frozen[v] = fixed[v] || fine.vertices[v] == trial.vertices[v];
      trial_fixed.resize(trial.vertices.size(), 0);
      std::vector<Vec3> trial_normal(trial.vertices.size());
      for (std::size_t v = 0; v < trial.vertices.size(); ++v)
        trial_normal[v] = s.projector.closest(trial.vertices[v]).normal;
      relax(trial, s, frozen, o.fidelity_relax_sweeps, &trial_normal);
      unfold(trial, s, trial_fixed, o.unfold_sweeps, &trial_normal);
      std::vector<double> trial_settled;
      snap_features(trial, s, trial_fixed, o.snap_rounds, o.snap_threshold_mm, &trial_normal, &trial_settled);
      const FarPoints next = measure_far(trial, s, o.snap_threshold_mm, std::move(trial_settled));
      std::vector<Vec3> kept;
      for (const Vec3& p : refinement.points)
        if (std::none_of(next.folded.begin(), next.folded.end(),
                         [&](const Vec3& f) { return norm(sub(f, p)) <= reach; }) &&
            next.near(p, reach) < current.near(p, reach))
          kept.push_back(p);
      if (kept.size() < refinement.points.size()) {
        refinement.points = kept;
        continue;
      }
      if (next.hausdorff < current.hausdorff - 1e-6 && next.folded.size() <= current.folded.size()) {
        fine = std::move(trial);
        fixed = std::move(trial_fixed);
        *surface_normal = std::move(trial_normal);
        report->ring_rungs.insert(report->ring_rungs.begin(), refined.ring_rungs.begin(),
                                  refined.ring_rungs.end());
        current = next;
        ++report->fidelity_rounds;
        kept_round = true;
      }
      break;
    }
    if (!kept_round) break;
  }
  // Rings that do not bring the quads within snap_threshold_mm are undone: on the real jaw they gained
  // 0.2 mm (landmarks, 1.66 -> 1.48 mm) at the cost of the hex mesh's mean (0.854 -> 0.847), and 0.4 mm
  // (1.42 -> 1.003 mm) with a mesh boundary slid 6.95 mm from the input instead of 3.69 mm.
  if (current.hausdorff > o.snap_threshold_mm && report->fidelity_rounds > 0) {
    fine = fine_before;
    fixed = fixed_before;
    *surface_normal = normal_before;
    report->ring_rungs.clear();
    report->fidelity_undone_rounds = report->fidelity_rounds;
    report->fidelity_rounds = 0;
  } else {
    *settled = current.input_distance;
  }
  report->fidelity_quads_added = static_cast<int>(fine.quads.size()) - quads_before;
}

}  // namespace

int quads_for_target_hexes(long target_hexes) {
  const double q = 1300.0 * std::pow(static_cast<double>(target_hexes) / 2500.0, 2.0 / 3.0);
  return std::max(24, 2 * static_cast<int>(std::lround(q / 2)));
}

QuadSurface quad_surface_from_mandible(const TriSurface& surface, const Landmarks* landmarks,
                                       const std::string& landmark_file, const MandibleQuadOptions& options,
                                       MandibleQuadReport* report_out) {
  const auto t0 = std::chrono::steady_clock::now();
  if (options.target_quads < 24 || options.target_quads > 200000)
    throw InputError("--target-quads " + std::to_string(options.target_quads) +
                     " is out of range: give a number from 24 to 200,000");
  // The template is an adult mandible about 100 mm across and its tolerances are in mm: a bone read in the
  // wrong unit would be warped to a tenth of a millimetre or a metre, and its relaxation can then run for
  // minutes. (The grid method meshes any size.)
  if (const double extent = largest_extent(surface); extent < 30.0 || extent > 300.0) {
    const InputTerms& terms = options.terms;
    char text[256];
    std::snprintf(text, sizeof text,
                  "the surface is %.4g mm across (the largest side of its bounding box) with its coordinates "
                  "read as %s, but the mandible template places on mandibles 30 to 300 mm across: ",
                  extent, terms.surface_unit.c_str());
    // The unit that gives a mandible's size, as the size warnings name it (a file in mm read as cm is ten
    // times too large, and "--units m or cm" pointed the wrong way).
    const std::string fix = unit_that_fits(extent, terms.surface_unit, 30.0, 300.0, terms.units);
    throw InputError(text +
                     (fix.empty()
                          ? "no unit of mm, cm or m gives such a size: scale the file to millimetres first"
                          : "if " + fix) +
                     "; or use " + terms.grid_method);
  }
  MandibleQuadReport report;
  Progress progress("quad surface");
  const MandibleQuadTemplate tmpl = mandible_quad_template();
  report.macro_quads = static_cast<int>(tmpl.macro.quads.size());

  // 1-2. Correspondence and warp.
  const Correspondence corr = correspond(tmpl, surface, landmarks, landmark_file, options.terms);
  report.placement = landmarks ? "landmarks" : "extreme points";
  report.matched_points = corr.names;
  std::vector<double> lambda(corr.names.size());
  for (std::size_t i = 0; i < lambda.size(); ++i)
    lambda[i] = !landmarks                                              ? options.extreme_smoothing_mm
                : corr.names[i].find(".insertion") != std::string::npos ? options.insertion_smoothing_mm
                                                                        : options.landmark_smoothing_mm;
  const ThinPlateSpline first_warp(corr.sources, corr.targets, lambda);
  Correspondence all = corr;
  const std::map<std::string, Vec3> features =
      derive_points(surface, tmpl, first_warp, landmark_midline_x(landmarks));
  for (const auto& [name, p] : features) {
    all.names.push_back(name);
    all.sources.push_back(tmpl.derived.at(name));
    all.targets.push_back(p);
    lambda.push_back(options.landmark_smoothing_mm);
  }
  const ThinPlateSpline warp(all.sources, all.targets, lambda);
  for (std::size_t i = 0; i < corr.sources.size(); ++i)
    report.warp_residual_mm =
        std::max(report.warp_residual_mm, norm(sub(warp(corr.sources[i]), corr.targets[i])));
  QuadSurface macro = tmpl.macro;
  for (Vec3& v : macro.vertices) v = warp(v);
  progress.update(0.1, "warped");

  // 3. Chord subdivision counts from the warped rung lengths.
  const QuadEdges macro_edges = build_quad_edges(macro.quads);
  const std::vector<Chord> chords = find_chords(macro.quads, macro_edges);
  std::vector<int> edge_chord(macro_edges.edges.size(), -1);
  std::vector<double> chord_length(chords.size(), 0.0);
  for (std::size_t c = 0; c < chords.size(); ++c) {
    for (int e : chords[c].edges) {
      edge_chord[e] = static_cast<int>(c);
      chord_length[c] +=
          norm(sub(macro.vertices[macro_edges.edges[e][1]], macro.vertices[macro_edges.edges[e][0]]));
    }
    chord_length[c] /= chords[c].length();
  }
  std::vector<std::array<int, 2>> quad_chords(macro.quads.size());
  for (std::size_t q = 0; q < macro.quads.size(); ++q)
    quad_chords[q] = {edge_chord[macro_edges.quad_edges[q][0]], edge_chord[macro_edges.quad_edges[q][1]]};
  // The chord through the bone (lingual to buccal) gets an odd count: with an even one a row of quad nodes
  // runs along the mid-line of every rim, which on a thin rim is its crest (the real jaw's coronoid blade is
  // 1.3 mm thick, its sigmoid notch rims about as thin). The quads there fold by about 124 degrees across
  // the node and no pillow hex corner at it gets much above 0.3: with 2 quads through the bone the real
  // jaw's mesh had a scaled Jacobian of 0.230 at the notch rims and coronoid tips, with 3 0.335
  // (docs/mandible_quads.md). With an odd count a quad lies across the crest.
  std::vector<char> odd(chords.size(), 0);
  {
    const int lingual = tmpl.key_nodes.at("symphysis_top_lingual"),
              buccal = tmpl.key_nodes.at("symphysis_top_buccal");
    for (std::size_t e = 0; e < macro_edges.edges.size(); ++e)
      if (std::minmax(macro_edges.edges[e][0], macro_edges.edges[e][1]) == std::minmax(lingual, buccal))
        odd[edge_chord[e]] = 1;
  }
  const std::vector<int> counts = chord_counts(chords, chord_length, quad_chords, options.target_quads, odd);
  std::vector<int> edge_count(macro_edges.edges.size());
  for (std::size_t e = 0; e < edge_count.size(); ++e) edge_count[e] = counts[edge_chord[e]];

  // 4. Refinement and restricted projection.
  QuadSurface fine = refine(macro, macro_edges, edge_count);
  std::vector<char> fixed(fine.vertices.size(), 0);
  const PlacementSurface target(surface, options.threads);
  const SurfaceProjector& projector = target.projector;
  std::vector<Vec3> surface_normal = project(fine, target);
  progress.update(0.3, "refined");

  // 5. Landmark nodes, fixed from here on.
  if (landmarks)
    for (const auto& [name, p] : landmarks->points) {
      const SurfacePoint on_surface = projector.closest(p);
      int best = -1;
      double best_d = std::numeric_limits<double>::infinity();
      for (std::size_t v = 0; v < fine.vertices.size(); ++v) {
        const double d = norm(sub(fine.vertices[v], on_surface.point));
        if (!fixed[v] && d < best_d) {
          best_d = d;
          best = static_cast<int>(v);
        }
      }
      fine.vertices[best] = on_surface.point;
      surface_normal[best] = on_surface.normal;
      fixed[best] = 1;
      report.landmark_nodes.push_back({name, norm(sub(on_surface.point, p))});
      report.landmark_vertices.push_back(best);
    }

  // 6-8. Relaxation, untangling and feature snapping on the target.
  relax(fine, target, fixed, options.relax_sweeps, &surface_normal);
  unfold(fine, target, fixed, options.unfold_sweeps, &surface_normal);
  std::vector<double> settled;  // distances of the input vertices to the quads, when known
  snap_features(fine, target, fixed, options.snap_rounds, options.snap_threshold_mm, &surface_normal,
                &settled);
  progress.update(0.8, "relaxed");

  // 9. Fidelity refinement: one ring of quads around the regions still far from the quads, then snapping.
  refine_for_fidelity(fine, target, fixed, &surface_normal, options, &report, &settled);
  progress.update(0.9, "refined for fidelity");

  // 10. Fidelity.
  const QuadEdges fine_edges = build_quad_edges(fine.quads);
  double edge_sum = 0;
  for (const auto& e : fine_edges.edges) edge_sum += norm(sub(fine.vertices[e[1]], fine.vertices[e[0]]));
  report.mean_edge_mm = edge_sum / fine_edges.edges.size();
  for (const Vec3& v : fine.vertices)
    report.max_vertex_distance_mm = std::max(report.max_vertex_distance_mm, projector.distance(v));
  Vec3 worst_quad{0, 0, 0};
  for (const auto& quad : fine.quads)
    for (int j = 0; j <= 4; ++j)
      for (int i = 0; i <= 4; ++i) {
        const Vec3 p = bilinear(fine, quad, i / 4.0, j / 4.0);
        const double d = projector.distance(p);
        if (d > report.quads_to_surface_mm) {
          report.quads_to_surface_mm = d;
          worst_quad = p;
        }
      }
  if (!complete_enough(settled, options.snap_threshold_mm)) {
    const SurfaceProjector quad_projector(fan_triangles(fine));
    settled.resize(surface.vertices.size());
    parallel_for(surface.vertices.size(), options.threads,
                 [&](std::size_t i) { settled[i] = quad_projector.distance(surface.vertices[i]); });
  }
  Vec3 worst_surface{0, 0, 0};
  for (std::size_t i = 0; i < surface.vertices.size(); ++i) {
    const double d = settled[i];
    if (d > report.surface_to_quads_mm) {
      report.surface_to_quads_mm = d;
      worst_surface = surface.vertices[i];
    }
  }
  report.hausdorff_mm = std::max(report.quads_to_surface_mm, report.surface_to_quads_mm);
  report.worst_quad_point = worst_quad;
  report.worst_surface_point = worst_surface;
  for (const auto& quad : fine.quads)
    for (int k = 0; k < 4; ++k) {
      const Vec3& p = fine.vertices[quad[k]];
      const Vec3 n =
          cross(sub(fine.vertices[quad[(k + 1) % 4]], p), sub(fine.vertices[quad[(k + 3) % 4]], p));
      if (dot(n, projector.closest(p).normal) <= 0) {
        ++report.folded_quads;
        break;
      }
    }
  if (report.hausdorff_mm > options.max_hausdorff_mm) {
    const bool missed = report.surface_to_quads_mm >= report.quads_to_surface_mm;
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.1f mm", report.hausdorff_mm);
    throw InputError(
        std::string("the surface does not fit the mandible template: the placed quad surface is ") + buf +
        (missed ? " away from the surface at " + format_point_mm(worst_surface)
                : " off the surface at " + format_point_mm(worst_quad)) +
        " (limit " + std::to_string(static_cast<int>(options.max_hausdorff_mm)) +
        " mm). The surface must be a whole mandible in the generator's frame (+x subject's left, "
        "+y posterior, +z superior, mm)" +
        (landmarks ? " with landmarks in the same frame"
                   : "; " + options.terms.landmarks + " helps place it") +
        ", or use " + options.terms.grid_method);
  }
  report.quads = static_cast<int>(fine.quads.size());
  const std::vector<Chord> fine_chords = find_chords(fine.quads, fine_edges);
  report.chords = static_cast<int>(fine_chords.size());
  for (const Chord& c : fine_chords) report.max_chord_length = std::max(report.max_chord_length, c.length());
  report.seconds = seconds_since(t0);
  progress.finish();
  if (report_out) *report_out = report;
  return fine;
}

std::vector<Vec3> quad_vertex_normals(const QuadSurface& quads) {
  return vertex_normals(quads);
}

}  // namespace hexbite
