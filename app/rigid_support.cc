#include "app/rigid_support.h"

#include <Eigen/Dense>
#include <cmath>
#include <stdexcept>

namespace hexbite {

namespace {

using Matrix6 = Eigen::Matrix<double, 6, 6>;
using Modes = Eigen::Matrix<double, 3, 6>;

// The six rigid motions at x: translations along x, y, z, then rotations about axes through c along x, y,
// z, divided by the length L so that all six columns have the size of the body.
Modes rigid_modes(const Vec3& x, const Vec3& c, double L) {
  const Eigen::Vector3d r((x[0] - c[0]) / L, (x[1] - c[1]) / L, (x[2] - c[2]) / L);
  Modes m = Modes::Zero();
  m.leftCols<3>().setIdentity();
  for (int k = 0; k < 3; ++k) m.col(3 + k) = Eigen::Vector3d::Unit(k).cross(r);
  return m;
}

}  // namespace

RigidMode weakest_rigid_mode(const std::vector<HeldPoint>& held, const std::vector<BodyPoint>& body) {
  double volume = 0.0;
  Vec3 c{0, 0, 0};
  for (const BodyPoint& p : body) {
    volume += p.weight;
    for (int a = 0; a < 3; ++a) c[a] += p.weight * p.x[a];
  }
  if (!(volume > 0.0)) throw std::invalid_argument("weakest_rigid_mode: the body has no volume");
  for (double& v : c) v /= volume;
  double second_moment = 0.0;
  for (const BodyPoint& p : body) second_moment += p.weight * vec3::dot(vec3::sub(p.x, c), vec3::sub(p.x, c));
  const double L = std::sqrt(second_moment / volume);  // RMS distance from the centroid

  Matrix6 M = Matrix6::Zero(), G = Matrix6::Zero();
  for (const BodyPoint& p : body) {
    const Modes m = rigid_modes(p.x, c, L);
    M += (p.weight / volume) * m.transpose() * m;
  }
  for (const HeldPoint& p : held) {
    Modes m = rigid_modes(p.x, c, L);
    for (int a = 0; a < 3; ++a)
      if (!p.held[a]) m.row(a).setZero();
    G += p.weight * m.transpose() * m;
  }
  RigidMode mode;
  const Eigen::GeneralizedSelfAdjointEigenSolver<Matrix6> eigen(G, M);
  if (eigen.info() != Eigen::Success) throw std::runtime_error("weakest_rigid_mode: eigenproblem failed");
  mode.rho = std::max(0.0, eigen.eigenvalues()(0));
  const Eigen::Matrix<double, 6, 1> v = eigen.eigenvectors().col(0);
  const Eigen::Vector3d t = v.head<3>(), w = v.tail<3>() / L;  // u(x) = t + w x (x - c)
  // A rotation whose axis passes within the body moves it by about |w| L; call the motion a translation
  // only when that is small against |t|.
  if (w.norm() * L < 1e-3 * t.norm()) {
    const Eigen::Vector3d d = t.normalized();
    mode.direction = {d[0], d[1], d[2]};
    return mode;
  }
  mode.rotation = true;
  const Eigen::Vector3d d = w.normalized();
  const Eigen::Vector3d p = w.cross(t) / w.squaredNorm();  // the screw axis's point nearest c, relative to c
  mode.direction = {d[0], d[1], d[2]};
  mode.axis_point = {c[0] + p[0], c[1] + p[1], c[2] + p[2]};
  return mode;
}

}  // namespace hexbite
