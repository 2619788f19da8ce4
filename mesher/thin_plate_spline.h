// A 3-D thin-plate spline (polyharmonic, kernel |r|): the smooth warp that carries a template's reference
// points onto a target's corresponding points (mesher/quad_surface_placement.h uses it to place the mandible
// macro-element mesh).
//
// Input: n >= 4 point pairs (source, target) whose sources are not coplanar, and per pair a smoothing
// weight lambda_i >= 0 (mm; 0 interpolates that pair exactly, larger values let the warp miss it in
// exchange for a gentler warp, tending to the best affine map: less trusted pairs get larger weights).
// Output: f(x) = A x + b + sum_i w_i |x - p_i|, evaluated by operator().
// Algorithm: the standard (n + 4) x (n + 4) saddle-point system [K + diag(lambda), P; P^T, 0], solved densely
// with Eigen's full-pivoting LU (n is a few dozen). Cost: O(n^3) to fit, O(n) per evaluation.
// Failure: InputError when the sources are fewer than 4 or (nearly) coplanar. Deterministic.
#pragma once

#include <vector>

#include "mesher/tri_surface.h"

namespace hexbite {

class ThinPlateSpline {
 public:
  ThinPlateSpline(const std::vector<Vec3>& sources, const std::vector<Vec3>& targets,
                  const std::vector<double>& lambda);
  Vec3 operator()(const Vec3& x) const;

 private:
  std::vector<Vec3> sources_;
  std::vector<Vec3> weights_;  // one per source
  std::vector<Vec3> affine_;   // rows: constant, then the x, y and z coefficients
};

}  // namespace hexbite
