#include "mesher/principal_frame.h"

#include <Eigen/Dense>
#include <cmath>

namespace hexbite {

namespace {

Eigen::Vector3d eigen(const Vec3& v) {
  return {v[0], v[1], v[2]};
}
Vec3 vec(const Eigen::Vector3d& v) {
  return {v[0], v[1], v[2]};
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

}  // namespace hexbite
