// The principal axes of a closed surface (mesher/principal_frame.h), which the grid mesher tries when its
// axis-aligned grids leave inverted hexes.
#include "mesher/principal_frame.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/test_shapes.h"

namespace hexbite {
namespace {

// `s` turned by `degrees` about z.
TriSurface turned(TriSurface s, double degrees) {
  const double c = std::cos(degrees * M_PI / 180.0), n = std::sin(degrees * M_PI / 180.0);
  for (Vec3& v : s.vertices) v = {c * v[0] - n * v[1], n * v[0] + c * v[1], v[2]};
  return s;
}

double largest_alignment(const PrincipalFrame& f, const Vec3& direction) {
  double best = 0;
  for (const Vec3& axis : f.axes)
    best = std::max(best, std::abs(axis[0] * direction[0] + axis[1] * direction[1] + axis[2] * direction[2]));
  return best;
}

TEST(PrincipalFrame, ARotatedBoxGetsItsOwnAxesAndKeepsTheFreeOneAlongZ) {
  const TriSurface box = test::box(100, 20, 20);
  const std::optional<PrincipalFrame> plain = principal_frame(box);
  ASSERT_TRUE(plain.has_value());
  EXPECT_TRUE(plain->along_coordinate_axes());
  const std::optional<PrincipalFrame> f = principal_frame(turned(box, 30));
  ASSERT_TRUE(f.has_value());
  EXPECT_FALSE(f->along_coordinate_axes());
  const double c = std::cos(M_PI / 6), n = std::sin(M_PI / 6);
  EXPECT_NEAR(largest_alignment(*f, {c, n, 0}), 1.0, 1e-9);  // the long axis
  // The square section's two equal moments leave their plane free: its axes are taken along z and the
  // direction across it, so the grid sees the box as if it were not turned.
  EXPECT_NEAR(largest_alignment(*f, {0, 0, 1}), 1.0, 1e-9);
  EXPECT_NEAR(largest_alignment(*f, {-n, c, 0}), 1.0, 1e-9);
  // A right-handed rotation, and to_body undoes to_frame.
  const Vec3& x = f->axes[0];
  const Vec3& y = f->axes[1];
  const Vec3& z = f->axes[2];
  EXPECT_NEAR(x[1] * y[2] - x[2] * y[1], z[0], 1e-12);
  EXPECT_NEAR(x[2] * y[0] - x[0] * y[2], z[1], 1e-12);
  EXPECT_NEAR(x[0] * y[1] - x[1] * y[0], z[2], 1e-12);
  const Vec3 p{12.5, -3, 7}, back = f->to_body(f->to_frame(p));
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(back[a], p[a], 1e-12);
}

TEST(PrincipalFrame, ACubeHasNoAxisToPrefer) {
  EXPECT_FALSE(principal_frame(test::box(10, 10, 10)).has_value());
}

// The largest flat faces give an L-shaped block's own axes, turned with it, where its principal axes lie
// along its diagonal; a solid without flat faces has none.
TEST(FaceFrame, AnLShapedBlockGetsItsFacesNormals) {
  const TriSurface block = test::l_block(40, 10, 10);
  const std::optional<PrincipalFrame> principal = principal_frame(test::rotated(block, {0, 0, 1}, 45));
  ASSERT_TRUE(principal.has_value());
  EXPECT_TRUE(principal->along_coordinate_axes());  // the diagonal, turned onto x and y
  const TriSurface turned_block = test::rotated(block, {1, 2, 3}, 33);
  const std::optional<PrincipalFrame> f = face_frame(turned_block);
  ASSERT_TRUE(f.has_value());
  EXPECT_FALSE(f->along_coordinate_axes());
  // Each axis along one of the block's turned axes; z along its largest faces (top and bottom: 1,400 mm^2
  // against 800 for the sides along x or y).
  TriSurface units;
  units.vertices = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  units = test::rotated(units, {1, 2, 3}, 33);
  for (const Vec3& unit : units.vertices) EXPECT_NEAR(largest_alignment(*f, unit), 1.0, 1e-9);
  const Vec3& z = units.vertices[2];
  EXPECT_NEAR(std::abs(f->axes[2][0] * z[0] + f->axes[2][1] * z[1] + f->axes[2][2] * z[2]), 1.0, 1e-9);
  EXPECT_TRUE(same_axes(*f, *f));
  EXPECT_FALSE(same_axes(*f, *principal));
  EXPECT_FALSE(face_frame(test::torus(64, 32)).has_value());
}

}  // namespace
}  // namespace hexbite
