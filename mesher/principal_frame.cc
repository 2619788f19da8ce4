#include "mesher/principal_frame.h"

#include <Eigen/Dense>
#include <cmath>
#include <map>
#include <tuple>
#include <vector>

namespace hexbite {

namespace {

Eigen::Vector3d eigen(const Vec3& v) {
  return {v[0], v[1], v[2]};
}
Vec3 vec(const Eigen::Vector3d& v) {
  return {v[0], v[1], v[2]};
}

struct Facet {
  Eigen::Vector3d normal;  // unit
  double area;
};

// The direction shared by the largest area of `facets` (normals of either sign), among those whose normal
// `keep` accepts, and that area. Written by hand (no library bins directions on a sphere): the normals,
// turned to one hemisphere, are binned in cubes of edge 0.05 (about 3 degrees); the heaviest bin with its
// 26 neighbours gives a mean direction, and the facets within 3 degrees of it give the result.
template <typename Keep>
std::pair<Eigen::Vector3d, double> heaviest_direction(const std::vector<Facet>& facets, Keep keep) {
  constexpr double kBin = 0.05;
  const double within = std::cos(3.0 * M_PI / 180.0);
  const auto hemisphere = [](Eigen::Vector3d n) {
    int a = 0;
    for (int k = 1; k < 3; ++k)
      if (std::abs(n[k]) > std::abs(n[a])) a = k;
    return n[a] < 0 ? Eigen::Vector3d(-n) : n;
  };
  std::map<std::tuple<long, long, long>, double> bins;
  const auto bin_of = [&](const Eigen::Vector3d& n) {
    return std::make_tuple(std::lround(n[0] / kBin), std::lround(n[1] / kBin), std::lround(n[2] / kBin));
  };
  for (const Facet& f : facets)
    if (keep(f.normal)) bins[bin_of(hemisphere(f.normal))] += f.area;
  if (bins.empty()) return {Eigen::Vector3d::Zero(), 0.0};
  auto best = bins.begin();
  for (auto it = bins.begin(); it != bins.end(); ++it)
    if (it->second > best->second) best = it;
  const auto [bx, by, bz] = best->first;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Facet& f : facets) {
    if (!keep(f.normal)) continue;
    const Eigen::Vector3d n = hemisphere(f.normal);
    const auto [x, y, z] = bin_of(n);
    if (std::abs(x - bx) <= 1 && std::abs(y - by) <= 1 && std::abs(z - bz) <= 1) mean += f.area * n;
  }
  mean.normalize();
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();
  double area = 0;
  for (const Facet& f : facets)
    if (keep(f.normal) && std::abs(f.normal.dot(mean)) >= within) {
      direction += f.area * (f.normal.dot(mean) < 0 ? Eigen::Vector3d(-f.normal) : f.normal);
      area += f.area;
    }
  return {direction.normalized(), area};
}

}  // namespace

Vec3 PrincipalFrame::to_frame(const Vec3& body) const {
  const Vec3 d{body[0] - centre[0], body[1] - centre[1], body[2] - centre[2]};
  Vec3 out{};
  for (int a = 0; a < 3; ++a) out[a] = d[0] * axes[a][0] + d[1] * axes[a][1] + d[2] * axes[a][2];
  return out;
}

Vec3 PrincipalFrame::to_body(const Vec3& frame) const {
  Vec3 out = centre;
  for (int a = 0; a < 3; ++a)
    for (int k = 0; k < 3; ++k) out[k] += frame[a] * axes[a][k];
  return out;
}

bool PrincipalFrame::along_coordinate_axes(double degrees) const {
  const double cosine = std::cos(degrees * M_PI / 180.0);
  for (const Vec3& axis : axes)
    if (std::max({std::abs(axis[0]), std::abs(axis[1]), std::abs(axis[2])}) < cosine) return false;
  return true;
}

std::optional<PrincipalFrame> principal_frame(const TriSurface& surface) {
  // The exact first and second moments of the surface's area: over a triangle of area A with corners
  // v1, v2, v3 (sum s), the integral of x is A s / 3 and that of x x^T is A / 12 (sum vi vi^T + s s^T).
  double area = 0;
  Eigen::Vector3d first = Eigen::Vector3d::Zero();
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
  for (const auto& t : surface.triangles) {
    const Eigen::Vector3d a = eigen(surface.vertices[t[0]]), b = eigen(surface.vertices[t[1]]),
                          c = eigen(surface.vertices[t[2]]);
    const double w = 0.5 * (b - a).cross(c - a).norm();
    const Eigen::Vector3d sum = a + b + c;
    area += w;
    first += w / 3.0 * sum;
    second += w / 12.0 * (a * a.transpose() + b * b.transpose() + c * c.transpose() + sum * sum.transpose());
  }
  if (!(area > 0)) return std::nullopt;
  const Eigen::Vector3d centre = first / area;
  const Eigen::Matrix3d moments = second - area * centre * centre.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(moments / area);
  const Eigen::Vector3d values = solver.eigenvalues();  // ascending
  Eigen::Matrix3d vectors = solver.eigenvectors();
  const double largest = values[2];
  if (!(largest > 0)) return std::nullopt;
  const auto close = [&](int i, int j) { return std::abs(values[i] - values[j]) < 0.05 * largest; };
  if (close(0, 1) && close(1, 2)) return std::nullopt;
  // A plane of two equal moments: its axes along the coordinate axis nearest to it, and that axis turned.
  for (const auto& [i, j, k] : {std::array<int, 3>{0, 1, 2}, std::array<int, 3>{1, 2, 0}}) {
    if (!close(i, j)) continue;
    const Eigen::Vector3d normal = vectors.col(k);
    Eigen::Vector3d best = Eigen::Vector3d::Zero();
    for (int a = 0; a < 3; ++a) {
      const Eigen::Vector3d in_plane =
          Eigen::Vector3d::Unit(a) - Eigen::Vector3d::Unit(a).dot(normal) * normal;
      if (in_plane.norm() > best.norm()) best = in_plane;
    }
    vectors.col(i) = best.normalized();
    vectors.col(j) = normal.cross(vectors.col(i));
  }
  if (vectors.determinant() < 0) vectors.col(0) = -vectors.col(0);
  PrincipalFrame frame;
  frame.centre = vec(centre);
  for (int a = 0; a < 3; ++a) frame.axes[a] = vec(vectors.col(a));
  return frame;
}

std::optional<PrincipalFrame> face_frame(const TriSurface& surface) {
  std::vector<Facet> facets;
  facets.reserve(surface.triangles.size());
  double total = 0;
  Eigen::Vector3d first = Eigen::Vector3d::Zero();
  for (const auto& t : surface.triangles) {
    const Eigen::Vector3d a = eigen(surface.vertices[t[0]]), b = eigen(surface.vertices[t[1]]),
                          c = eigen(surface.vertices[t[2]]);
    const Eigen::Vector3d cross = (b - a).cross(c - a);
    const double area = 0.5 * cross.norm();
    if (!(area > 0)) continue;
    facets.push_back({cross.normalized(), area});
    total += area;
    first += area / 3.0 * (a + b + c);
  }
  if (!(total > 0)) return std::nullopt;
  const auto heaviest_z = heaviest_direction(facets, [](const Eigen::Vector3d&) { return true; });
  if (heaviest_z.second < 0.1 * total) return std::nullopt;
  const Eigen::Vector3d z = heaviest_z.first;
  const double across = std::sin(3.0 * M_PI / 180.0);
  const auto [x_raw, x_area] = heaviest_direction(
      facets, [&z, across](const Eigen::Vector3d& n) { return std::abs(n.dot(z)) <= across; });
  if (x_area < 0.1 * total) return std::nullopt;
  const Eigen::Vector3d x = (x_raw - x_raw.dot(z) * z).normalized();
  PrincipalFrame frame;
  frame.centre = vec(first / total);
  frame.axes = {vec(x), vec(z.cross(x)), vec(z)};
  return frame;
}

bool same_axes(const PrincipalFrame& a, const PrincipalFrame& b, double degrees) {
  const double cosine = std::cos(degrees * M_PI / 180.0);
  for (const Vec3& u : a.axes) {
    double best = 0;
    for (const Vec3& v : b.axes) best = std::max(best, std::abs(u[0] * v[0] + u[1] * v[1] + u[2] * v[2]));
    if (best < cosine) return false;
  }
  return true;
}

}  // namespace hexbite
