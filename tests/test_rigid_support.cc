// The weakest rigid motion that a set of supports holds (app/rigid_support.h), on a bar-shaped body.
#include <gtest/gtest.h>

#include <cmath>

#include "app/rigid_support.h"

namespace hexbite {
namespace {

// A bar 100 x 20 x 20 mm along x, centred at the origin, as 1 mm^3 volume points on a 2 mm lattice.
std::vector<BodyPoint> bar() {
  std::vector<BodyPoint> body;
  for (double x = -49; x <= 49; x += 2)
    for (double y = -9; y <= 9; y += 2)
      for (double z = -9; z <= 9; z += 2) body.push_back({{x, y, z}, 8.0});
  return body;
}

// A square patch of side 2 r on the face x = x0 (a bar end), held in the given components, its points'
// weights summing to 1.
std::vector<HeldPoint> end_patch(double x0, double cy, double cz, double r, std::array<bool, 3> held) {
  std::vector<HeldPoint> patch;
  for (double y = -r + 0.25; y < r; y += 0.5)
    for (double z = -r + 0.25; z < r; z += 0.5) patch.push_back({{x0, cy + y, cz + z}, 1.0, held});
  for (HeldPoint& p : patch) p.weight /= patch.size();
  return patch;
}

std::vector<HeldPoint> both(std::vector<HeldPoint> a, const std::vector<HeldPoint>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

constexpr std::array<bool, 3> kXYZ{true, true, true};

TEST(WeakestRigidMode, ATranslationAnySupportHoldsCountsInFull) {
  // Only a 1 mm pin on the top face holds z, beside two 16 mm end patches that hold x and y: z stays held
  // (rho >= 1 for the translation), and the rotations have the pin's 10 mm lever and the end patches.
  auto held = both(end_patch(-50, 0, 0, 8, {true, true, false}), end_patch(50, 0, 0, 8, {true, true, false}));
  for (double x = -0.25; x < 0.5; x += 0.5)
    for (double y = -0.25; y < 0.5; y += 0.5) held.push_back({{x, y, 10.0}, 0.25, kXYZ});
  EXPECT_GT(weakest_rigid_mode(held, bar()).rho, 0.1);
  // Without the pin, z is free.
  held.resize(held.size() - 4);
  EXPECT_NEAR(weakest_rigid_mode(held, bar()).rho, 0.0, 1e-9);
}

TEST(WeakestRigidMode, AComponentNoSupportHoldsIsAFreeTranslation) {
  const auto held =
      both(end_patch(-50, 0, 0, 5, {true, true, false}), end_patch(50, 0, 0, 5, {true, true, false}));
  const RigidMode mode = weakest_rigid_mode(held, bar());
  EXPECT_NEAR(mode.rho, 0.0, 1e-12);
  EXPECT_FALSE(mode.rotation);
  EXPECT_NEAR(std::abs(mode.direction[2]), 1.0, 1e-9);
}

TEST(WeakestRigidMode, TwoEndPatchesLeaveTheRotationAboutTheirLineWeak) {
  // Both ends fixed in x, y and z: every rotation but the one about the bar's axis moves a patch by 50 mm;
  // that one moves the patches' points by at most 5 sqrt(2) mm and the bar's by up to 14 mm.
  const RigidMode mode =
      weakest_rigid_mode(both(end_patch(-50, 0, 0, 5, kXYZ), end_patch(50, 0, 0, 5, kXYZ)), bar());
  EXPECT_TRUE(mode.rotation);
  EXPECT_NEAR(std::abs(mode.direction[0]), 1.0, 1e-9);
  EXPECT_NEAR(mode.axis_point[1], 0.0, 1e-6);
  EXPECT_NEAR(mode.axis_point[2], 0.0, 1e-6);
  // Mean |u|^2 over each patch r^2 2/3 = 16.7, two patches, against the bar's 2 (10^2 - 1) / 3 = 66:
  // about 0.5.
  EXPECT_GT(mode.rho, 0.45);
  EXPECT_LT(mode.rho, 0.55);
  // Smaller patches hold that rotation less, as (radius)^2.
  const RigidMode small =
      weakest_rigid_mode(both(end_patch(-50, 0, 0, 1, kXYZ), end_patch(50, 0, 0, 1, kXYZ)), bar());
  EXPECT_NEAR(small.rho / mode.rho, 1.0 / 25.0, 0.01);
}

TEST(WeakestRigidMode, AThirdPatchOffTheLineHoldsEveryMotionFirmly) {
  auto held = both(end_patch(-50, 0, 0, 1, kXYZ), end_patch(50, 0, 0, 1, kXYZ));
  const double weak = weakest_rigid_mode(held, bar()).rho;
  // A patch on the top face (z = 10), halfway along the bar, 10 mm off the line through the end patches.
  for (double x = -0.75; x < 1; x += 0.5)
    for (double y = -0.75; y < 1; y += 0.5) held.push_back({{x, y, 10.0}, 1.0 / 16, kXYZ});
  const double firm = weakest_rigid_mode(held, bar()).rho;
  EXPECT_GT(firm, 20 * weak);
}

TEST(WeakestRigidMode, ARotationAxisAwayFromTheCentroidIsLocated) {
  // One end fixed in every component, the other held only along y: the bar turns about the axis along y
  // through the first end's patch (the other end moves along z, which nothing holds there).
  const auto held = both(end_patch(-50, 0, 0, 2, kXYZ), end_patch(50, 0, 0, 2, {false, true, false}));
  const RigidMode mode = weakest_rigid_mode(held, bar());
  EXPECT_TRUE(mode.rotation);
  EXPECT_NEAR(std::abs(mode.direction[1]), 1.0, 1e-3);
  EXPECT_NEAR(mode.axis_point[0], -50.0, 1.0);
  EXPECT_NEAR(mode.axis_point[2], 0.0, 1.0);
}

TEST(WeakestRigidMode, RefusesAnEmptyBody) {
  EXPECT_THROW(weakest_rigid_mode({}, {}), std::invalid_argument);
}

}  // namespace
}  // namespace hexbite
