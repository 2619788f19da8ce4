// clean_surface() and `hexbite surface clean`: small angles are removed (or each survivor is
// reported), the deviation stays within the bound (measured again here, independently), the result
// still bounds the same solid (closed, manifold, same genus, outward, volume kept), the size target
// is met, the output is deterministic, and bad options or inputs are refused with exit code 2.
#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "common/error.h"
#include "mesher/mandible_generator.h"
#include "mesher/surface_check.h"
#include "mesher/surface_clean.h"
#include "mesher/surface_io.h"
#include "tests/test_shapes.h"
#include "tests/test_util.h"

namespace hexbite {
namespace {

using test::torus;

using test::run_hexbite;
using test::shared_data;
using test::temp_dir;

const double kPi = std::acos(-1.0);

double triangle_min_angle(const TriSurface& s, const std::array<int, 3>& t) {
  double smallest = 180.0;
  for (int k = 0; k < 3; ++k) {
    const Vec3 &a = s.vertices[t[k]], &b = s.vertices[t[(k + 1) % 3]], &c = s.vertices[t[(k + 2) % 3]];
    const Vec3 u{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double dot = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
    const double nu = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    const double nv = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    smallest = std::min(smallest, std::acos(std::clamp(dot / (nu * nv), -1.0, 1.0)) * 180.0 / kPi);
  }
  return smallest;
}

// A lower estimate of the symmetric Hausdorff distance, computed differently from the program:
// points on a barycentric grid (4 steps) of every triangle of each surface against an AABB tree of
// the other surface. It can only under-estimate, so it must stay below both the bound and the
// program's reported value (an upper bound).
double sampled_hausdorff(const TriSurface& a, const TriSurface& b) {
  using K = CGAL::Simple_cartesian<double>;
  using Mesh = CGAL::Surface_mesh<K::Point_3>;
  using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, CGAL::AABB_face_graph_triangle_primitive<Mesh>>>;
  auto one_way = [](const TriSurface& from, const TriSurface& to) {
    Mesh mesh;
    for (const Vec3& v : to.vertices) mesh.add_vertex(K::Point_3(v[0], v[1], v[2]));
    for (const auto& t : to.triangles)
      mesh.add_face(Mesh::Vertex_index(t[0]), Mesh::Vertex_index(t[1]), Mesh::Vertex_index(t[2]));
    Tree tree(faces(mesh).first, faces(mesh).second, mesh);
    tree.accelerate_distance_queries();
    const int steps = 4;
    double worst = 0;
    for (const auto& t : from.triangles) {
      for (int i = 0; i <= steps; ++i)
        for (int j = 0; i + j <= steps; ++j) {
          const double w[3] = {double(i) / steps, double(j) / steps, double(steps - i - j) / steps};
          double x = 0, y = 0, z = 0;
          for (int k = 0; k < 3; ++k) {
            x += w[k] * from.vertices[t[k]][0];
            y += w[k] * from.vertices[t[k]][1];
            z += w[k] * from.vertices[t[k]][2];
          }
          worst = std::max(worst, tree.squared_distance(K::Point_3(x, y, z)));
        }
    }
    return std::sqrt(worst);
  };
  return std::max(one_way(a, b), one_way(b, a));
}

// Everything a cleanup must guarantee, checked with the project's own surface checker and the
// independent deviation estimate above.
void expect_valid_cleanup(const TriSurface& input, const TriSurface& output, const CleanOptions& options,
                          const CleanReport& report, long genus) {
  EXPECT_EQ(report.triangles_before, input.triangles.size());
  EXPECT_EQ(report.vertices_before, input.vertices.size());
  EXPECT_EQ(report.triangles_after, output.triangles.size());
  EXPECT_EQ(report.vertices_after, output.vertices.size());

  // Every triangle still below the threshold is listed, with its index and angle, and nothing else is.
  std::vector<std::size_t> bad;
  double smallest = 180.0;
  for (std::size_t i = 0; i < output.triangles.size(); ++i) {
    const double angle = triangle_min_angle(output, output.triangles[i]);
    smallest = std::min(smallest, angle);
    if (angle < options.min_angle_deg) bad.push_back(i);
  }
  ASSERT_EQ(report.unfixed_triangles.size(), bad.size());
  ASSERT_EQ(report.unfixed.size(), bad.size());
  for (std::size_t k = 0; k < bad.size(); ++k) {
    EXPECT_EQ(report.unfixed_triangles[k].index, bad[k]);
    EXPECT_NEAR(report.unfixed_triangles[k].min_angle_deg,
                triangle_min_angle(output, output.triangles[bad[k]]), 1e-6);
  }
  EXPECT_NEAR(report.min_angle_after_deg, smallest, 1e-6);

  // The deviation: reported within the bound, and an independent estimate agrees.
  EXPECT_GT(report.hausdorff_mm, 0.0);
  EXPECT_LE(report.hausdorff_mm, options.max_deviation_mm);
  const double sampled = sampled_hausdorff(input, output);
  EXPECT_LE(sampled, options.max_deviation_mm);
  EXPECT_LE(sampled, report.hausdorff_mm + 1e-9);

  // Still the boundary of the same solid.
  TriSurface checked = output;
  const SurfaceReport check = check_surface(checked, "cleaned");
  EXPECT_TRUE(check.usable()) << (check.problems.empty() ? "" : check.problems.front());
  EXPECT_TRUE(check.closed);
  EXPECT_TRUE(check.manifold);
  EXPECT_TRUE(check.outward);
  EXPECT_EQ(check.components, 1u);
  EXPECT_EQ(check.self_intersections, 0u);
  EXPECT_EQ(check.degenerate_triangles, 0u);
  EXPECT_EQ(check.genus, genus);
  EXPECT_TRUE(checked.triangles.size() == output.triangles.size()) << "the checker had to repair the result";
  TriSurface original = input;
  const SurfaceReport before = check_surface(original, "input");
  EXPECT_NEAR(check.volume_mm3, before.volume_mm3, 0.005 * before.volume_mm3);
  EXPECT_NEAR(report.volume_after_mm3, check.volume_mm3, 1e-6 * check.volume_mm3);
}

// A UV sphere: its triangles near the poles are needles with apex angles of 360/segments degrees.
TriSurface uv_sphere(double radius, int rings, int segments) {
  TriSurface s;
  s.vertices.push_back({0, 0, radius});
  for (int i = 1; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const double theta = kPi * i / rings, phi = 2 * kPi * j / segments;
      s.vertices.push_back({radius * std::sin(theta) * std::cos(phi),
                            radius * std::sin(theta) * std::sin(phi), radius * std::cos(theta)});
    }
  s.vertices.push_back({0, 0, -radius});
  const int south = int(s.vertices.size()) - 1;
  auto id = [&](int ring, int j) { return 1 + (ring - 1) * segments + (j % segments); };
  for (int j = 0; j < segments; ++j) s.triangles.push_back({0, id(1, j), id(1, j + 1)});
  for (int i = 1; i + 1 < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      s.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      s.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  for (int j = 0; j < segments; ++j) s.triangles.push_back({south, id(rings - 1, j + 1), id(rings - 1, j)});
  return s;
}

const TriSurface& real_jaw() {
  static const TriSurface jaw = load_closed_surface(shared_data("jaw/jaw_smooth.stl"), 1.0);
  return jaw;
}

TEST(SurfaceClean, RealJawAtDefaults) {
  const TriSurface& jaw = real_jaw();
  ASSERT_EQ(jaw.triangles.size(), 41760u);
  CleanOptions options;
  CleanReport report;
  const TriSurface cleaned = clean_surface(jaw, options, &report);
  expect_valid_cleanup(jaw, cleaned, options, report, 0);
  EXPECT_NEAR(report.min_angle_before_deg, 1.2, 0.05);
  EXPECT_GT(report.bad_before, 0u);
  // Measured: all 50 small-angle triangles are fixed.
  EXPECT_TRUE(report.unfixed.empty());
  EXPECT_GE(report.min_angle_after_deg, 5.0);
  EXPECT_GT(report.collapses, 0u);
  EXPECT_GT(report.flips, 0u);
  EXPECT_LT(report.triangles_after, report.triangles_before);
}

TEST(SurfaceClean, RealJawReducedToTarget) {
  const TriSurface& jaw = real_jaw();
  CleanOptions options;
  options.target_triangles = 20000;
  CleanReport report;
  const TriSurface cleaned = clean_surface(jaw, options, &report);
  expect_valid_cleanup(jaw, cleaned, options, report, 0);
  EXPECT_TRUE(report.target_reached) << report.target_note;
  EXPECT_LE(cleaned.triangles.size(), 20000u);
  EXPECT_TRUE(report.unfixed.empty());
}

TEST(SurfaceClean, UnreachableTargetIsExplained) {
  // A sphere of radius 10 cannot become 8 triangles within 0.05 mm: the cleanup stops and says why.
  const TriSurface sphere = uv_sphere(10.0, 24, 48);
  CleanOptions options;
  options.target_triangles = 8;
  options.max_deviation_mm = 0.05;
  CleanReport report;
  const TriSurface cleaned = clean_surface(sphere, options, &report);
  expect_valid_cleanup(sphere, cleaned, options, report, 0);
  EXPECT_FALSE(report.target_reached);
  EXPECT_GT(cleaned.triangles.size(), 8u);
  EXPECT_NE(report.target_note.find("stopped at"), std::string::npos);
}

// The deviation bound was tested with CGAL's sphere test, which is one of the sphere's surface: with a
// bound wider than the solid every input triangle lay inside the ball, so every contraction was refused
// (0 operations, "no further contraction keeps the deviation within 100 mm"), while 20 mm reduced it.
TEST(SurfaceClean, BoundWiderThanTheSolidStillReduces) {
  const TriSurface sphere = uv_sphere(10.0, 12, 24);
  CleanOptions options;
  options.target_triangles = 100;
  options.max_deviation_mm = 100.0;
  CleanReport report;
  TriSurface cleaned = clean_surface(sphere, options, &report);
  EXPECT_LT(cleaned.triangles.size(), sphere.triangles.size() / 2);
  EXPECT_LE(report.hausdorff_mm, options.max_deviation_mm);
  // Coarser (the volume is not kept within the usual 0.5 %: the bound allows far more), but still a solid.
  EXPECT_TRUE(check_surface(cleaned, "cleaned").usable());
}

TEST(SurfaceClean, PoleNeedlesOfASphereAreRemoved) {
  // 90 segments: the pole triangles have 4-degree apex angles, and the next band is made of needles.
  const TriSurface sphere = uv_sphere(20.0, 40, 90);
  CleanOptions options;
  CleanReport report;
  const TriSurface cleaned = clean_surface(sphere, options, &report);
  EXPECT_GE(report.bad_before, 180u);
  expect_valid_cleanup(sphere, cleaned, options, report, 0);
  EXPECT_TRUE(report.unfixed.empty());
}

TEST(SurfaceClean, TorusKeepsItsGenus) {
  // 600 x 8 grid: every triangle is a needle of about 3 degrees.
  const TriSurface ring = torus(600, 8);
  CleanOptions options;
  options.max_deviation_mm = 0.2;
  CleanReport report;
  const TriSurface cleaned = clean_surface(ring, options, &report);
  EXPECT_EQ(report.bad_before, ring.triangles.size());
  expect_valid_cleanup(ring, cleaned, options, report, 1);
  EXPECT_LT(report.bad_after, report.bad_before / 10);
}

TEST(SurfaceClean, GeneratedMandible) {
  const GeneratedMandible mandible = generate_mandible(MandibleParameters{});
  CleanOptions options;
  CleanReport report;
  const TriSurface cleaned = clean_surface(mandible.surface, options, &report);
  expect_valid_cleanup(mandible.surface, cleaned, options, report, 0);
  EXPECT_GT(report.bad_before, 0u);  // marching cubes makes slivers
  EXPECT_LE(report.bad_after, report.bad_before / 20);
}

TEST(SurfaceClean, Deterministic) {
  // Angle cleanup, size reduction and flips all run; the real jaw at the defaults is compared byte
  // for byte through the command line below.
  const TriSurface sphere = uv_sphere(20.0, 40, 90);
  CleanOptions options;
  options.target_triangles = 2000;
  const std::string dir = temp_dir();
  write_surface(dir + "/a.stl", clean_surface(sphere, options, nullptr));
  write_surface(dir + "/b.stl", clean_surface(sphere, options, nullptr));
  EXPECT_EQ(test::read_file(dir + "/a.stl"), test::read_file(dir + "/b.stl"));
}

TEST(SurfaceClean, OptionsAreValidated) {
  auto invalid = [](double angle, double deviation, std::size_t target) {
    CleanOptions o;
    o.min_angle_deg = angle;
    o.max_deviation_mm = deviation;
    o.target_triangles = target;
    EXPECT_THROW(validate_clean_options(o), InputError) << angle << " " << deviation << " " << target;
  };
  invalid(-1, 0.1, 0);
  invalid(70, 0.1, 0);
  invalid(std::nan(""), 0.1, 0);
  invalid(5, 0, 0);
  invalid(5, -0.1, 0);
  invalid(5, std::nan(""), 0);
  invalid(5, INFINITY, 0);
  invalid(5, 0.1, 3);
  EXPECT_NO_THROW(validate_clean_options(CleanOptions{}));
  EXPECT_THROW(clean_surface(uv_sphere(1, 8, 8), CleanOptions{-1.0, 0, 0.1}, nullptr), InputError);
}

TEST(SurfaceCleanCli, CleansTheRealJawAsJson) {
  const std::string out = temp_dir() + "/clean.stl";
  const auto r = run_hexbite({"surface", "clean", shared_data("jaw/jaw_smooth.stl"), "-o", out, "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_TRUE(std::filesystem::exists(out));
  const auto j = nlohmann::json::parse(r.out);
  for (const char* key : {"triangles_before", "triangles_after", "vertices_before", "vertices_after",
                          "min_angle_before_deg", "min_angle_after_deg", "collapses", "flips", "hausdorff_mm",
                          "max_deviation_mm", "seconds", "unfixed"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["triangles_before"], 41760);
  EXPECT_GE(j["min_angle_after_deg"].get<double>(), 5.0);
  EXPECT_LE(j["hausdorff_mm"].get<double>(), j["max_deviation_mm"].get<double>());
  EXPECT_TRUE(j["unfixed"].is_array());
  const TriSurface written = read_surface(out);
  EXPECT_EQ(written.triangles.size(), j["triangles_after"].get<std::size_t>());

  // The same command again writes the same bytes.
  const std::string again = temp_dir() + "/clean.stl";
  ASSERT_EQ(
      run_hexbite({"surface", "clean", shared_data("jaw/jaw_smooth.stl"), "-o", again, "--quiet"}).exit_code,
      0);
  EXPECT_EQ(test::read_file(out), test::read_file(again));
}

TEST(SurfaceCleanCli, TextReportAndUnits) {
  // The jaw read as if in cm is ten times larger; the result is in mm.
  const std::string out = temp_dir() + "/clean.off";
  const auto r = run_hexbite({"surface", "clean", shared_data("jaw/jaw_smooth.stl"), "-o", out, "--units",
                              "cm", "--max-deviation", "1"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("Hausdorff distance"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("41760 ->"), std::string::npos) << r.out;
  const TriSurface written = read_surface(out);
  double xmin = 1e300, xmax = -1e300;
  for (const Vec3& v : written.vertices) {
    xmin = std::min(xmin, v[0]);
    xmax = std::max(xmax, v[0]);
  }
  EXPECT_NEAR(xmax - xmin, 1177.0, 5.0);
}

void expect_refused(const std::vector<std::string>& extra, const std::string& input,
                    const std::string& words) {
  const std::string out = temp_dir() + "/never.stl";
  std::vector<std::string> args = {"surface", "clean", input, "-o", out};
  args.insert(args.end(), extra.begin(), extra.end());
  const auto r = run_hexbite(args);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find(words), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(SurfaceCleanCli, BadOptionsExitTwo) {
  const std::string jaw = shared_data("jaw/jaw_smooth.stl");
  expect_refused({"--min-angle", "-1"}, jaw, "--min-angle");
  expect_refused({"--min-angle", "70"}, jaw, "--min-angle");
  expect_refused({"--max-deviation", "0"}, jaw, "--max-deviation");
  expect_refused({"--max-deviation", "-0.5"}, jaw, "--max-deviation");
  expect_refused({"--target-triangles", "2"}, jaw, "--target-triangles");
  // -1 used to wrap around to 18446744073709551615 and was accepted as "no reduction" (exit 0).
  expect_refused({"--target-triangles", "-1"}, jaw, "--target-triangles: -1 is out of range");
  expect_refused({"--target-triangles", "2.5"}, jaw, "not a whole number");
  expect_refused({"--units", "inch"}, jaw, "inch");
  // Checked while parsing, with the range: "Could not convert: --min-angle = abc" before, and "(got
  // 45.000000)" for a value out of range.
  expect_refused({"--min-angle", "abc"}, jaw, "--min-angle: abc is not a number: give a number from 0 to 30");
  expect_refused({"--min-angle", "45"}, jaw, "--min-angle: 45 is out of range: give a number from 0 to 30");
  expect_refused({"--max-deviation", "1mm"}, jaw,
                 "--max-deviation: 1mm is not a number: give a number greater than 0 (a distance in mm)");
  expect_refused({"--max-deviation", "inf"}, jaw, "--max-deviation: inf is out of range");
}

TEST(SurfaceCleanCli, OpenSurfaceExitsTwo) {
  TriSurface open = uv_sphere(10, 8, 16);
  open.triangles.pop_back();
  const std::string input = temp_dir() + "/open.stl";
  write_surface(input, open);
  expect_refused({}, input, "open");
}

}  // namespace
}  // namespace hexbite
