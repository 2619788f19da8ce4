// How firmly the supports of a scenario hold the bone against rigid-body motion, before any solve.
//
// Why: the scenario checks refuse a direction that no support holds at all (a singular problem), but a
// scenario can hold every translation and leave a rotation held only by the extent of small patches: the
// condyles fixed in x and y and one bite patch in z lets the bone turn about an axis through the patches.
// The solve then succeeds, and its displacements and stresses measure the supports rather than the bone.
//
// Method: among the rigid motions u(x) = t + w x (x - c) of a body, the one with the least
//   rho = (sum over the supports of the mean over the support's patch of |u's held components|^2)
//         / (mean over the body's volume of |u|^2),
// by a 6 x 6 generalized symmetric eigenproblem (Eigen). Each support counts by its mean, not its area: a
// fixed patch of any size stops a translation, so rho is at least 1 for a translation along a component
// that some support holds, and 0 along one that none holds; a rotation about an axis through the patches
// gives about (patch radius / the bone's distance from the axis)^2, the patch's lever against that
// rotation. Elastic (spring) supports count as holding every component.
// Input: the supports' surface as points with the components their support holds and weights that sum to
// 1 over each support (area / the patch's area), and the body's volume as points with volume weights.
// Output: rho and the motion, as a translation direction or a rotation axis.
// Cost: O(points), one 6 x 6 eigenproblem.
#pragma once

#include <array>
#include <vector>

#include "mesher/vec3.h"

namespace hexbite {

struct HeldPoint {
  Vec3 x;
  double weight = 0;           // the point's share of its support's patch area (1 over each support)
  std::array<bool, 3> held{};  // components the support fixes there
};

struct BodyPoint {
  Vec3 x;
  double weight = 0;  // volume, mm^3
};

struct RigidMode {
  double rho = 0;            // see above; 0 when some rigid motion is not held at all
  bool rotation = false;     // false: a translation along `direction`
  Vec3 direction{0, 0, 0};   // unit: the translation, or the rotation axis's direction
  Vec3 axis_point{0, 0, 0};  // a point of the rotation axis (the one nearest the body's centroid)
};

// Below this rho the supports resist a rigid motion only by the extent of their patches, and the
// displacements and stresses mostly measure that motion. Measured on the built-in mandible at 4,000 hexes
// (docs/scenario-format.md "Supports"): the shipped scenarios 0.33 to 1.28; a bite patch fixed in z with
// the condyles in x and y 0.0031 (largest displacement 2.9 mm, against 0.12 mm with every component
// fixed), the condyles alone 0.0067 (11 mm), a bite and one condyle 0.012 (3.9 mm). A 100 mm box clamped
// over one patch of 20 mm radius, a proper cantilever, has 0.035 and is not weak.
constexpr double kWeakSupportHold = 0.02;

// A weak motion is a rotation: every translation has rho >= 1 once some support holds each of x, y and z
// (and 0, a singular problem, otherwise, which the scenario checks refuse before).
inline bool is_weak(const RigidMode& m) {
  return m.rotation && m.rho < kWeakSupportHold;
}

// The rigid motion that the held points resist least. Requires a body with positive total weight.
RigidMode weakest_rigid_mode(const std::vector<HeldPoint>& held, const std::vector<BodyPoint>& body);

}  // namespace hexbite
