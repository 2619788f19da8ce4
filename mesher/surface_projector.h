// Closest-point, distance, inside and ray queries against a closed triangle surface.
//
// Input: a TriSurface (closed and outward oriented for inside() and normals to be meaningful).
// A triangle that the halfedge structure rejects (a non-manifold soup, such as the boundary of a
// non-manifold hex mesh) is still stored for closest-point queries, on its own vertices.
// Output: per query, the closest surface point, its distance, the unit normal of the triangle that
// holds it, whether a point is inside the enclosed solid, and the first hit of a ray.
// Cost: building is O(m log m) for m triangles (a CGAL AABB tree, built eagerly in the constructor);
// each query is O(log m) on average. All queries are const and safe to call from several threads at
// once, because the tree and its distance accelerator are built before the constructor returns.
#pragma once

#include <memory>
#include <vector>

#include "mesher/tri_surface.h"

namespace hexbite {

struct SurfacePoint {
  Vec3 point{};         // closest point on the surface
  Vec3 normal{};        // unit outward normal of the triangle that holds `point`
  int triangle = -1;    // index of that triangle in the TriSurface
  double distance = 0;  // |query - point|
};

class SurfaceProjector {
 public:
  explicit SurfaceProjector(const TriSurface& surface);
  ~SurfaceProjector();
  SurfaceProjector(const SurfaceProjector&) = delete;
  SurfaceProjector& operator=(const SurfaceProjector&) = delete;

  SurfacePoint closest(const Vec3& query) const;
  // The same closest point, found faster when `hint` (a point on the surface with its triangle, such as an
  // earlier answer for a nearby query) is close to it: the search starts from the hint instead of the
  // tree's own first guess. Equidistant candidates may resolve to a different triangle than closest(query).
  SurfacePoint closest(const Vec3& query, const SurfacePoint& hint) const;
  double distance(const Vec3& query) const;
  // True when the query lies strictly inside the solid (points on the surface count as outside).
  bool inside(const Vec3& query) const;
  // First intersection of the ray origin + t * direction, 0 < t <= max_t, with the surface; returns
  // false when there is none. `hit` receives the point, the triangle and its normal, and t as distance
  // (scaled by |direction|).
  bool first_hit(const Vec3& origin, const Vec3& direction, double max_t, SurfacePoint* hit) const;

  // Parameters t in [0, 1] of the points where the segment a + t (b - a) crosses the surface, ascending.
  // Returns false when the segment touches the surface in a degenerate way (along an edge, a vertex or
  // inside a triangle's plane), where crossing parity would be unreliable. With `triangles`, also the
  // crossed triangle of each parameter, in the same order.
  bool segment_crossings(const Vec3& a, const Vec3& b, std::vector<double>* t,
                         std::vector<int>* triangles = nullptr) const;

  const TriSurface& surface() const { return surface_; }

 private:
  struct Impl;
  TriSurface surface_;
  std::unique_ptr<Impl> impl_;
};

// Volume enclosed by a closed, outward oriented triangle surface (divergence theorem).
double enclosed_volume(const TriSurface& surface);

}  // namespace hexbite
