// check_surface(): the real jaw checks clean, safe repairs are applied and reported, and every kind
// of defect is found, counted and located.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>

#include "common/error.h"
#include "mesher/surface_check.h"
#include "mesher/surface_io.h"
#include "tests/test_shapes.h"
#include "tests/test_util.h"

namespace hexbite {
namespace {

using test::torus;

using test::shared_data;
using test::temp_dir;

// Unit cube with outward quads split into triangles; vertex i has x = bit 0, y = bit 1, z = bit 2.
TriSurface unit_cube(const Vec3& offset = {0, 0, 0}, double size = 1.0) {
  TriSurface s;
  for (int i = 0; i < 8; ++i)
    s.vertices.push_back(
        {offset[0] + size * (i & 1), offset[1] + size * ((i >> 1) & 1), offset[2] + size * ((i >> 2) & 1)});
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    s.triangles.push_back({q[0], q[1], q[2]});
    s.triangles.push_back({q[0], q[2], q[3]});
  }
  return s;
}

TriSurface merged(TriSurface a, const TriSurface& b) {
  const int n = static_cast<int>(a.vertices.size());
  a.vertices.insert(a.vertices.end(), b.vertices.begin(), b.vertices.end());
  for (auto t : b.triangles) a.triangles.push_back({t[0] + n, t[1] + n, t[2] + n});
  return a;
}

void flip(TriSurface& s) {
  for (auto& t : s.triangles) std::swap(t[1], t[2]);
}

bool any_contains(const std::vector<std::string>& lines, const std::string& fragment) {
  return std::any_of(lines.begin(), lines.end(),
                     [&](const std::string& l) { return l.find(fragment) != l.npos; });
}

std::string joined(const std::vector<std::string>& lines) {
  std::string s;
  for (const auto& l : lines) s += l + "\n";
  return s;
}

TEST(SurfaceCheck, RealJawChecksClean) {
  TriSurface jaw = read_surface(shared_data("jaw/jaw_smooth.stl"));
  const auto start = std::chrono::steady_clock::now();
  const SurfaceReport r = check_surface(jaw, "jaw_smooth.stl");
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  RecordProperty("check_seconds", std::to_string(seconds));
  EXPECT_EQ(r.triangles, 41760u);
  EXPECT_EQ(r.vertices, 20882u);
  EXPECT_EQ(r.components, 1u);
  EXPECT_TRUE(r.closed);
  EXPECT_TRUE(r.manifold);
  EXPECT_EQ(r.open_edges + r.non_manifold_edges + r.non_manifold_vertices, 0u);
  EXPECT_TRUE(r.consistently_oriented);
  EXPECT_TRUE(r.outward);
  EXPECT_EQ(r.self_intersections, 0u);
  EXPECT_EQ(r.degenerate_triangles, 0u);
  EXPECT_EQ(r.euler_characteristic, 2);
  EXPECT_EQ(r.genus, 0);
  EXPECT_NEAR(r.volume_mm3, 57600.0, 0.005 * 57600.0);
  EXPECT_NEAR(r.bbox_max[0] - r.bbox_min[0], 117.7, 0.1);
  EXPECT_NEAR(r.bbox_max[1] - r.bbox_min[1], 87.2, 0.1);
  EXPECT_NEAR(r.bbox_max[2] - r.bbox_min[2], 76.9, 0.1);
  EXPECT_NEAR(r.min_angle_deg, 1.2, 0.05);
  ASSERT_EQ(r.min_angle_histogram.size(), 12u);
  std::size_t total = 0;
  for (std::size_t n : r.min_angle_histogram) total += n;
  EXPECT_EQ(total, r.triangles);
  EXPECT_GT(r.min_angle_histogram[0], 0u);  // the smallest angle, 1.2 degrees, lies in [0, 5)
  // A binary STL stores three corners per triangle: merging them is the one repair.
  ASSERT_EQ(r.repairs.size(), 1u);
  EXPECT_NE(r.repairs[0].find("merged 104398 duplicate vertices"), std::string::npos) << r.repairs[0];
  EXPECT_TRUE(r.usable()) << joined(r.problems);
}

TEST(SurfaceCheck, FlippedJawIsTurnedOutward) {
  TriSurface jaw = read_surface(shared_data("jaw/jaw_smooth.stl"));
  TriSurface reference = jaw;
  const SurfaceReport good = check_surface(reference);
  flip(jaw);
  const SurfaceReport r = check_surface(jaw);
  EXPECT_TRUE(r.usable()) << joined(r.problems);
  EXPECT_TRUE(r.outward);
  EXPECT_TRUE(any_contains(r.repairs, "reversed the orientation of all 41760 triangles"))
      << joined(r.repairs);
  EXPECT_NEAR(r.volume_mm3, good.volume_mm3, 1e-9 * good.volume_mm3);
  EXPECT_TRUE(jaw.triangles == reference.triangles);  // exactly the original orientation again
}

TEST(SurfaceCheck, CubeStlWithDuplicatedVerticesIsMerged) {
  const std::string path = temp_dir() + "/cube.stl";
  write_surface(path, unit_cube());
  TriSurface s = read_surface(path);
  ASSERT_EQ(s.vertices.size(), 36u);
  const SurfaceReport r = check_surface(s);
  EXPECT_EQ(r.vertices, 8u);
  EXPECT_EQ(s.vertices.size(), 8u);
  EXPECT_TRUE(any_contains(r.repairs, "merged 28 duplicate vertices")) << joined(r.repairs);
  EXPECT_TRUE(r.usable());
  EXPECT_NEAR(r.volume_mm3, 1.0, 1e-12);
  EXPECT_EQ(r.min_angle_histogram[9], 12u);  // right isosceles triangles: 45 degrees
  EXPECT_DOUBLE_EQ(r.min_angle_deg, 45.0);
}

TEST(SurfaceCheck, UnusedVerticesAreDropped) {
  TriSurface s = unit_cube();
  s.vertices.insert(s.vertices.begin(), Vec3{5, 5, 5});
  for (auto& t : s.triangles)
    for (int& v : t) ++v;
  const SurfaceReport r = check_surface(s);
  EXPECT_TRUE(any_contains(r.repairs, "removed 1 vertex not used")) << joined(r.repairs);
  EXPECT_TRUE(s.vertices == unit_cube().vertices);
  EXPECT_TRUE(s.triangles == unit_cube().triangles);
  EXPECT_EQ(r.bbox_max[0], 1.0);  // the unused vertex does not count in the bounding box
}

TEST(SurfaceCheck, OpenSurfaceIsLocated) {
  TriSurface s = unit_cube();
  s.triangles.erase(s.triangles.begin() + 3);
  const SurfaceReport r = check_surface(s);
  EXPECT_FALSE(r.closed);
  EXPECT_EQ(r.open_edges, 3u);
  EXPECT_EQ(r.genus, -1);
  EXPECT_FALSE(r.usable());
  ASSERT_EQ(r.problems.size(), 1u);
  EXPECT_NE(r.problems[0].find("3 open edges"), std::string::npos);
  EXPECT_NE(r.problems[0].find("from (0, 0, 1) to"), std::string::npos) << r.problems[0];
  EXPECT_THROW(
      {
        const std::string path = temp_dir() + "/open.obj";
        write_surface(path, s);
        load_closed_surface(path, 1.0);
      },
      InputError);
}

TEST(SurfaceCheck, NonManifoldEdgeAndVertex) {
  // A fin: a third triangle on the cube's edge 0-1.
  TriSurface fin = unit_cube();
  fin.vertices.push_back({0.5, -1, -1});
  fin.triangles.push_back({0, 1, 8});
  SurfaceReport r = check_surface(fin);
  EXPECT_EQ(r.non_manifold_edges, 1u);
  EXPECT_FALSE(r.manifold);
  EXPECT_TRUE(any_contains(r.problems, "1 non-manifold edge (shared by more than two triangles)"));
  EXPECT_TRUE(any_contains(r.problems, "shared by triangles 1, 4, 12")) << joined(r.problems);

  // Two cubes touching at one corner: (1, 1, 1) is a non-manifold vertex, and the only one.
  TriSurface touching = merged(unit_cube(), unit_cube({1, 1, 1}));
  r = check_surface(touching);
  EXPECT_TRUE(any_contains(r.repairs, "merged 1 duplicate vertex"));
  EXPECT_EQ(r.non_manifold_vertices, 1u);
  EXPECT_EQ(r.non_manifold_edges, 0u);
  EXPECT_TRUE(r.closed);
  EXPECT_TRUE(any_contains(r.problems, "at (1, 1, 1)")) << joined(r.problems);
}

TEST(SurfaceCheck, InconsistentOrientation) {
  TriSurface s = unit_cube();
  std::swap(s.triangles[7][1], s.triangles[7][2]);
  const SurfaceReport r = check_surface(s);
  EXPECT_FALSE(r.consistently_oriented);
  EXPECT_EQ(r.inconsistent_edges, 3u);
  EXPECT_TRUE(r.closed);
  EXPECT_TRUE(r.manifold);
  EXPECT_TRUE(any_contains(r.problems, "inconsistent orientation: 3 edges")) << joined(r.problems);
}

TEST(SurfaceCheck, SelfIntersectionsAndDegenerateTriangles) {
  TriSurface overlapping = merged(unit_cube(), unit_cube({0.5, 0.5, 0.5}));
  SurfaceReport r = check_surface(overlapping);
  EXPECT_EQ(r.components, 2u);
  EXPECT_GT(r.self_intersections, 0u);
  EXPECT_TRUE(any_contains(r.problems, "self-intersections:")) << joined(r.problems);

  TriSurface flat = unit_cube();
  flat.vertices.push_back({0.5, 0, 0});  // midpoint of edge 0-1: triangle 0, 8, 1 has zero area
  flat.triangles.push_back({0, 8, 1});
  flat.triangles.push_back({2, 2, 3});  // a repeated corner
  r = check_surface(flat);
  EXPECT_EQ(r.degenerate_triangles, 2u);
  EXPECT_TRUE(any_contains(r.problems, "2 degenerate triangles")) << joined(r.problems);
  EXPECT_TRUE(any_contains(r.problems, "triangle 12 with corners (0, 0, 0), (0.5, 0, 0), (1, 0, 0)"));
  EXPECT_DOUBLE_EQ(r.min_angle_deg, 0.0);
  EXPECT_EQ(r.min_angle_histogram[0], 2u);
}

TEST(SurfaceCheck, GenusAndComponents) {
  TriSurface ring = torus(24, 12);
  SurfaceReport r = check_surface(ring);
  EXPECT_TRUE(r.usable()) << joined(r.problems);
  EXPECT_EQ(r.euler_characteristic, 0);
  EXPECT_EQ(r.genus, 1);
  EXPECT_GT(r.volume_mm3, 0.0);

  // Two separate cubes: genus 0 each, volumes add up.
  TriSurface two = merged(unit_cube(), unit_cube({3, 0, 0}, 2.0));
  r = check_surface(two);
  EXPECT_TRUE(r.usable()) << joined(r.problems);
  EXPECT_EQ(r.components, 2u);
  EXPECT_EQ(r.euler_characteristic, 4);
  EXPECT_EQ(r.genus, 0);
  EXPECT_NEAR(r.volume_mm3, 9.0, 1e-12);

  // A cube with a cavity (inner cube facing inward) bounds a volume as it is: no repair.
  TriSurface inner = unit_cube({1, 1, 1}, 1.0);
  flip(inner);
  TriSurface hollow = merged(unit_cube({0, 0, 0}, 3.0), inner);
  r = check_surface(hollow);
  EXPECT_TRUE(r.usable()) << joined(r.problems);
  EXPECT_TRUE(r.outward);
  EXPECT_TRUE(r.repairs.empty()) << joined(r.repairs);
  EXPECT_NEAR(r.volume_mm3, 26.0, 1e-12);

  // All of it inside out: one flip repairs it.
  flip(hollow);
  r = check_surface(hollow);
  EXPECT_TRUE(r.usable()) << joined(r.problems);
  EXPECT_TRUE(any_contains(r.repairs, "reversed the orientation"));
  EXPECT_NEAR(r.volume_mm3, 26.0, 1e-12);

  // Outer shell and cavity both facing outward: no single flip helps, the cavity is named and there is
  // no volume (the sum of both, 28, was reported).
  TriSurface wrong = merged(unit_cube({0, 0, 0}, 3.0), unit_cube({1, 1, 1}, 1.0));
  r = check_surface(wrong);
  EXPECT_FALSE(r.usable());
  EXPECT_FALSE(r.volume_defined());
  EXPECT_TRUE(
      any_contains(r.problems,
                   "the closed components are oriented inconsistently with each other and no single "
                   "flip makes the surface bound a volume: 1 component of 2 faces against the others, "
                   "e.g. component 1 of 12 triangles (the first is triangle 12) from (1, 1, 1) to (2, 2, "
                   "2), a cavity facing outward. Reverse the triangles of the components named"))
      << joined(r.problems);
}

TEST(SurfaceCheck, ShellFacingInwardBesideOneFacingOutwardIsNamed) {
  // Two separate cubes, the second inside out: the second is named; the volume is undefined (0 was reported).
  TriSurface inward = unit_cube({3, 0, 0}, 2.0);
  flip(inward);
  TriSurface two = merged(unit_cube(), inward);
  SurfaceReport r = check_surface(two);
  EXPECT_FALSE(r.usable());
  EXPECT_FALSE(r.volume_defined());
  EXPECT_TRUE(any_contains(r.problems,
                           "1 component of 2 faces against the others, e.g. component 1 of 12 "
                           "triangles (the first is triangle 12) from (3, 0, 0) to (5, 2, 2), an "
                           "outer shell facing inward."))
      << joined(r.problems);

  // Three inward beside one outward: reversing the outward one (the global flip does the rest) is the
  // smaller repair, so that one is named.
  TriSurface four = merged(merged(merged(unit_cube(), inward), inward), inward);
  for (std::size_t v = 16; v < four.vertices.size(); ++v) four.vertices[v][1] += v < 24 ? 3.0 : 6.0;
  r = check_surface(four);
  EXPECT_EQ(r.components, 4u);
  EXPECT_TRUE(any_contains(r.problems,
                           "1 component of 4 faces against the others, e.g. component 0 of 12 "
                           "triangles (the first is triangle 0) from (0, 0, 0) to (1, 1, 1), an "
                           "outer shell facing outward."))
      << joined(r.problems);
}

}  // namespace
}  // namespace hexbite
