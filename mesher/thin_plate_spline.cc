#include "mesher/thin_plate_spline.h"

#include <Eigen/Dense>
#include <cmath>
#include <string>

#include "common/error.h"

namespace hexbite {

namespace {

double distance(const Vec3& a, const Vec3& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                   (a[2] - b[2]) * (a[2] - b[2]));
}

}  // namespace

ThinPlateSpline::ThinPlateSpline(const std::vector<Vec3>& sources, const std::vector<Vec3>& targets,
                                 const std::vector<double>& lambda)
    : sources_(sources) {
  const int n = static_cast<int>(sources.size());
  if (n < 4 || targets.size() != sources.size() || lambda.size() != sources.size())
    throw InputError("a thin-plate spline warp needs at least 4 corresponding points, got " +
                     std::to_string(n));
  // The sources must span 3-D: the smallest singular value of the centred point cloud, relative to the
  // largest, must not vanish.
  Eigen::MatrixXd centred(n, 3);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Vec3& p : sources) mean += Eigen::Vector3d(p[0], p[1], p[2]) / n;
  for (int i = 0; i < n; ++i)
    centred.row(i) = Eigen::Vector3d(sources[i][0], sources[i][1], sources[i][2]) - mean;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(centred);
  const Eigen::Vector3d sv = svd.singularValues();
  if (!(sv[2] > 1e-3 * sv[0]))
    throw InputError(
        "the corresponding points of the warp are (nearly) coplanar; give points spread over "
        "the whole mandible (both condyles and the front)");
  Eigen::MatrixXd system = Eigen::MatrixXd::Zero(n + 4, n + 4);
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(n + 4, 3);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) system(i, j) = distance(sources[i], sources[j]);
    system(i, i) += lambda[i];
    system(i, n) = system(n, i) = 1.0;
    for (int a = 0; a < 3; ++a) {
      system(i, n + 1 + a) = system(n + 1 + a, i) = sources[i][a];
      rhs(i, a) = targets[i][a];
    }
  }
  const Eigen::MatrixXd solution = system.fullPivLu().solve(rhs);
  weights_.resize(n);
  for (int i = 0; i < n; ++i) weights_[i] = {solution(i, 0), solution(i, 1), solution(i, 2)};
  affine_.resize(4);
  for (int r = 0; r < 4; ++r) affine_[r] = {solution(n + r, 0), solution(n + r, 1), solution(n + r, 2)};
}

Vec3 ThinPlateSpline::operator()(const Vec3& x) const {
  Vec3 y = affine_[0];
  for (int a = 0; a < 3; ++a)
    for (int c = 0; c < 3; ++c) y[c] += affine_[1 + a][c] * x[a];
  for (std::size_t i = 0; i < sources_.size(); ++i) {
    const double r = distance(x, sources_[i]);
    for (int c = 0; c < 3; ++c) y[c] += weights_[i][c] * r;
  }
  return y;
}

}  // namespace hexbite
