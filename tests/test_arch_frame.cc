// The arch-following frame (mesher/arch_frame.h) and the grid mesher laid along it (GridMeshOptions::
// arch_frame): the map straightens the built-in mandible and returns every point, a solid that does not
// follow an arch is refused, and the arch-aligned grid gives the built-in mandible a better mean.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "common/error.h"
#include "mesher/arch_frame.h"
#include "mesher/grid_mesher.h"
#include "mesher/hex_quality.h"
#include "mesher/mandible_generator.h"
#include "mesher/surface_io.h"
#include "mesher/vec3.h"
#include "tests/test_util.h"

namespace hexbite {
namespace {

using vec3::norm;
using vec3::sub;

const GeneratedMandible& mandible() {
  static const GeneratedMandible g = generate_mandible({});
  return g;
}

TEST(ArchFrame, StraightensTheMandibleAndMapsEveryPointBack) {
  const GeneratedMandible& g = mandible();
  const ArchFrame frame(g.surface);
  double worst = 0, widest = 0;
  for (const Vec3& p : g.surface.vertices) {
    const Vec3 q = frame.to_arch(p);
    worst = std::max(worst, norm(sub(frame.to_body(q), p)));
    EXPECT_EQ(q[2], p[2]);
    widest = std::max(widest, std::fabs(q[1]));
  }
  EXPECT_LT(worst, 1e-9);
  // The bone lies along the curve: no point farther across it than 1.5 body thicknesses (12.3 mm, the
  // proclined incisors; a curve through the arch's hollow would leave the bone 25 mm or more away).
  EXPECT_LT(widest, 1.5 * g.parameters.body_thickness_mm);
  // s runs from the right side through the chin (halfway, the mandible being symmetric) to the left;
  // t is positive lingual: at the chin a step backwards is a step across the arch, inwards.
  const Vec3 right = frame.to_arch(g.landmarks.points.at("right_gonion"));
  const Vec3 chin = frame.to_arch(g.landmarks.points.at("incisal_point"));
  const Vec3 left = frame.to_arch(g.landmarks.points.at("left_gonion"));
  EXPECT_LT(right[0], chin[0]);
  EXPECT_LT(chin[0], left[0]);
  EXPECT_NEAR(chin[0], 0.5 * frame.length(), 0.01 * frame.length());
  EXPECT_NEAR(left[0] - chin[0], chin[0] - right[0], 0.5);
  const Vec3 behind = frame.to_arch(vec3::add(g.landmarks.points.at("incisal_point"), Vec3{0, 1, 0}));
  EXPECT_NEAR(behind[1] - chin[1], 1.0, 0.01);
  EXPECT_NEAR(behind[0], chin[0], 0.01);
  // Beyond the tabulated ends the curve goes on straight: still a round trip.
  for (const Vec3& q : {Vec3{-20, 3, 40}, Vec3{frame.length() + 20, -3, 40}})
    EXPECT_LT(norm(sub(frame.to_arch(frame.to_body(q)), q)), 1e-9);
}

// A torus around the vertical axis is no arch: the fitted curve runs through its hole, and the map would
// fold the ring.
TriSurface torus() {
  TriSurface torus;
  const int n = 32, m = 12;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) {
      const double u = 2 * M_PI * i / n, v = 2 * M_PI * j / m;
      torus.vertices.push_back(
          {(30 + 8 * std::cos(v)) * std::cos(u), (30 + 8 * std::cos(v)) * std::sin(u), 8 * std::sin(v)});
    }
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) {
      const int a = i * m + j, b = ((i + 1) % n) * m + j, c = ((i + 1) % n) * m + (j + 1) % m,
                d = i * m + (j + 1) % m;
      torus.triangles.push_back({a, b, c});
      torus.triangles.push_back({a, c, d});
    }
  return torus;
}

TEST(ArchFrame, RefusesASolidThatFollowsNoArch) {
  const std::string message = test::message_of<InputError>([] { ArchFrame frame(torus()); });
  EXPECT_NE(message.find("arch frame: "), std::string::npos) << message;
  EXPECT_NE(message.find("--grid-frame axes"), std::string::npos) << message;
}

// `hexbite mesh --grid-frame arch` on such a solid: exit code 2, the reason, no mesh.
TEST(ArchFrame, MeshCommandRefusesANonArchWithExitCode2) {
  const std::string dir = test::temp_dir();
  write_surface(dir + "/torus.stl", torus());
  const test::CommandResult r = test::run_hexbite(
      {"mesh", dir + "/torus.stl", "--grid-frame", "arch", "--target-hexes", "500", "-o", dir + "/t.vtu"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("arch frame: "), std::string::npos) << r.err;
  EXPECT_FALSE(std::ifstream(dir + "/t.vtu").good());
  const test::CommandResult bad =
      test::run_hexbite({"mesh", dir + "/torus.stl", "--grid-frame", "curved", "-o", dir + "/t.vtu"});
  EXPECT_EQ(bad.exit_code, 2) << bad.err;
  EXPECT_NE(bad.err.find("--grid-frame"), std::string::npos) << bad.err;
}

// --method sheets lays no grid: --grid-frame arch with it is refused (like a scenario's grid_frame), not
// ignored.
TEST(ArchFrame, MeshCommandRefusesTheArchFrameForTheSheetsMethod) {
  const std::string dir = test::temp_dir();
  write_surface(dir + "/torus.stl", torus());
  const test::CommandResult r = test::run_hexbite(
      {"mesh", dir + "/torus.stl", "--method", "sheets", "--grid-frame", "arch", "-o", dir + "/t.vtu"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--grid-frame arch lays the overlay grid of --method grid"), std::string::npos)
      << r.err;
  EXPECT_FALSE(std::ifstream(dir + "/t.vtu").good());
}

// Two boxes side by side pass the frame's checks but keep inverted hexes along the arch: the failure (exit
// 1) points to the axis-aligned grid.
TEST(ArchFrame, InvertedHexesAlongTheArchPointToTheAxes) {
  const std::string dir = test::temp_dir();
  test::write_file(dir + "/boxes.obj", test::cubes_obj(2));
  const test::CommandResult r = test::run_hexbite(
      {"mesh", dir + "/boxes.obj", "--grid-frame", "arch", "--target-hexes", "800", "-o", dir + "/b.vtu"});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("stay inverted"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--grid-frame axes, may mesh it valid"), std::string::npos) << r.err;
  EXPECT_FALSE(std::ifstream(dir + "/b.vtu").good());
}

// The axis-aligned grid cuts the curved arch obliquely; along the arch the built-in mandible's mean scaled
// Jacobian at 2,500 hexes rises from 0.792 (docs/meshing.md) to 0.822, with every boundary node on the
// surface.
TEST(ArchFrame, GridAlongTheArchRaisesTheMandiblesMean) {
  GridMeshOptions options;
  options.target_hexes = 2500;
  options.arch_frame = true;
  GridMeshReport report;
  const HexMesh mesh = grid_mesh(mandible().surface, options, &report);
  const QualitySummary q = summarize_quality(mesh);
  EXPECT_EQ(q.inverted, 0);
  EXPECT_NEAR(double(mesh.hexes.size()), 2500.0, 250.0);
  EXPECT_GE(q.scaled_jacobian.min, 0.3);
  EXPECT_GE(q.scaled_jacobian.mean, 0.81);
  EXPECT_LE(q.condition.max, 10.0);
  EXPECT_LT(std::fabs(report.fidelity.volume_difference), 0.03);
}

}  // namespace
}  // namespace hexbite
