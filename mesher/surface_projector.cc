#include "mesher/surface_projector.h"

#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Surface_mesh.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <utility>

#include "common/error.h"

namespace hexbite {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;
using Inside = CGAL::Side_of_triangle_mesh<Mesh, Kernel>;
using Tree = Inside::AABB_tree;

Vec3 to_vec(const Point& p) {
  return {p.x(), p.y(), p.z()};
}

}  // namespace

struct SurfaceProjector::Impl {
  Mesh mesh;
  std::vector<int> face_to_triangle;  // Surface_mesh face index -> TriSurface triangle index
  std::vector<int> triangle_to_face;  // the inverse
  std::vector<Vec3> normals;          // per TriSurface triangle
  std::unique_ptr<Tree> tree;
  std::unique_ptr<Inside> inside;

  SurfacePoint make_point(const Point& p, Mesh::Face_index f, const Vec3& query) const {
    SurfacePoint s;
    s.point = to_vec(p);
    s.triangle = face_to_triangle[f.idx()];
    s.normal = normals[s.triangle];
    const double dx = query[0] - s.point[0], dy = query[1] - s.point[1], dz = query[2] - s.point[2];
    s.distance = std::sqrt(dx * dx + dy * dy + dz * dz);
    return s;
  }
};

SurfaceProjector::SurfaceProjector(const TriSurface& surface) : surface_(surface), impl_(new Impl) {
  if (surface.triangles.empty()) throw InputError("surface projector: the surface has no triangles");
  std::vector<Mesh::Vertex_index> vertices;
  vertices.reserve(surface.vertices.size());
  for (const Vec3& v : surface.vertices) vertices.push_back(impl_->mesh.add_vertex(Point(v[0], v[1], v[2])));
  impl_->normals.resize(surface.triangles.size());
  for (std::size_t t = 0; t < surface.triangles.size(); ++t) {
    const auto& tri = surface.triangles[t];
    Mesh::Face_index f = impl_->mesh.add_face(vertices[tri[0]], vertices[tri[1]], vertices[tri[2]]);
    if (f == Mesh::null_face()) {
      // Not manifold here: keep the triangle's geometry for distance queries on its own vertices.
      Mesh::Vertex_index w[3];
      for (int i = 0; i < 3; ++i) {
        const Vec3& p = surface.vertices[tri[i]];
        w[i] = impl_->mesh.add_vertex(Point(p[0], p[1], p[2]));
      }
      f = impl_->mesh.add_face(w[0], w[1], w[2]);
    }
    if (impl_->face_to_triangle.size() <= f.idx()) impl_->face_to_triangle.resize(f.idx() + 1, -1);
    impl_->face_to_triangle[f.idx()] = static_cast<int>(t);
    impl_->triangle_to_face.push_back(static_cast<int>(f.idx()));
    const Vec3& a = surface.vertices[tri[0]];
    const Vec3& b = surface.vertices[tri[1]];
    const Vec3& c = surface.vertices[tri[2]];
    const Vec3 u{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    Vec3 n{u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (len > 0) n = {n[0] / len, n[1] / len, n[2] / len};
    impl_->normals[t] = n;
  }
  impl_->tree = std::make_unique<Tree>(faces(impl_->mesh).first, faces(impl_->mesh).second, impl_->mesh);
  impl_->tree->build();
  impl_->tree->accelerate_distance_queries();
  impl_->inside = std::make_unique<Inside>(*impl_->tree);
}

SurfaceProjector::~SurfaceProjector() = default;

SurfacePoint SurfaceProjector::closest(const Vec3& query) const {
  const auto pp = impl_->tree->closest_point_and_primitive(Point(query[0], query[1], query[2]));
  return impl_->make_point(pp.first, pp.second, query);
}

SurfacePoint SurfaceProjector::closest(const Vec3& query, const SurfacePoint& hint) const {
  if (hint.triangle < 0 || hint.triangle >= static_cast<int>(impl_->triangle_to_face.size()))
    return closest(query);
  const Tree::Point_and_primitive_id start(Point(hint.point[0], hint.point[1], hint.point[2]),
                                           Mesh::Face_index(impl_->triangle_to_face[hint.triangle]));
  const auto pp = impl_->tree->closest_point_and_primitive(Point(query[0], query[1], query[2]), start);
  return impl_->make_point(pp.first, pp.second, query);
}

double SurfaceProjector::distance(const Vec3& query) const {
  return std::sqrt(impl_->tree->squared_distance(Point(query[0], query[1], query[2])));
}

bool SurfaceProjector::inside(const Vec3& query) const {
  return (*impl_->inside)(Point(query[0], query[1], query[2])) == CGAL::ON_BOUNDED_SIDE;
}

bool SurfaceProjector::first_hit(const Vec3& origin, const Vec3& direction, double max_t,
                                 SurfacePoint* hit) const {
  const Point o(origin[0], origin[1], origin[2]);
  const Kernel::Ray_3 ray(o, Kernel::Vector_3(direction[0], direction[1], direction[2]));
  const auto result = impl_->tree->first_intersection(ray);
  if (!result) return false;
  const Point* p = boost::get<Point>(&result->first);
  if (p == nullptr) return false;  // the ray runs inside a triangle's plane: no single hit point
  const double dlen =
      std::sqrt(direction[0] * direction[0] + direction[1] * direction[1] + direction[2] * direction[2]);
  SurfacePoint s = impl_->make_point(*p, result->second, origin);
  if (!(dlen > 0) || s.distance / dlen > max_t) return false;
  if (hit != nullptr) *hit = s;
  return true;
}

bool SurfaceProjector::segment_crossings(const Vec3& a, const Vec3& b, std::vector<double>* t,
                                         std::vector<int>* triangles) const {
  const Kernel::Segment_3 seg(Point(a[0], a[1], a[2]), Point(b[0], b[1], b[2]));
  using Hit = Tree::Intersection_and_primitive_id<Kernel::Segment_3>::Type;
  std::vector<Hit> hits;
  impl_->tree->all_intersections(seg, std::back_inserter(hits));
  const Vec3 ab{b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double len2 = ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2];
  t->clear();
  std::vector<std::pair<double, int>> crossed;
  for (const Hit& h : hits) {
    const Point* p = boost::get<Point>(&h.first);
    if (p == nullptr) return false;
    const double tp = ((p->x() - a[0]) * ab[0] + (p->y() - a[1]) * ab[1] + (p->z() - a[2]) * ab[2]) / len2;
    if (triangles != nullptr)
      crossed.emplace_back(tp, impl_->face_to_triangle[h.second.idx()]);
    else
      t->push_back(tp);
  }
  if (triangles != nullptr) {
    std::sort(crossed.begin(), crossed.end());
    triangles->clear();
    for (const auto& [tp, tri] : crossed) t->push_back(tp), triangles->push_back(tri);
  }
  std::sort(t->begin(), t->end());
  // Two hits at the same point mean the segment passes through an edge or a vertex shared by triangles.
  for (std::size_t i = 1; i < t->size(); ++i)
    if ((*t)[i] - (*t)[i - 1] < 1e-12) return false;
  return t->size() % 2 == 0;
}

double enclosed_volume(const TriSurface& surface) {
  double six_v = 0;
  for (const auto& t : surface.triangles) {
    const Vec3& a = surface.vertices[t[0]];
    const Vec3& b = surface.vertices[t[1]];
    const Vec3& c = surface.vertices[t[2]];
    six_v += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
             a[2] * (b[0] * c[1] - b[1] * c[0]);
  }
  return six_v / 6.0;
}

}  // namespace hexbite
