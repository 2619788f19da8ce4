// Readers and writers: every format round-trips known closed meshes with identical geometry, the
// text variants of each format are parsed, and each kind of bad file fails with its own message.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <map>

#include "common/error.h"
#include "mesher/surface_check.h"
#include "mesher/surface_io.h"
#include "tests/test_util.h"

namespace hexbite {
namespace {

using test::read_file;
using test::temp_dir;
using test::write_file;

// A cube [-1, 1]^3 with n x n squares per face, two triangles each, counter-clockwise from outside.
// With n a power of two every coordinate is exact in float, so even STL keeps the geometry exactly.
TriSurface subdivided_cube(int n) {
  TriSurface s;
  std::map<Vec3, int> index;
  auto vertex = [&](const Vec3& p) {
    auto [it, inserted] = index.emplace(p, static_cast<int>(s.vertices.size()));
    if (inserted) s.vertices.push_back(p);
    return it->second;
  };
  for (int axis = 0; axis < 3; ++axis)
    for (int sign : {-1, 1}) {
      // (u, v, axis) is a cyclic permutation of (x, y, z), so e_u x e_v = e_axis.
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      auto point = [&](int i, int j) {
        Vec3 p{};
        p[axis] = sign;
        p[u] = -1.0 + 2.0 * i / n;
        p[v] = -1.0 + 2.0 * j / n;
        return vertex(p);
      };
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          int q[4] = {point(i, j), point(i + 1, j), point(i + 1, j + 1), point(i, j + 1)};
          if (sign < 0) std::swap(q[1], q[3]);
          s.triangles.push_back({q[0], q[1], q[2]});
          s.triangles.push_back({q[0], q[2], q[3]});
        }
    }
  return s;
}

// An icosahedron subdivided `levels` times and projected onto the sphere of radius 10; coordinates
// are rounded so that every format (STL stores floats) holds them exactly.
TriSurface icosphere(int levels) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec3> v = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                         {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  std::vector<std::array<int, 3>> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                       {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<int, int>, int> midpoint;
    auto mid = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      auto it = midpoint.find(key);
      if (it != midpoint.end()) return it->second;
      v.push_back({(v[a][0] + v[b][0]) / 2, (v[a][1] + v[b][1]) / 2, (v[a][2] + v[b][2]) / 2});
      return midpoint[key] = static_cast<int>(v.size()) - 1;
    };
    std::vector<std::array<int, 3>> next;
    for (const auto& tri : f) {
      const int a = mid(tri[0], tri[1]), b = mid(tri[1], tri[2]), c = mid(tri[2], tri[0]);
      next.push_back({tri[0], a, c});
      next.push_back({tri[1], b, a});
      next.push_back({tri[2], c, b});
      next.push_back({a, b, c});
    }
    f = next;
  }
  // Rounding to a 2^-20 grid keeps 24 significant bits for |x| <= 10, so the values are exact floats.
  auto on_grid = [](double x) { return std::round(x * 1048576.0) / 1048576.0; };
  TriSurface s;
  for (const Vec3& p : v) {
    const double r = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    s.vertices.push_back({on_grid(10 * p[0] / r), on_grid(10 * p[1] / r), on_grid(10 * p[2] / r)});
  }
  s.triangles = f;
  return s;
}

// The geometry of a surface independent of its vertex numbering: each triangle as its three
// corner points, rotated to start at the smallest (which keeps the orientation), then sorted.
using Corners = std::array<Vec3, 3>;
std::vector<Corners> geometry(const TriSurface& s) {
  std::vector<Corners> g;
  for (const auto& t : s.triangles) {
    Corners c{s.vertices[t[0]], s.vertices[t[1]], s.vertices[t[2]]};
    std::rotate(c.begin(), std::min_element(c.begin(), c.end()), c.end());
    g.push_back(c);
  }
  std::sort(g.begin(), g.end());
  return g;
}

void expect_same_geometry(const TriSurface& expected, TriSurface actual, const std::string& what) {
  const SurfaceReport r = check_surface(actual, what);
  EXPECT_TRUE(r.usable()) << what;
  EXPECT_TRUE(r.closed && r.manifold && r.outward) << what;
  EXPECT_EQ(r.genus, 0) << what;
  EXPECT_EQ(actual.vertices.size(), expected.vertices.size()) << what;
  EXPECT_EQ(actual.triangles.size(), expected.triangles.size()) << what;
  EXPECT_TRUE(geometry(actual) == geometry(expected)) << what << ": geometry changed in the round trip";
}

// Expects `f` to throw InputError whose message contains every fragment.
void expect_input_error(const std::function<void()>& f, const std::vector<std::string>& fragments) {
  try {
    f();
    ADD_FAILURE() << "no InputError thrown; expected one containing '" << fragments.front() << "'";
  } catch (const InputError& e) {
    for (const auto& fragment : fragments)
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos)
          << "message '" << e.what() << "' lacks '" << fragment << "'";
  }
}

class RoundTrip : public ::testing::TestWithParam<std::string> {};

TEST_P(RoundTrip, CubeAndIcosphereKeepTheirGeometry) {
  const std::string dir = temp_dir();
  for (const auto& [name, mesh] :
       {std::pair{std::string("cube"), subdivided_cube(4)}, std::pair{std::string("sphere"), icosphere(2)}}) {
    const std::string path = dir + "/" + name + "." + GetParam();
    write_surface(path, mesh);
    expect_same_geometry(mesh, read_surface(path), path);
  }
}

TEST_P(RoundTrip, WritingIsDeterministic) {
  const std::string dir = temp_dir();
  const TriSurface mesh = icosphere(1);
  write_surface(dir + "/a." + GetParam(), mesh);
  write_surface(dir + "/b." + GetParam(), mesh);
  const std::string a = read_file(dir + "/a." + GetParam());
  EXPECT_FALSE(a.empty());
  EXPECT_EQ(a, read_file(dir + "/b." + GetParam()));
}

TEST_P(RoundTrip, UpperCaseExtensionAndUnits) {
  std::string ext = GetParam();
  std::transform(ext.begin(), ext.end(), ext.begin(), ::toupper);
  const std::string path = temp_dir() + "/cube." + ext;
  write_surface(path, subdivided_cube(2));
  TriSurface s = read_surface(path, 10.0);  // as if the file were in cm
  const SurfaceReport r = check_surface(s);
  EXPECT_DOUBLE_EQ(r.bbox_min[0], -10.0);
  EXPECT_DOUBLE_EQ(r.bbox_max[2], 10.0);
  EXPECT_NEAR(r.volume_mm3, 8000.0, 1e-9);
}

INSTANTIATE_TEST_SUITE_P(Formats, RoundTrip, ::testing::Values("stl", "obj", "off", "ply", "vtp"));

TEST(SurfaceIo, BinaryStlIsASoupAndIsMergedBack) {
  const std::string path = temp_dir() + "/cube.stl";
  const TriSurface cube = subdivided_cube(2);
  write_surface(path, cube);
  EXPECT_EQ(read_file(path).size(), 84 + 50 * cube.triangles.size());
  TriSurface s = read_surface(path);
  EXPECT_EQ(s.vertices.size(), 3 * cube.triangles.size());  // as stored: three corners per record
  expect_same_geometry(cube, s, path);
}

TEST(SurfaceIo, BinaryStlWhoseHeaderSaysSolid) {
  // Many exporters start a binary header with "solid"; the size rule must still see binary.
  const std::string path = temp_dir() + "/solid.stl";
  const TriSurface cube = subdivided_cube(1);
  write_surface(path, cube);
  std::string bytes = read_file(path);
  bytes.replace(0, 11, "solid cube ");
  write_file(path, bytes);
  expect_same_geometry(cube, read_surface(path), path);
}

TEST(SurfaceIo, AsciiStl) {
  const TriSurface cube = subdivided_cube(2);
  std::string text = "solid cube\n";
  for (const auto& t : cube.triangles) {
    text += "  facet normal 0 0 0\r\n    outer loop\n";
    for (int v : t) {
      char line[128];
      std::snprintf(line, sizeof line, "      vertex %.17g %+.17g %.17g\n", cube.vertices[v][0],
                    cube.vertices[v][1], cube.vertices[v][2]);
      text += line;
    }
    text += "    endloop\n  endfacet\n";
  }
  text += "endsolid cube\n";
  const std::string path = temp_dir() + "/ascii.stl";
  write_file(path, text);
  expect_same_geometry(cube, read_surface(path), path);
  // A solid named in UTF-8 is still text: it was read as a corrupt binary STL ("its header announces
  // 170926128 triangles").
  const std::string named = temp_dir() + "/named.stl";
  const std::string name =
      "Unterkiefer_r\xc3\xa4"  // a-umlaut
      "chts";
  write_file(named, "solid " + name + text.substr(text.find('\n'), text.rfind("endsolid") - text.find('\n')) +
                        "endsolid " + name + "\n");
  expect_same_geometry(cube, read_surface(named), named);
}

// Keywords in upper case were "text that does not begin with 'solid'"; a file with all of it on one line
// "contains no triangles" (everything was the solid's name).
TEST(SurfaceIo, AsciiStlKeywordsInAnyCaseAndStatementsOnOneLine) {
  const std::string facet =
      "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n";
  std::string upper = "SOLID PART\n" + facet + "ENDSOLID PART\n";
  std::transform(upper.begin(), upper.end(), upper.begin(), [](unsigned char c) { return std::toupper(c); });
  const std::string dir = temp_dir();
  write_file(dir + "/upper.stl", upper);
  TriSurface s = read_surface(dir + "/upper.stl");
  ASSERT_EQ(s.triangles.size(), 1u);
  EXPECT_EQ(s.vertices[1], (Vec3{1, 0, 0}));

  std::string one_line = "solid my part " + facet + facet + "endsolid my part";
  std::replace(one_line.begin(), one_line.end(), '\n', ' ');
  write_file(dir + "/one_line.stl", one_line + "\n");
  s = read_surface(dir + "/one_line.stl");
  ASSERT_EQ(s.triangles.size(), 2u);
  EXPECT_EQ(s.vertices[5], (Vec3{0, 1, 0}));
  // A number too many is still named, on one line as on several.
  one_line.replace(one_line.find("vertex 1 0 0"), 12, "vertex 1 0 0 7");
  write_file(dir + "/four.stl", one_line + "\n");
  expect_input_error([&] { read_surface(dir + "/four.stl"); },
                     {"line 1", "expected 'vertex x y z' with three numbers"});
}

// Unit cube corners: vertex i has x = bit 0, y = bit 1, z = bit 2; faces as outward quads.
const char* const kCubeVertices = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n";

TEST(SurfaceIo, ObjFaceFormsNegativeIndicesAndPolygons) {
  // Quads are fanned; v/t, v//n, v/t/n and negative (relative) indices all name the same corners.
  const std::string text = std::string("# cube\no cube\n") + kCubeVertices +
                           "vt 0 0\nvn 0 0 1\ng faces\ns off\nusemtl bone\n"
                           "f 1 3 4 2\n"
                           "f 5/1 6/1 8/1 7/1\n"
                           "f 1//1 2//1 6//1 5//1\n"
                           "f 3/1/1 7/1/1 8/1/1 4/1/1\n"
                           "f -8 -4 -2 -6\n"
                           "f -7 -5 -1 -3\n";
  const std::string path = temp_dir() + "/cube.obj";
  write_file(path, text);
  TriSurface s = read_surface(path);
  EXPECT_EQ(s.triangles.size(), 12u);
  const SurfaceReport r = check_surface(s);
  EXPECT_TRUE(r.usable()) << (r.problems.empty() ? "" : r.problems[0]);
  EXPECT_TRUE(r.outward);
  EXPECT_NEAR(r.volume_mm3, 1.0, 1e-12);
}

TEST(SurfaceIo, OffWithCommentsPolygonsAndColours) {
  const std::string text =
      "OFF # a unit cube\n8 6 12\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n0 0 1\n1 0 1\n0 1 1\n1 1 1\n\n"
      "4 0 2 3 1\n4 4 5 7 6 255 0 0\n4 0 1 5 4\n4 2 6 7 3\n4 0 4 6 2\n4 1 3 7 5\n";
  const std::string path = temp_dir() + "/cube.off";
  write_file(path, text);
  TriSurface s = read_surface(path);
  EXPECT_EQ(s.triangles.size(), 12u);
  const SurfaceReport r = check_surface(s);
  EXPECT_TRUE(r.usable());
  EXPECT_NEAR(r.volume_mm3, 1.0, 1e-12);
}

// OFF is whitespace-delimited: several vertices on a line were read as one vertex and "colours", the face
// lines then as vertices, ending in "it was cut off". Without a C in the header a vertex has no colour, so
// the line's values are whole vertices; with one (COFF), one vertex per line.
TEST(SurfaceIo, OffWithSeveralVerticesOnALine) {
  const std::string dir = temp_dir();
  const std::string faces = "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
  write_file(dir + "/pairs.off", "OFF\n4 4 0\n0 0 0 10 0 0\n0 10 0 0 0 10\n" + faces);
  TriSurface s = read_surface(dir + "/pairs.off");
  ASSERT_EQ(s.vertices.size(), 4u);
  EXPECT_EQ(s.vertices[3], (Vec3{0, 0, 10}));
  EXPECT_TRUE(check_surface(s).usable());
  write_file(dir + "/normals.off",
             "NOFF\n4 4 0\n0 0 0 0 0 1 10 0 0 0 0 1\n0 10 0 0 0 1\n0 0 10 0 0 1\n" + faces);
  EXPECT_EQ(read_surface(dir + "/normals.off").vertices.at(1), (Vec3{10, 0, 0}));
  write_file(dir + "/colours.off",
             "COFF\n4 4 0\n0 0 0 255 0 0 255\n10 0 0 255 0 0\n0 10 0 1 1 1 1\n0 0 10 0 0 0 1\n" + faces);
  EXPECT_EQ(read_surface(dir + "/colours.off").vertices.at(3), (Vec3{0, 0, 10}));

  // What is not whole vertices is named with its line.
  write_file(dir + "/seven.off", "OFF\n4 4 0\n0 0 0 255 0 0 255\n10 0 0\n0 10 0\n0 0 10\n" + faces);
  expect_input_error(
      [&] { read_surface(dir + "/seven.off"); },
      {"line 3: malformed OFF line '0 0 0 255 0 0 255'", "vertex 2 as 'x y z'",
       "7 values are not whole vertices of 3 values each", "vertex colours need a COFF header"});
  write_file(dir + "/two_coloured.off",
             "COFF\n4 4 0\n0 0 0 1 1 1 1 10 0 0 1 1 1 1\n0 10 0 1 1 1 1\n0 0 10 1 1 1 1\n" + faces);
  expect_input_error(
      [&] { read_surface(dir + "/two_coloured.off"); },
      {"line 3", "vertex 0 as 'x y z r g b [a]', one vertex per line (the line has 14 values)"});
  write_file(dir + "/spill.off", "OFF\n3 1 0\n0 0 0 1 0 0\n0 1 0 3 0 1 2\n");
  expect_input_error([&] { read_surface(dir + "/spill.off"); },
                     {"line 4", "no more values after vertex 2, the last of the 3 the header announces"});
  write_file(dir + "/two_faces.off", "OFF\n4 4 0\n0 0 0\n10 0 0\n0 10 0\n0 0 10\n3 0 2 1 3 0 1 3 3 0 3 2\n");
  expect_input_error([&] { read_surface(dir + "/two_faces.off"); },
                     {"line 7", "face 0 as 'k i_1 ... i_k [colour]' on a line of its own",
                      "after its 3 indices come 8 values"});
}

// ASCII PLY records are read by the header's properties: several on a line were one record each, the rest
// of the line dropped.
TEST(SurfaceIo, AsciiPlyWithSeveralRecordsOnALine) {
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 4\nproperty list uchar int vertex_indices\nend_header\n";
  const std::string faces = "3 0 2 1 3 0 1 3\n3 0 3 2\n3 1 2 3\n";
  const std::string dir = temp_dir();
  write_file(dir + "/pairs.ply", header + "0 0 0 10 0 0\n0 10 0 0 0 10\n" + faces);
  TriSurface s = read_surface(dir + "/pairs.ply");
  ASSERT_EQ(s.vertices.size(), 4u);
  EXPECT_EQ(s.vertices[3], (Vec3{0, 0, 10}));
  EXPECT_TRUE(check_surface(s).usable());
  // A record does not continue on the next line.
  write_file(dir + "/split.ply", header + "0 0 0 10 0\n0 0 10 0 0 0 10\n" + faces);
  expect_input_error(
      [&] { read_surface(dir + "/split.ply"); },
      {"line 10: vertex 1 (0-based) starts after value 3 of the line and the line ends inside it",
       "its 5 values are not whole records"});
  write_file(dir + "/more.ply",
             header + "0 0 0 10 0 0\n0 10 0 0 0 10\n" + faces.substr(0, faces.size() - 1) + " 5\n");
  expect_input_error([&] { read_surface(dir + "/more.ply"); },
                     {"line 14: '5' after the elements the header announces"});
}

TEST(SurfaceIo, AsciiPlyWithExtraProperties) {
  const std::string text =
      "ply\nformat ascii 1.0\ncomment unit cube\nelement vertex 8\nproperty float x\nproperty float y\n"
      "property float z\nproperty uchar red\nelement face 6\nproperty list uchar int vertex_indices\n"
      "property list uchar float texcoord\nelement edge 0\nproperty int vertex1\nend_header\n"
      "0 0 0 255\n1 0 0 0\n0 1 0 0\n1 1 0 0\n0 0 1 0\n1 0 1 0\n0 1 1 0\n1 1 1 0\n"
      "4 0 2 3 1 2 0.5 0.5\n4 4 5 7 6 0\n4 0 1 5 4 0\n4 2 6 7 3 0\n4 0 4 6 2 0\n4 1 3 7 5 0\n";
  const std::string path = temp_dir() + "/cube.ply";
  write_file(path, text);
  TriSurface s = read_surface(path);
  EXPECT_EQ(s.triangles.size(), 12u);
  const SurfaceReport r = check_surface(s);
  EXPECT_TRUE(r.usable());
  EXPECT_NEAR(r.volume_mm3, 1.0, 1e-12);
}

// The format lets the face element come before the vertex element; such a file reads like the usual order
// (its faces were said to refer to vertices "out of range: the file has 0 vertices").
TEST(SurfaceIo, PlyWithFacesBeforeVertices) {
  const std::string text =
      "ply\nformat ascii 1.0\nelement face 6\nproperty list uchar int vertex_indices\nelement vertex 8\n"
      "property float x\nproperty float y\nproperty float z\nend_header\n"
      "4 0 2 3 1\n4 4 5 7 6\n4 0 1 5 4\n4 2 6 7 3\n4 0 4 6 2\n4 1 3 7 5\n"
      "0 0 0\n1 0 0\n0 1 0\n1 1 0\n0 0 1\n1 0 1\n0 1 1\n1 1 1\n";
  const std::string dir = temp_dir();
  write_file(dir + "/cube.ply", text);
  TriSurface s = read_surface(dir + "/cube.ply");
  const SurfaceReport r = check_surface(s);
  EXPECT_TRUE(r.usable());
  EXPECT_NEAR(r.volume_mm3, 1.0, 1e-12);
  std::string bad = text;
  bad.replace(bad.find("4 1 3 7 5"), 9, "4 1 3 7 8");
  write_file(dir + "/bad.ply", bad);
  expect_input_error([&] { read_surface(dir + "/bad.ply"); },
                     {"face 5 (0-based) refers to vertex 8", "the file has 8 vertices"});
}

// Data after the counts the header announces (a fifth face under "4 faces", a garbage line) was dropped
// without a word; blank lines and OFF comments after the data are fine.
TEST(SurfaceIoErrors, DataAfterTheAnnouncedCountsIsNamed) {
  const std::string dir = temp_dir();
  const std::string off = "OFF\n4 4 0\n0 0 0\n10 0 0\n0 10 0\n0 0 10\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
  write_file(dir + "/ok.off", off + "\n# end\n");
  EXPECT_EQ(read_surface(dir + "/ok.off").triangles.size(), 4u);
  write_file(dir + "/more.off", off + "3 0 1 2\n");
  expect_input_error([&] { read_surface(dir + "/more.off"); },
                     {"more.off' line 11: '3 0 1 2' after the 4 faces the header announces"});
  write_file(dir + "/more.ply",
             "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
             "element face 3\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n10 0 0\n0 10 0\n0 0 "
             "10\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
  expect_input_error([&] { read_surface(dir + "/more.ply"); },
                     {"more.ply' line 17: '3 1 2 3' after the elements the header announces"});
}

// A second vertex element after an empty one (a damaged header) crashed the reader (exit 139): the first
// one's property places were used for the second.
TEST(SurfaceIoErrors, PlyWithTwoVertexElements) {
  const std::string dir = temp_dir();
  write_file(dir + "/two.ply",
             "ply\nformat ascii 1.0\nelement vertex 3\nelement vertex 3\nproperty float x\nproperty float y\n"
             "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
             "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  expect_input_error([&] { read_surface(dir + "/two.ply"); },
                     {"two.ply' line 4: a second 'element vertex'", "fix the PLY header"});
}

TEST(SurfaceIo, BigEndianPly) {
  std::string bytes =
      "ply\nformat binary_big_endian 1.0\nelement vertex 8\nproperty float x\nproperty float y\n"
      "property float z\nelement face 6\nproperty list uchar int vertex_indices\nend_header\n";
  auto put_be = [&](std::uint32_t u) {
    for (int i = 3; i >= 0; --i) bytes.push_back(static_cast<char>((u >> (8 * i)) & 0xff));
  };
  for (int i = 0; i < 8; ++i)
    for (int axis = 0; axis < 3; ++axis) {
      const float f = static_cast<float>((i >> axis) & 1);
      std::uint32_t u;
      std::memcpy(&u, &f, 4);
      put_be(u);
    }
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    bytes.push_back(4);
    for (int v : q) put_be(static_cast<std::uint32_t>(v));
  }
  const std::string path = temp_dir() + "/cube.ply";
  write_file(path, bytes);
  TriSurface s = read_surface(path);
  const SurfaceReport r = check_surface(s);
  EXPECT_TRUE(r.usable());
  EXPECT_NEAR(r.volume_mm3, 1.0, 1e-12);
}

// --- Bad files: each with its own message that names the file and the place.

TEST(SurfaceIoErrors, MissingFile) {
  expect_input_error([] { read_surface("/nonexistent/jaw.stl"); },
                     {"'/nonexistent/jaw.stl'", "does not exist"});
}

TEST(SurfaceIoErrors, EmptyFile) {
  const std::string path = temp_dir() + "/empty.obj";
  write_file(path, "");
  expect_input_error([&] { read_surface(path); }, {path, "is empty"});
}

// A VTP whose cell data array is too short, without <PointData> (VTK 9.1: a segmentation fault).
TEST(SurfaceIoErrors, VtpWithAShortCellDataArray) {
  const std::string path = temp_dir() + "/short.vtp";
  write_file(
      path,
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\">\n"
      "<PolyData><Piece NumberOfPoints=\"4\" NumberOfPolys=\"4\">\n<CellData><DataArray type=\"Float64\" "
      "Name=\"a\" format=\"ascii\">1</DataArray></CellData>\n<Points><DataArray type=\"Float64\" "
      "NumberOfComponents=\"3\" format=\"ascii\">0 0 0 1 0 0 0 1 0 0 0 1</DataArray></Points>\n<Polys>"
      "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">0 2 1 0 1 3 1 2 3 0 3 2</DataArray>\n"
      "<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">3 6 9 12</DataArray></Polys>\n"
      "</Piece></PolyData></VTKFile>\n");
  expect_input_error([&] { read_surface(path); }, {path, "Cannot read cell data array \"a\""});
}

// Text that is no ASCII STL was "a truncated or corrupt binary STL" announcing 171122740 triangles; an
// ASCII STL behind a UTF-8 byte order mark too.
TEST(SurfaceIoErrors, TextThatIsNoStlIsNamedAndAByteOrderMarkIsSkipped) {
  const std::string dir = temp_dir();
  write_file(dir + "/cube.stl", kCubeVertices + std::string("f 1 2 3\n"));
  expect_input_error(
      [&] { read_surface(dir + "/cube.stl"); },
      {"is not an STL: it is text that does not begin with 'solid'", "it looks like an OBJ file"});
  write_file(dir + "/bom.stl",
             "\xEF\xBB\xBFsolid c\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
             "endloop\nendfacet\nendsolid c\n");
  EXPECT_EQ(read_surface(dir + "/bom.stl").triangles.size(), 1u);
}

// An OBJ behind a UTF-8 byte order mark was refused naming an invisible character glued to its first 'v',
// and a coordinate below the double range (1e-400) was "NaN or infinite": it is read as 0, as strtod does.
TEST(SurfaceIo, ObjByteOrderMarkAndUnderflow) {
  const std::string dir = temp_dir();
  write_file(dir + "/bom.obj",
             "\xEF\xBB\xBFv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1e-400\nv 0 0 1\n"
             "f 1 3 2\nf 1 2 5\nf 1 5 3\nf 2 3 5\n");
  const TriSurface s = read_surface(dir + "/bom.obj");
  EXPECT_EQ(s.triangles.size(), 4u);
  EXPECT_EQ(s.vertices.at(3)[2], 0.0);
}

// OFF and PLY behind a UTF-8 byte order mark were refused ("expected the keyword OFF", "its first line must
// be 'ply'") where OBJ and STL were read.
TEST(SurfaceIo, OffAndPlyByteOrderMarkIsSkipped) {
  const std::string dir = temp_dir();
  write_file(dir + "/bom.off", "\xEF\xBB\xBFOFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  EXPECT_EQ(read_surface(dir + "/bom.off").triangles.size(), 1u);
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  write_file(dir + "/bom.ply", "\xEF\xBB\xBF" + header + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  EXPECT_EQ(read_surface(dir + "/bom.ply").triangles.size(), 1u);
  // Binary data starts after the header, wherever the mark put it.
  const std::string path = dir + "/bom_binary.ply";
  write_surface(path, subdivided_cube(1));
  write_file(path, "\xEF\xBB\xBF" + read_file(path));
  EXPECT_EQ(read_surface(path).triangles.size(), 12u);
}

// A backslash at the end of an OBJ line continues the statement on the next line (Wavefront spec): it was
// "malformed OBJ face line 'f 1 3 \\'". Messages name the lines of a continued statement.
TEST(SurfaceIo, ObjLineContinuation) {
  const std::string dir = temp_dir();
  write_file(dir + "/joined.obj",
             "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 \\\n 1\nf 1 3 \\\n2\nf 1 2 4\nf 1 4 3\\  \r\n\nf 2 3 4\n");
  const TriSurface s = read_surface(dir + "/joined.obj");
  ASSERT_EQ(s.triangles.size(), 4u);
  EXPECT_EQ(s.vertices.at(3), (Vec3{0, 0, 1}));
  EXPECT_EQ(s.triangles[0], (std::array<int, 3>{0, 2, 1}));
  EXPECT_EQ(s.triangles[3], (std::array<int, 3>{1, 2, 3}));
  write_file(dir + "/bad.obj", "v 0 0 0\nv 1 0 \\\nzero\nv 0 1 0\nf 1 2 x\n");
  expect_input_error([&] { read_surface(dir + "/bad.obj"); },
                     {"bad.obj' lines 2-3: malformed OBJ vertex line 'v 1 0 zero'"});
  write_file(dir + "/bad2.obj", "v 0 0 0\nv 1 0 \\\n0\nv 0 1 0\nf 1 2 x\n");
  expect_input_error([&] { read_surface(dir + "/bad2.obj"); }, {"bad2.obj' line 5: malformed OBJ face line"});
}

// A binary STL with bytes after its announced records: fewer than a record (a line end) are ignored with a
// warning (it was "truncated or corrupt ... (extra 1)"); a record or more is a wrong count.
TEST(SurfaceIo, BinaryStlWithTrailingBytes) {
  const std::string path = temp_dir() + "/trailing.stl";
  write_surface(path, subdivided_cube(1));  // 12 triangles: 684 bytes
  const std::string bytes = read_file(path);
  write_file(path, bytes + "\n");
  testing::internal::CaptureStderr();
  const TriSurface s = read_surface(path);
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_EQ(s.triangles.size(), 12u);
  EXPECT_NE(
      err.find("hexbite: warning: '" + path +
               "': its header announces 12 triangles, which take 84 + 50 x 12 = 684 bytes, but the file "
               "has 685 bytes (1 more, less than a triangle record); the 12 triangles are read and the "
               "extra bytes ignored"),
      std::string::npos)
      << err;
  write_file(path, bytes + bytes.substr(84, 50));
  expect_input_error([&] { read_surface(path); },
                     {"is a corrupt binary STL: its header announces 12 triangles",
                      "the file has 734 bytes, 50 more", "the count is wrong or other data was appended"});
}

// Counts beyond 2^31 - 1 were "expected the counts ... as non-negative integers".
TEST(SurfaceIoErrors, CountsBeyondWhatIsReadAreNamed) {
  const std::string dir = temp_dir();
  write_file(dir + "/big.off", "OFF\n4000000000 4 0\n0 0 0\n");
  expect_input_error(
      [&] { read_surface(dir + "/big.off"); },
      {"big.off' line 2: the header announces 4000000000 vertices, more than hexbite reads (at "
       "most 2147483647 = 2^31 - 1)"});
  write_file(dir + "/big.ply",
             "ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\nend_header\n");
  expect_input_error(
      [&] { read_surface(dir + "/big.ply"); },
      {"big.ply' line 3: 'element vertex' announces 4000000000 records, more than hexbite reads"});
}

// Coordinates of a kilometre and more: `surface check` called such a surface usable and wrote an STL of
// infinities (1e40 does not fit a float), `mesh` stopped on a CGAL assertion (1e16).
TEST(SurfaceIoErrors, CoordinatesBeyondAKilometreAreRefused) {
  const std::string path = temp_dir() + "/huge.obj";
  write_file(path, "v 0 0 0\nv 1e16 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
  expect_input_error([&] { read_surface(path); },
                     {"vertex 1 (0-based) has the x coordinate 1e+16 mm, beyond 1e+06 mm in size"});
  EXPECT_EQ(read_surface(path, 1e-12).triangles.size(), 4u);  // the limit is on millimetres
}

TEST(SurfaceIoErrors, UnknownExtension) {
  const std::string path = temp_dir() + "/cube.xyz";
  write_file(path, kCubeVertices);
  expect_input_error([&] { read_surface(path); },
                     {"unknown extension '.xyz'", ".stl, .obj, .ply, .off, .vtp"});
  expect_input_error([&] { write_surface(path, subdivided_cube(1)); }, {"unknown extension '.xyz'"});
}

TEST(SurfaceIoErrors, TruncatedBinaryStl) {
  const std::string path = temp_dir() + "/cut.stl";
  write_surface(path, subdivided_cube(1));  // 12 triangles: 684 bytes
  write_file(path, read_file(path).substr(0, 600));
  expect_input_error([&] { read_surface(path); },
                     {"truncated", "12 triangles", "684 bytes", "has 600 bytes"});
  write_file(path, std::string(40, '\x01'));
  expect_input_error([&] { read_surface(path); }, {"truncated", "84", "has 40 bytes"});
}

TEST(SurfaceIoErrors, TruncatedBinaryPly) {
  const std::string path = temp_dir() + "/cut.ply";
  write_surface(path, subdivided_cube(1));
  const std::string bytes = read_file(path);
  write_file(path, bytes.substr(0, bytes.size() - 7));
  expect_input_error([&] { read_surface(path); }, {"ends in face 11 (0-based) of the 12", "cut off"});
  write_file(path, bytes.substr(0, bytes.find("end_header") + 11 + 8 * 3 * 3 + 4));
  expect_input_error([&] { read_surface(path); }, {"ends in vertex 3 (0-based) of the 8"});
}

// Bytes after a binary PLY's announced elements (a thirteenth triangle under "12 faces") were dropped
// without a word, as ASCII lines were; a line end after the data is fine.
TEST(SurfaceIoErrors, BytesAfterABinaryPlysElementsAreNamed) {
  const std::string path = temp_dir() + "/more.ply";
  write_surface(path, subdivided_cube(1));
  const std::string bytes = read_file(path);
  write_file(path, bytes + "\n");
  EXPECT_EQ(read_surface(path).triangles.size(), 12u);
  write_file(path, bytes + bytes.substr(bytes.size() - 13));
  expect_input_error([&] { read_surface(path); },
                     {"more.ply': 13 bytes follow the elements the header announces",
                      "from byte " + std::to_string(bytes.size()), "fix the counts"});
}

TEST(SurfaceIoErrors, NonFiniteCoordinates) {
  const std::string dir = temp_dir();
  write_file(dir + "/nan.obj", "v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n");
  expect_input_error([&] { read_surface(dir + "/nan.obj"); }, {"line 3", "y coordinate is NaN"});
  write_file(dir + "/inf.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 0 -inf\n3 0 1 2\n");
  expect_input_error([&] { read_surface(dir + "/inf.off"); }, {"line 5", "z coordinate is infinite"});
  write_file(
      dir + "/big.stl",
      "solid x\nfacet normal 0 0 1\nouter loop\nvertex 1e999 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\n"
      "endfacet\nendsolid\n");
  expect_input_error([&] { read_surface(dir + "/big.stl"); }, {"line 4", "x coordinate is infinite"});

  // Binary STL: the record and corner are named.
  const std::string path = dir + "/nan.stl";
  write_surface(path, subdivided_cube(1));
  std::string bytes = read_file(path);
  const float nan = std::nanf("");
  std::memcpy(&bytes[84 + 50 * 7 + 12 + 12 * 2 + 4], &nan, 4);  // record 7, corner 2, y
  write_file(path, bytes);
  expect_input_error([&] { read_surface(path); }, {"triangle record 7", "corner 2", "y coordinate is NaN"});
}

TEST(SurfaceIoErrors, OutOfRangeIndices) {
  const std::string dir = temp_dir();
  write_file(dir + "/a.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 9\n");
  expect_input_error([&] { read_surface(dir + "/a.obj"); },
                     {"line 5", "face index 9 is out of range", "only 3"});
  write_file(dir + "/b.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n");
  expect_input_error([&] { read_surface(dir + "/b.obj"); }, {"line 4", "face index -4 is out of range"});
  write_file(dir + "/c.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n");
  expect_input_error([&] { read_surface(dir + "/c.obj"); }, {"line 4", "start at 1"});
  write_file(dir + "/d.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n");
  expect_input_error([&] { read_surface(dir + "/d.off"); },
                     {"line 6", "face 0 refers to vertex 3", "out of range"});
  write_file(
      dir + "/e.ply",
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
  expect_input_error([&] { read_surface(dir + "/e.ply"); }, {"face 0", "vertex 7", "out of range"});
}

// Binary bytes in a text line are shown as \xNN: a NUL byte cut the message there (what() is a C string), and
// the advice after the quoted line was lost.
TEST(SurfaceIoErrors, BinaryBytesInALineKeepTheMessageWhole) {
  const std::string dir = temp_dir();
  write_file(dir + "/a.obj", std::string("v 0 0 0\nv 0 0 \0\x01x 0\n", 20));
  expect_input_error(
      [&] { read_surface(dir + "/a.obj"); },
      {"line 2", "malformed OBJ vertex line 'v 0 0 \\x00\\x01x 0'", "export the surface again"});
  EXPECT_EQ(InputError(std::string("a\0b\x7f\nc\td\xc3\xa9", 10)).what(),
            std::string("a\\x00b\\x7f\nc\td\xc3\xa9"));
}

TEST(SurfaceIoErrors, MalformedLines) {
  const std::string dir = temp_dir();
  write_file(dir + "/a.obj", "v 0 0 0\nv 1 0\n");
  expect_input_error([&] { read_surface(dir + "/a.obj"); }, {"line 2", "malformed OBJ vertex line 'v 1 0'"});
  write_file(dir + "/b.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n");
  expect_input_error([&] { read_surface(dir + "/b.obj"); }, {"line 4", "malformed OBJ face line"});
  write_file(dir + "/c.obj", "v 0 0 0\nhello world\n");
  expect_input_error([&] { read_surface(dir + "/c.obj"); }, {"line 2", "'hello' is not an OBJ statement"});
  write_file(dir + "/d.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 zero\n");
  expect_input_error([&] { read_surface(dir + "/d.stl"); },
                     {"line 5", "malformed ASCII STL line 'vertex 1 0 zero'"});
  write_file(dir + "/e.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n");
  expect_input_error([&] { read_surface(dir + "/e.stl"); }, {"ends inside the facet that starts at line 2"});
  write_file(dir + "/f.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n");
  expect_input_error([&] { read_surface(dir + "/f.off"); }, {"vertex 2 of 3", "cut off"});
  // A vertex count beyond memory in a damaged header: std::bad_alloc (exit 1, no file named) before.
  write_file(dir + "/f2.off", "OFF\n2000000000 1 0\n0 0 0\n");
  expect_input_error([&] { read_surface(dir + "/f2.off"); }, {"f2.off", "vertex 1 of 2000000000", "cut off"});
  write_file(dir + "/g.off", "PFF\n3 1 0\n");
  expect_input_error([&] { read_surface(dir + "/g.off"); }, {"line 1", "keyword OFF"});
  write_file(dir + "/h.ply", "not a ply file\n");
  expect_input_error([&] { read_surface(dir + "/h.ply"); }, {"not a valid PLY file"});
  write_file(dir + "/h2.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n");
  expect_input_error([&] { read_surface(dir + "/h2.ply"); }, {"line 4", "unknown property type 'quad'"});
  write_file(dir + "/h3.ply",
             "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
             "end_header\n0 0 0\n1 0 zero\n");
  expect_input_error([&] { read_surface(dir + "/h3.ply"); },
                     {"line 9", "malformed PLY value 'zero' in vertex 1"});
  write_file(dir + "/i.vtp", "<VTKFile type=\"PolyData\"><PolyData><Piece NumberOfPoints=\"3\"");
  expect_input_error([&] { read_surface(dir + "/i.vtp"); }, {"i.vtp"});
  write_file(dir + "/j.obj", "v 0 0 0\nv 1 0 0\n");
  expect_input_error([&] { read_surface(dir + "/j.obj"); }, {"contains no triangles"});
}

}  // namespace
}  // namespace hexbite
