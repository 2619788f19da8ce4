#include "mesher/hex_point_location.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

namespace hexbite {

namespace {

// Unit cube corners in VTK order.
constexpr int kCorner[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                               {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};

// The trilinear shape function of corner k at u, and its derivatives.
double shape(int k, const Vec3& u) {
  double value = 1.0;
  for (int a = 0; a < 3; ++a) value *= kCorner[k][a] ? u[a] : 1.0 - u[a];
  return value;
}

double shape_derivative(int k, const Vec3& u, int along) {
  double value = 1.0;
  for (int a = 0; a < 3; ++a)
    value *= a == along ? (kCorner[k][a] ? 1.0 : -1.0) : (kCorner[k][a] ? u[a] : 1.0 - u[a]);
  return value;
}

// The derivative of hex h's map at u: column k is dx/du_k.
Eigen::Matrix3d jacobian_at(const HexMesh& mesh, int h, const Vec3& u) {
  Eigen::Matrix3d jacobian = Eigen::Matrix3d::Zero();
  for (int k = 0; k < 8; ++k) {
    const Vec3& v = mesh.vertices[mesh.hexes[h][k]];
    for (int along = 0; along < 3; ++along) {
      const double d = shape_derivative(k, u, along);
      for (int a = 0; a < 3; ++a) jacobian(a, along) += d * v[a];
    }
  }
  return jacobian;
}

}  // namespace

Vec3 trilinear_point(const HexMesh& mesh, int h, const Vec3& unit) {
  Vec3 x{0.0, 0.0, 0.0};
  for (int k = 0; k < 8; ++k) {
    const double n = shape(k, unit);
    const Vec3& v = mesh.vertices[mesh.hexes[h][k]];
    for (int a = 0; a < 3; ++a) x[a] += n * v[a];
  }
  return x;
}

std::optional<Vec3> trilinear_unit(const HexMesh& mesh, int h, const Vec3& point) {
  Vec3 u{0.5, 0.5, 0.5};
  double size = 0.0;  // the hex's extent, for the convergence test
  for (int k = 1; k < 8; ++k)
    for (int a = 0; a < 3; ++a)
      size =
          std::max(size, std::abs(mesh.vertices[mesh.hexes[h][k]][a] - mesh.vertices[mesh.hexes[h][0]][a]));
  for (int iteration = 0; iteration < 30; ++iteration) {
    const Vec3 x = trilinear_point(mesh, h, u);
    const Eigen::Vector3d residual(point[0] - x[0], point[1] - x[1], point[2] - x[2]);
    if (residual.norm() <= 1e-12 * (1.0 + size)) return u;
    const Eigen::FullPivLU<Eigen::Matrix3d> lu(jacobian_at(mesh, h, u));
    if (!lu.isInvertible()) return std::nullopt;
    const Eigen::Vector3d step = lu.solve(residual);
    for (int a = 0; a < 3; ++a) u[a] += step[a];
    if (!std::isfinite(u[0] + u[1] + u[2]) || std::abs(u[0]) + std::abs(u[1]) + std::abs(u[2]) > 100.0)
      return std::nullopt;
  }
  return std::nullopt;
}

bool hex_holds(const HexMesh& mesh, int h, const Vec3& point, double tolerance) {
  const std::optional<Vec3> u = trilinear_unit(mesh, h, point);
  if (!u) return false;
  for (int a = 0; a < 3; ++a)
    if ((*u)[a] < -tolerance || (*u)[a] > 1.0 + tolerance) return false;
  return true;
}

PointInHex nearest_point_inside(const HexMesh& mesh, const std::vector<int>& hexes, const Vec3& point,
                                double inset) {
  PointInHex best;
  best.distance = std::numeric_limits<double>::infinity();
  const auto distance = [&](const Vec3& x) {
    return std::sqrt((x[0] - point[0]) * (x[0] - point[0]) + (x[1] - point[1]) * (x[1] - point[1]) +
                     (x[2] - point[2]) * (x[2] - point[2]));
  };
  const auto clamp = [&](Vec3 u) {
    for (int a = 0; a < 3; ++a) u[a] = std::clamp(u[a], inset, 1.0 - inset);
    return u;
  };
  for (int h : hexes) {
    const std::optional<Vec3> u = trilinear_unit(mesh, h, point);
    if (!u) continue;
    // From the clamped inverse, projected Newton steps toward the point, each kept only when it comes
    // nearer: on a curved face the clamped inverse is not the nearest point.
    Vec3 unit = clamp(*u), x = trilinear_point(mesh, h, unit);
    for (int iteration = 0; iteration < 20; ++iteration) {
      const Eigen::Matrix3d jacobian = jacobian_at(mesh, h, unit);
      const Eigen::Vector3d residual(point[0] - x[0], point[1] - x[1], point[2] - x[2]);
      // Steps only along the unit directions not held at a bound by the residual.
      const Eigen::Vector3d gradient = jacobian.transpose() * residual;
      Eigen::Matrix3d free = Eigen::Matrix3d::Identity();
      for (int a = 0; a < 3; ++a)
        if ((unit[a] <= inset && gradient[a] < 0) || (unit[a] >= 1.0 - inset && gradient[a] > 0))
          free(a, a) = 0;
      const Eigen::Matrix3d normal =
          free * jacobian.transpose() * jacobian * free + (Eigen::Matrix3d::Identity() - free);
      const Eigen::Vector3d step = normal.ldlt().solve(free * gradient);
      const Vec3 next = clamp({unit[0] + step[0], unit[1] + step[1], unit[2] + step[2]});
      const Vec3 next_x = trilinear_point(mesh, h, next);
      if (!(distance(next_x) < distance(x) - 1e-12)) break;
      unit = next;
      x = next_x;
    }
    const double d = distance(x);
    if (d < best.distance) best = {h, x, d};
  }
  if (best.hex < 0) best.distance = 0.0;
  return best;
}

}  // namespace hexbite
