// Points in trilinear hexes (mesher/hex_point_location.h): the probes' placement.
#include <gtest/gtest.h>

#include <cmath>

#include "mesher/hex_point_location.h"

namespace hexbite {
namespace {

// One hex with a bulging top face: the top's centre lies 0.5 above its corners' plane (z = 2).
HexMesh bulging_hex() {
  HexMesh m;
  m.vertices = {{0, 0, 0},   {2, 0, 0},   {2, 2, 0},   {0, 2, 0},
                {0, 0, 2.5}, {2, 0, 1.5}, {2, 2, 2.5}, {0, 2, 1.5}};
  m.hexes = {{0, 1, 2, 3, 4, 5, 6, 7}};
  return m;
}

double distance(const Vec3& a, const Vec3& b) {
  return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
}

TEST(HexPointLocation, TheInverseMapReturnsTheUnitCoordinates) {
  const HexMesh m = bulging_hex();
  for (const Vec3& unit :
       {Vec3{0.1, 0.2, 0.3}, Vec3{0.9, 0.5, 0.99}, Vec3{0.5, 0.5, 0.5}, Vec3{1.2, -0.1, 0.5}}) {
    const Vec3 x = trilinear_point(m, 0, unit);
    const std::optional<Vec3> back = trilinear_unit(m, 0, x);
    ASSERT_TRUE(back.has_value());
    for (int a = 0; a < 3; ++a) EXPECT_NEAR((*back)[a], unit[a], 1e-12) << a;
  }
  EXPECT_TRUE(hex_holds(m, 0, {1, 1, 1.9}));   // under the twisted top face
  EXPECT_FALSE(hex_holds(m, 0, {1, 1, 2.1}));  // above it: the top's centre is at z = 2
}

// A point above the twisted top face: the nearest point inside lies on that face (z = 2 at the middle), not
// at the clamped inverse alone, and inside the hex by construction.
TEST(HexPointLocation, TheNearestPointInsideLiesInTheHexAndNearTheFace) {
  const HexMesh m = bulging_hex();
  const Vec3 p{1.0, 1.0, 2.6};
  const PointInHex in = nearest_point_inside(m, {0}, p);
  ASSERT_EQ(in.hex, 0);
  EXPECT_TRUE(hex_holds(m, 0, in.point));
  EXPECT_NEAR(in.distance, distance(in.point, p), 1e-12);
  // The twisted face's nearest point to p is within a few hundredths of the face centre's distance 0.6.
  EXPECT_LT(in.distance, 0.6 + 0.01);
  EXPECT_GT(in.distance, 0.5);
  // A point inside needs no move.
  EXPECT_NEAR(nearest_point_inside(m, {0}, {1, 1, 1}).distance, 0.0, 1e-12);
  EXPECT_EQ(nearest_point_inside(m, {}, p).hex, -1);
}

}  // namespace
}  // namespace hexbite
