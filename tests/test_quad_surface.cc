// Quad surfaces: reading and writing, the combinatorial check (closed, manifold, genus, even, simple,
// 3-connected, chords) and `hexbite quad check`.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "common/error.h"
#include "mesher/hex_block.h"
#include "mesher/hex_boundary.h"
#include "mesher/hex_mesh_io.h"
#include "mesher/quad_check.h"
#include "mesher/quad_surface_crossings.h"
#include "mesher/quad_surface_io.h"
#include "tests/quad_test_surfaces.h"
#include "tests/test_util.h"

namespace hexbite {
namespace {

std::vector<int> sorted_lengths(const QuadSurfaceReport& r) {
  std::vector<int> lengths;
  for (const Chord& c : r.chords) lengths.push_back(c.length());
  std::sort(lengths.begin(), lengths.end());
  return lengths;
}

// An n x m x k block has one chord per unit slab in each direction: the ring around the slab. A slab across
// x crosses the four faces parallel to x, so its chord has length 2 (m + k); likewise for y and z. So there
// are n + m + k chords and their lengths sum to 2 * quads = 4 (nm + mk + nk).
TEST(QuadCheck, BlockBoundaryChordCountsAndLengths) {
  for (const std::array<int, 3> dims : {std::array<int, 3>{1, 1, 1}, {2, 3, 4}, {3, 1, 2}}) {
    const auto [n, m, k] = dims;
    const QuadSurfaceReport r = check_quad_surface(test::block_surface(n, m, k), "block");
    SCOPED_TRACE(std::to_string(n) + "x" + std::to_string(m) + "x" + std::to_string(k));
    EXPECT_TRUE(r.usable());
    EXPECT_EQ(r.quads, 2 * (n * m + m * k + n * k));
    EXPECT_EQ(r.vertices, r.quads + 2);
    EXPECT_TRUE(r.closed && r.manifold && r.consistently_oriented && r.even && r.simple);
    EXPECT_EQ(r.genus, 0);
    EXPECT_TRUE(r.ball);
    EXPECT_TRUE(r.planar);
    EXPECT_TRUE(r.three_connected);
    std::vector<int> expected;
    for (int i = 0; i < n; ++i) expected.push_back(2 * (m + k));
    for (int i = 0; i < m; ++i) expected.push_back(2 * (n + k));
    for (int i = 0; i < k; ++i) expected.push_back(2 * (n + m));
    std::sort(expected.begin(), expected.end());
    EXPECT_EQ(sorted_lengths(r), expected);
    EXPECT_TRUE(r.self_intersecting_chords.empty());
  }
}

// The L of three unit cubes (2 x 2 x 1 minus one cell) has 14 quads: one horizontal chord around the L
// (length 8) and, per direction x and y, a chord of length 6 around the two-cube column and one of length 4
// around the single cube.
TEST(QuadCheck, LShapedPolycube) {
  const QuadSurface s = test::polycube_surface(2, 2, 1, [](int i, int j, int) { return i == 0 || j == 0; });
  const QuadSurfaceReport r = check_quad_surface(test::perturbed(s, 0.1), "L");
  EXPECT_TRUE(r.usable());
  EXPECT_EQ(r.quads, 14);
  EXPECT_TRUE(r.three_connected);
  EXPECT_EQ(sorted_lengths(r), (std::vector<int>{4, 4, 6, 6, 8}));
}

TEST(QuadCheck, GraphTests) {
  const std::vector<std::array<int, 2>> k4 = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
  EXPECT_TRUE(is_three_connected(4, k4));
  EXPECT_TRUE(is_planar_graph(4, k4));
  // A 6-cycle with one chord is 2-connected only: vertex 1's neighbours 0 and 2 separate it.
  std::vector<int> separator;
  EXPECT_FALSE(is_three_connected(6, {{0, 1}, {1, 2}, {2, 3}, {3, 4}, {4, 5}, {5, 0}, {0, 3}}, &separator));
  EXPECT_EQ(separator, (std::vector<int>{0, 2}));
  // Two K4 glued at two vertices {0, 1}: removing 0 and 1 separates them (all degrees are at least 3).
  EXPECT_FALSE(is_three_connected(
      6, {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}, {0, 4}, {0, 5}, {1, 4}, {1, 5}, {4, 5}},
      &separator));
  EXPECT_EQ(separator, (std::vector<int>{0, 1}));
  std::vector<std::array<int, 2>> k5;
  for (int a = 0; a < 5; ++a)
    for (int b = a + 1; b < 5; ++b) k5.push_back({a, b});
  EXPECT_FALSE(is_planar_graph(5, k5));
  EXPECT_TRUE(is_three_connected(5, k5));
}

// A cube whose top quad is split into two quads through an interior vertex: 7 quads.
QuadSurface odd_surface() {
  QuadSurface s = test::block_surface(1, 1, 1);
  std::array<int, 4> top{};
  for (auto& q : s.quads)
    if (s.vertices[q[0]][2] == 1 && s.vertices[q[1]][2] == 1 && s.vertices[q[2]][2] == 1) top = q;
  s.quads.erase(std::find(s.quads.begin(), s.quads.end(), top));
  const int o = static_cast<int>(s.vertices.size());
  s.vertices.push_back({0.4, 0.6, 1.0});
  s.quads.push_back({top[0], top[1], top[2], o});
  s.quads.push_back({top[0], o, top[2], top[3]});
  return s;
}

TEST(QuadCheck, ProblemsAreNamed) {
  const QuadSurfaceReport odd = check_quad_surface(odd_surface(), "odd");
  EXPECT_FALSE(odd.even);
  ASSERT_FALSE(odd.problems.empty());
  EXPECT_NE(odd.problems[0].find("odd number of quads (7)"), std::string::npos);

  QuadSurface open = test::block_surface(2, 1, 1);
  open.quads.resize(open.quads.size() - 2);
  const QuadSurfaceReport o = check_quad_surface(open, "open");
  EXPECT_FALSE(o.closed);
  EXPECT_GT(o.open_edges, 0);
  EXPECT_FALSE(o.ball);
  EXPECT_NE(o.problems.at(0).find("close the holes"), std::string::npos) << o.problems.at(0);
  // Each problem names its first place (it gave counts only).
  EXPECT_NE(o.problems.at(0).find("(edges in only one quad; the first: edge "), std::string::npos)
      << o.problems.at(0);
  QuadSurface flipped = test::block_surface(2, 1, 1);
  std::reverse(flipped.quads[3].begin(), flipped.quads[3].end());
  const QuadSurfaceReport f = check_quad_surface(flipped, "flipped");
  ASSERT_FALSE(f.problems.empty());
  EXPECT_NE(f.problems.back().find("traversed in the same direction by both quads (the first: edge "),
            std::string::npos)
      << f.problems.back();
  QuadSurface unused = test::block_surface(1, 1, 1);
  unused.vertices.push_back({5, 6, 7});
  EXPECT_NE(check_quad_surface(unused, "unused")
                .problems.at(0)
                .find("1 vertex in no quad (the first: vertex 8 at (5, 6, 7))"),
            std::string::npos);

  // Every quad with its own four corners: every edge is open although the solid is closed. "Close the
  // holes" sent the user looking for holes that are not there.
  QuadSurface unwelded;
  for (const auto& q : test::block_surface(1, 1, 1).quads) {
    std::array<int, 4> own{};
    for (int k = 0; k < 4; ++k) {
      own[k] = static_cast<int>(unwelded.vertices.size());
      unwelded.vertices.push_back(test::block_surface(1, 1, 1).vertices[q[k]]);
    }
    unwelded.quads.push_back(own);
  }
  const QuadSurfaceReport u = check_quad_surface(unwelded, "unwelded");
  EXPECT_EQ(u.open_edges, 24);
  EXPECT_NE(u.problems.at(0).find("16 vertices lie exactly on another one: the quads are not welded"),
            std::string::npos)
      << u.problems.at(0);

  const QuadSurfaceReport t = check_quad_surface(test::torus_surface(6, 4), "torus");
  EXPECT_TRUE(t.closed && t.manifold && t.even);
  EXPECT_EQ(t.euler_characteristic, 0);
  EXPECT_EQ(t.genus, 1);
  EXPECT_FALSE(t.ball);

  const QuadSurfaceReport si = check_quad_surface(test::self_intersecting_surface(), "twisted");
  EXPECT_TRUE(si.ball && si.even && si.simple && si.three_connected);
  EXPECT_EQ(si.quads, 22);
  ASSERT_EQ(si.self_intersecting_chords.size(), 1u);
  const Chord& c = si.chords[si.self_intersecting_chords[0]];
  EXPECT_EQ(c.length(), 20);
  EXPECT_FALSE(c.repeated_quads.empty());
  for (int q : c.repeated_quads) EXPECT_EQ(std::count(c.quads.begin(), c.quads.end(), q), 2);
  EXPECT_FALSE(si.usable());
}

TEST(QuadSurfaceIo, ObjRoundTripAndDeterminism) {
  const std::string dir = test::temp_dir();
  const QuadSurface s = test::perturbed(test::block_surface(2, 1, 3), 0.05);
  write_quad_obj(dir + "/a.obj", s);
  write_quad_obj(dir + "/b.obj", s);
  EXPECT_EQ(test::read_file(dir + "/a.obj"), test::read_file(dir + "/b.obj"));
  const QuadSurface back = read_quad_surface(dir + "/a.obj");
  EXPECT_EQ(back.vertices, s.vertices);  // %.17g round-trips exactly
  EXPECT_EQ(back.quads, s.quads);
}

std::string error_of(const std::string& path) {
  try {
    read_quad_surface(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(QuadSurfaceIo, RejectsNonQuadsWithTheirPlace) {
  const std::string dir = test::temp_dir();
  test::write_file(dir + "/tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n# comment\nf 1 2 4 3\nf 1 2 3\n");
  const std::string e = error_of(dir + "/tri.obj");
  EXPECT_NE(e.find("tri.obj' line 7"), std::string::npos) << e;
  EXPECT_NE(e.find("3 corners"), std::string::npos) << e;
  test::write_file(dir + "/range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 9\n");
  EXPECT_NE(error_of(dir + "/range.obj").find("line 4: face index 9 is out of range"), std::string::npos);
  EXPECT_NE(error_of(dir + "/missing.obj").find("does not exist"), std::string::npos);
  EXPECT_NE(error_of(dir + "/x.stl").find("accepted quad surface formats"), std::string::npos);
  // 2^32 + 8 was cut to an int, 8: the face silently took vertex 8 instead of being refused.
  test::write_file(dir + "/wrap.obj",
                   "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n"
                   "f 1 2 3 4294967304\n");
  EXPECT_NE(
      error_of(dir + "/wrap.obj").find("line 9: face index 4294967304 is beyond the supported 2^31 vertices"),
      std::string::npos)
      << error_of(dir + "/wrap.obj");
  test::write_file(dir + "/slash.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1/1/1 2//2 -2 4\n");
  const QuadSurface slash = read_quad_surface(dir + "/slash.obj");
  EXPECT_EQ(slash.quads.at(0), (std::array<int, 4>{0, 1, 2, 3}));
  // A comment at the end of a line is a comment, as in a triangle OBJ: it was taken for two more corners
  // ("face with 6 corners").
  test::write_file(dir + "/comment.obj",
                   "v 0 0 0 # origin\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4 # the quad\n");
  const QuadSurface commented = read_quad_surface(dir + "/comment.obj");
  ASSERT_EQ(commented.quads.size(), 1u);
  EXPECT_EQ(commented.quads[0], (std::array<int, 4>{0, 1, 2, 3}));
}

TEST(QuadSurfaceIo, LegacyVtkPolydata) {
  const std::string dir = test::temp_dir();
  const std::string head =
      "# vtk DataFile Version 3.0\nquads\nASCII\nDATASET POLYDATA\nPOINTS 5 double\n0 0 0\n1 0 0\n1 1 0\n"
      "0 1 0\n2 0 0\n";
  test::write_file(dir + "/q.vtk", head + "POLYGONS 1 5\n4 0 1 2 3\n");
  const QuadSurface q = read_quad_surface(dir + "/q.vtk");
  ASSERT_EQ(q.quads.size(), 1u);
  EXPECT_EQ(q.quads[0], (std::array<int, 4>{0, 1, 2, 3}));
  EXPECT_EQ(q.vertices[4], (Vec3{2, 0, 0}));
  test::write_file(dir + "/t.vtk", head + "POLYGONS 2 9\n4 0 1 2 3\n3 1 4 2\n");
  const std::string e = error_of(dir + "/t.vtk");
  EXPECT_NE(e.find("face 1 (0-based) has 3 corners"), std::string::npos) << e;
}

// VTK 9.1's legacy reader crashed (segmentation fault) on a cell section that ends early or holds a
// non-integer, and read a cut-off CONNECTIVITY section (file version 5) with a made-up index. Each is now an
// InputError naming the section; whole files, ASCII and binary, still read.
TEST(QuadSurfaceIo, CutOffLegacyVtkIsRefusedNotACrash) {
  const std::string dir = test::temp_dir();
  const std::string head =
      "# vtk DataFile Version 3.0\nquads\nASCII\nDATASET POLYDATA\nPOINTS 4 float\n0 0 0 1 0 0 1 1 0 0 1 0\n";
  struct Case {
    std::string name, text, fragment;
  };
  const std::vector<Case> cases = {
      {"short.vtk", head + "POLYGONS 1 5\n4 0 1 2\n",
       "the file ends inside its POLYGONS section, which announces 5 values: it was cut off"},
      {"none.vtk", head + "POLYGONS 1 5\n", "the file ends inside its POLYGONS section"},
      {"word.vtk", head + "POLYGONS 1 5\n4 0 1 2 x\n",
       "line 8: 'x' in its POLYGONS section is not an integer"},
      // Beyond an int (VTK reads one into an int): a segmentation fault.
      {"huge.vtk", head + "POLYGONS 1 5\n4 0 1 2 2147483648\n",
       "line 8: '2147483648' in its POLYGONS section is beyond the 32-bit integers of its type int"},
      {"count.vtk", head + "POLYGONS 1 5\n4294967297 0 1 2 3\n",
       "'4294967297' in its POLYGONS section is beyond"},
      {"lines.vtk", head + "LINES 1 5\n4 0 1\n", "the file ends inside its LINES section"},
      {"points.vtk", head.substr(0, head.size() - 7) + "\nPOLYGONS 1 5\n4 0 1 2 3\n",
       "'POLYGONS' in its POINTS section is not a number"},
      {"v5.vtk",
       "# vtk DataFile Version 5.1\nquads\nASCII\nDATASET POLYDATA\nPOINTS 4 float\n0 0 0 1 0 0 1 1 0 0 1 0\n"
       "POLYGONS 2 4\nOFFSETS vtktypeint64\n0 4\nCONNECTIVITY vtktypeint64\n0 1 2\n",
       "the file ends inside its POLYGONS CONNECTIVITY section, which announces 4 values"},
  };
  for (const Case& c : cases) {
    test::write_file(dir + "/" + c.name, c.text);
    const std::string e = error_of(dir + "/" + c.name);
    EXPECT_NE(e.find("'" + dir + "/" + c.name + "'"), std::string::npos) << e;
    EXPECT_NE(e.find(c.fragment), std::string::npos) << c.name << ": " << e;
  }
  // Binary: big-endian values right after each keyword line.
  auto be32 = [](std::uint32_t u) {
    return std::string{char(u >> 24), char(u >> 16), char(u >> 8), char(u)};
  };
  auto f32 = [&](float f) {
    std::uint32_t u;
    std::memcpy(&u, &f, 4);
    return be32(u);
  };
  std::string binary = "# vtk DataFile Version 3.0\nquads\nBINARY\nDATASET POLYDATA\nPOINTS 4 float\n";
  for (const float c : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 1.f, 1.f, 0.f, 0.f, 1.f, 0.f}) binary += f32(c);
  binary += "\nPOLYGONS 1 5\n";
  for (const std::uint32_t i : {4u, 0u, 1u, 2u, 3u}) binary += be32(i);
  binary += "\n";
  test::write_file(dir + "/binary.vtk", binary);
  const QuadSurface q = read_quad_surface(dir + "/binary.vtk");
  ASSERT_EQ(q.quads.size(), 1u);
  EXPECT_EQ(q.quads[0], (std::array<int, 4>{0, 1, 2, 3}));
  EXPECT_EQ(q.vertices[2], (Vec3{1, 1, 0}));
  test::write_file(dir + "/binary_cut.vtk", binary.substr(0, binary.size() - 9));
  const std::string e = error_of(dir + "/binary_cut.vtk");
  EXPECT_NE(e.find("the file ends inside its POLYGONS section"), std::string::npos) << e;
}

// A NaN, infinite or too large coordinate in a legacy VTK file got VTK's "Unrecognized keyword: nan" (or
// ": 1" for 1e400) without a line; an OBJ coordinate below the double range (1e-400) was "NaN or infinite";
// and an OBJ behind a UTF-8 byte order mark was an "unknown OBJ line" showing the invisible mark.
TEST(QuadSurfaceIo, NonFiniteUnderflowAndByteOrderMark) {
  const std::string dir = test::temp_dir();
  const std::string head = "# vtk DataFile Version 3.0\ncube\nASCII\nDATASET POLYDATA\nPOINTS 8 double\n";
  const std::string tail =
      "\nPOLYGONS 6 30\n4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n";
  const std::string points = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n";
  for (const std::string bad : {"nan", "inf", "1e400"}) {
    test::write_file(dir + "/c.vtk", head + points + bad + " 1 1" + tail);
    try {
      read_quad_surface(dir + "/c.vtk");
      ADD_FAILURE() << bad;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("c.vtk' line 13: '" + bad +
                                           "' in its POINTS section is NaN, infinite or beyond the double "
                                           "range; every coordinate must be a finite number"),
                std::string::npos)
          << e.what();
    }
  }
  std::string obj = "\xEF\xBB\xBF";
  const QuadSurface cube = test::block_surface(1, 1, 1);
  for (const Vec3& p : cube.vertices)
    obj +=
        "v " + std::to_string(p[0]) + " " + std::to_string(p[1]) + " " + (p[2] == 0 ? "1e-400" : "1") + "\n";
  for (const auto& q : cube.quads)
    obj += "f " + std::to_string(q[0] + 1) + " " + std::to_string(q[1] + 1) + " " + std::to_string(q[2] + 1) +
           " " + std::to_string(q[3] + 1) + "\n";
  test::write_file(dir + "/bom.obj", obj);
  const QuadSurface read = read_quad_surface(dir + "/bom.obj");
  EXPECT_EQ(read.quads, cube.quads);
  EXPECT_EQ(read.vertices, cube.vertices);
}

// A quad surface in metres is meshed in its own coordinates, read as mm: `mesh --quad-surface` (whose .inp
// says mm) and `quad check` warned of nothing, as the readers of hex meshes do.
TEST(QuadCheckCli, SizeOfNoBoneIsWarnedAbout) {
  const std::string dir = test::temp_dir();
  QuadSurface small = test::block_surface(2, 1, 1);
  for (Vec3& v : small.vertices) v = {v[0] * 0.002, v[1] * 0.002, v[2] * 0.002};
  write_quad_obj(dir + "/m.obj", small);
  const std::string warning = "hexbite: warning: '" + dir +
                              "/m.obj': the quad surface is only 0.004 mm across (the largest side of its "
                              "bounding box) with its coordinates read as mm";
  const auto check = test::run_hexbite({"quad", "check", dir + "/m.obj"});
  EXPECT_EQ(check.exit_code, 0) << check.err;
  EXPECT_NE(check.err.find(warning), std::string::npos) << check.err;
  const auto mesh = test::run_hexbite(
      {"mesh", "--method", "sheets", "--quad-surface", dir + "/m.obj", "-o", dir + "/m.inp"});
  EXPECT_EQ(mesh.exit_code, 0) << mesh.err;
  EXPECT_NE(mesh.err.find(warning), std::string::npos) << mesh.err;
  EXPECT_NE(
      mesh.err.find("If the file's coordinates are in m (4 mm across), scale the quad surface from m to "
                    "millimetres where it was made: quad surface files are read in mm"),
      std::string::npos)
      << mesh.err;
}

// A cut-off XML file: VTK's reader reports it only by printing, and that explanation is the error's reason.
TEST(QuadSurfaceIo, CutOffVtpGivesVtksReason) {
  const std::string dir = test::temp_dir();
  const std::string vtp =
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      "<PolyData><Piece NumberOfPoints=\"4\" NumberOfPolys=\"1\">\n"
      "<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">0 0 0 1 0 0 1 1 0 0 1 0"
      "</DataArray></Points>\n"
      "<Polys><DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">0 1 2 3</DataArray>"
      "<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">4</DataArray></Polys>\n"
      "</Piece></PolyData>\n</VTKFile>\n";
  test::write_file(dir + "/q.vtp", vtp);
  ASSERT_EQ(read_quad_surface(dir + "/q.vtp").quads.size(), 1u);
  test::write_file(dir + "/cut.vtp", vtp.substr(0, vtp.size() / 2));
  const std::string e = error_of(dir + "/cut.vtp");
  EXPECT_NE(e.find("'" + dir + "/cut.vtp' could not be read as VTK XML polydata"), std::string::npos) << e;
  EXPECT_NE(e.find("(VTK: Error parsing XML"), std::string::npos) << e;

  // Two damaged files that VTK's reader does not survive: a point string array with one value for four
  // points (segmentation fault; it is skipped now) and a point count beyond memory (std::bad_alloc, with
  // neither file nor reason named).
  std::string labelled = vtp;
  labelled.insert(labelled.find("<Points>"),
                  "<PointData><DataArray type=\"String\" Name=\"label\" format=\"ascii\">97 0</DataArray>"
                  "</PointData>");
  test::write_file(dir + "/labelled.vtp", labelled);
  EXPECT_EQ(read_quad_surface(dir + "/labelled.vtp").quads.size(), 1u);
  std::string huge = vtp;
  huge.replace(huge.find("NumberOfPoints=\"4\""), 18, "NumberOfPoints=\"1000000000000000\"");
  test::write_file(dir + "/huge.vtp", huge);
  const std::string msg = test::message_of<InputError>([&] { read_quad_surface(dir + "/huge.vtp"); });
  EXPECT_NE(
      msg.find(
          "huge.vtp': its <Piece> announces NumberOfPoints=\"1000000000000000\", more than the 2^31 - 1"),
      std::string::npos)
      << msg;
}

// An OBJ 'l' line is refused, but the line cells of a .vtp or .vtk file were dropped silently: a file of
// quads and lines (e.g. feature edges exported with the surface) was read as its quads alone.
TEST(QuadSurfaceIo, LinesAndVerticesAreRefusedInEveryFormat) {
  const std::string dir = test::temp_dir();
  const std::string points =
      "<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">0 0 0 1 0 0 1 1 0 0 1 0"
      "</DataArray></Points>\n";
  const std::string polys =
      "<Polys><DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">0 1 2 3</DataArray>"
      "<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">4</DataArray></Polys>\n";
  const auto vtp = [&](const std::string& counts, const std::string& cells) {
    return "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\" "
           "byte_order=\"LittleEndian\">\n<PolyData><Piece NumberOfPoints=\"4\" " +
           counts + ">\n" + points + cells + "</Piece></PolyData>\n</VTKFile>\n";
  };
  test::write_file(dir + "/lines.vtp",
                   vtp("NumberOfPolys=\"1\" NumberOfLines=\"2\"",
                       "<Lines><DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">0 2 1 3"
                       "</DataArray><DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">2 4"
                       "</DataArray></Lines>\n" +
                           polys));
  const std::string lines = error_of(dir + "/lines.vtp");
  EXPECT_NE(lines.find("'" + dir + "/lines.vtp' holds 2 line cells besides its 1 polygon"), std::string::npos)
      << lines;
  EXPECT_NE(lines.find("remove them"), std::string::npos) << lines;
  test::write_file(dir + "/verts.vtp",
                   vtp("NumberOfPolys=\"1\" NumberOfVerts=\"1\"",
                       "<Verts><DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">0"
                       "</DataArray><DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">1"
                       "</DataArray></Verts>\n" +
                           polys));
  const std::string verts = error_of(dir + "/verts.vtp");
  EXPECT_NE(verts.find("'" + dir + "/verts.vtp' holds 1 vertex cell besides its 1 polygon"),
            std::string::npos)
      << verts;
  test::write_file(
      dir + "/lines.vtk",
      "# vtk DataFile Version 3.0\nquads\nASCII\nDATASET POLYDATA\nPOINTS 4 double\n0 0 0\n1 0 0\n"
      "1 1 0\n0 1 0\nPOLYGONS 1 5\n4 0 1 2 3\nLINES 1 3\n2 0 2\n");
  const std::string legacy = error_of(dir + "/lines.vtk");
  EXPECT_NE(legacy.find("'" + dir + "/lines.vtk' holds 1 line cell besides"), std::string::npos) << legacy;
  // The OBJ message says what to do too.
  test::write_file(dir + "/lines.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nl 1 3\n");
  const std::string obj = error_of(dir + "/lines.obj");
  EXPECT_NE(obj.find("lines.obj' line 6: 'l' elements (lines or points) are not part of a quad surface"),
            std::string::npos)
      << obj;
  EXPECT_NE(obj.find("remove them"), std::string::npos) << obj;
}

// A 2 x 1 x 1 box with the bottom front middle vertex (1, 0, 0) moved to (0.5, 0, 0.5), onto the line
// between its neighbours (0, 0, 0) and (1, 0, 1) in the front left quad: that corner is straight.
QuadSurface flat_corner_surface() {
  QuadSurface s = test::block_surface(2, 1, 1);
  for (Vec3& v : s.vertices)
    if (v == Vec3{1, 0, 0}) v = {0.5, 0, 0.5};
  return s;
}

// A 2 x 2 x 2 box whose top centre vertex is moved within the top face towards the corner (0, 0, 2): at
// (0.5, 0.5, 2) the quad over [0, 1]^2 has three collinear corners, nearer the corner it has a reflex one.
QuadSurface reflex_corner_surface(double at) {
  QuadSurface s = test::block_surface(2, 2, 2);
  for (Vec3& v : s.vertices)
    if (v == Vec3{1, 1, 2}) v = {at, at, 2};
  return s;
}

// A reflex corner passed `quad check` ("usable: yes"), and `mesh` then ran the whole elimination and
// embedding to fail with an inverted hex (exit 1). Bent quads whose corners are convex seen along their
// normal (a sphere's, a raised vertex's) pass.
TEST(QuadCheck, ReflexCornersAreNamedBentQuadsPass) {
  const std::string reflex = non_convex_corners_problem(reflex_corner_surface(0.45));
  EXPECT_NE(reflex.find("is not convex: its corner at vertex "), std::string::npos) << reflex;
  EXPECT_NE(reflex.find(" at (0.45, 0.45, 2) between corners "), std::string::npos) << reflex;
  EXPECT_NE(reflex.find(" is reflex (191 degrees inside): every hex on it has a negative corner Jacobian"),
            std::string::npos)
      << reflex;
  EXPECT_EQ(reflex.find("collinear"), std::string::npos) << reflex;
  EXPECT_NE(non_convex_corners_problem(reflex_corner_surface(0.5)).find("has three collinear corners"),
            std::string::npos);
  EXPECT_EQ(non_convex_corners_problem(reflex_corner_surface(0.55)), "");
  QuadSurface raised = test::block_surface(2, 2, 2);
  for (Vec3& v : raised.vertices)
    if (v == Vec3{1, 1, 2}) v = {1, 1, 3.5};
  EXPECT_EQ(non_convex_corners_problem(raised), "");
  EXPECT_EQ(non_convex_corners_problem(test::sphere_surface(4)), "");
  EXPECT_EQ(non_convex_corners_problem(test::perturbed(test::block_surface(3, 2, 2), 0.1)), "");
  // Either orientation: the normal turns with the corners.
  QuadSurface inward = reflex_corner_surface(0.45);
  for (auto& q : inward.quads) std::reverse(q.begin(), q.end());
  EXPECT_NE(non_convex_corners_problem(inward).find("(191 degrees inside)"), std::string::npos);
}

TEST(QuadCheckCli, ReflexCornerIsRefusedBeforeTheWork) {
  const std::string dir = test::temp_dir();
  write_quad_obj(dir + "/r045.obj", reflex_corner_surface(0.45));
  const auto check = test::run_hexbite({"quad", "check", dir + "/r045.obj"});
  EXPECT_EQ(check.exit_code, 2) << check.err;
  EXPECT_NE(check.err.find("is reflex (191 degrees inside)"), std::string::npos) << check.err;
  EXPECT_NE(check.out.find("usable for --method sheets: no"), std::string::npos) << check.out;
  for (const char* extra : {"--json", "--allow-invalid"}) {
    const auto mesh = test::run_hexbite(
        {"mesh", "--method", "sheets", "--quad-surface", dir + "/r045.obj", "-o", dir + "/m.vtu", extra});
    EXPECT_EQ(mesh.exit_code, 2) << mesh.err;
    EXPECT_NE(mesh.err.find("is reflex (191 degrees inside)"), std::string::npos) << mesh.err;
    EXPECT_EQ(mesh.out.find("Meshed"), std::string::npos) << mesh.out;  // before the elimination
    EXPECT_EQ(mesh.out.find("eliminations"), std::string::npos) << mesh.out;
    EXPECT_FALSE(std::filesystem::exists(dir + "/m.vtu"));
  }
}

// Two quads sharing two edges were counted ("2 pairs of quads share two or more edges, 0 duplicate quads")
// but not named, the cut vertices of the graph were named by no problem although "3-connected no", and
// a repeated quad was reported only as a non-manifold edge.
TEST(QuadCheck, NonSimpleGraphsNameTheirQuads) {
  // A cube whose top and bottom are each split by a vertex of degree 2 on their diagonal.
  QuadSurface split;
  split.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},       {0, 0, 1},
                    {1, 0, 1}, {1, 1, 1}, {0, 1, 1}, {0.5, 0.5, 1.3}, {0.5, 0.5, -0.3}};
  split.quads = {{0, 3, 2, 9}, {0, 9, 2, 1}, {4, 5, 6, 8}, {4, 8, 6, 7},
                 {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  const QuadSurfaceReport r = check_quad_surface(split, "split");
  EXPECT_EQ(r.quad_pairs_sharing_edges, 2);
  const auto has = [&](const QuadSurfaceReport& report, const std::string& text) {
    for (const std::string& p : report.problems)
      if (p.find(text) != std::string::npos) return true;
    return false;
  };
  EXPECT_TRUE(
      has(r,
          "graph not simple: 2 pairs of quads share two or more edges (the first: quad 0 (vertices "
          "0, 3, 2, 9; centre (0.375, 0.625, -0.075)) and quad 1 (vertices 0, 9, 2, 1; centre (0.625, "
          "0.375, -0.075)) share edges 0-9, 2-9)"))
      << r.problems.size();
  // The top's vertex of degree 2 (vertex 8) is found first: its two neighbours separate it.
  EXPECT_TRUE(has(r,
                  "graph not 3-connected: removing vertex 4 at (0, 0, 1) and vertex 6 at (1, 1, 1) "
                  "disconnects it"));
  EXPECT_FALSE(has(r, "duplicate"));

  QuadSurface twice = test::block_surface(1, 1, 1);
  twice.quads.push_back(twice.quads[3]);
  twice.quads.push_back(twice.quads[3]);
  const QuadSurfaceReport d = check_quad_surface(twice, "twice");
  EXPECT_EQ(d.duplicate_quads, 2);
  EXPECT_TRUE(has(d,
                  "graph not simple: 2 duplicate quads (the same vertices as an earlier quad; the first: "
                  "quad 6 (vertices "));
  EXPECT_TRUE(has(d, ", the same as quad 3); remove the repeated quads"));
  EXPECT_TRUE(has(d, "not manifold: "));
}

TEST(QuadCheckCli, ExitCodesAndMessages) {
  const std::string dir = test::temp_dir();
  write_quad_obj(dir + "/block.obj", test::block_surface(2, 3, 4));
  const auto ok = test::run_hexbite({"quad", "check", dir + "/block.obj", "--json"});
  EXPECT_EQ(ok.exit_code, 0) << ok.err;
  const auto j = nlohmann::json::parse(ok.out);
  EXPECT_EQ(j["chords"].size(), 9u);
  EXPECT_EQ(j["quads"], 52);
  EXPECT_EQ(j["three_connected"], true);
  EXPECT_EQ(j["genus"], 0);

  struct Case {
    std::string name;
    QuadSurface surface;
    std::string message;
  };
  QuadSurface open = test::block_surface(2, 1, 1);
  open.quads.resize(open.quads.size() - 2);
  const std::vector<Case> cases = {
      {"odd", odd_surface(), "odd number of quads (7)"},
      {"open", open, "not closed: "},
      {"torus", test::torus_surface(6, 4), "not a ball: genus 1"},
      {"twisted", test::self_intersecting_surface(), "(length 20) self-intersects"},
      // Combinatorially fine, but no valid mesh keeps this boundary: was "usable: yes", and the mesh command
      // then refused it.
      {"flat_corner", flat_corner_surface(), "has three collinear corners"}};
  for (const Case& c : cases) {
    write_quad_obj(dir + "/" + c.name + ".obj", c.surface);
    const auto r = test::run_hexbite({"quad", "check", dir + "/" + c.name + ".obj"});
    EXPECT_EQ(r.exit_code, 2) << c.name;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.name << ": " << r.err;
    EXPECT_NE(r.out.find("usable for --method sheets: no"), std::string::npos) << c.name;  // report printed
  }
}

// A 3 x 1 x 1 box whose top vertices over x = 1 and 2 on the front are pulled below the bottom: the quads
// fold over themselves, which every combinatorial test passes.
QuadSurface folded_box() {
  QuadSurface fold = test::block_surface(3, 1, 1);
  for (Vec3& v : fold.vertices)
    if (v[1] == 0 && v[2] == 1 && (v[0] == 1 || v[0] == 2)) v[2] = -0.5;
  return fold;
}

TEST(QuadCrossings, FoldedSurfacesAndPlainOnes) {
  EXPECT_TRUE(crossing_quads(test::block_surface(3, 2, 2)).empty());
  EXPECT_EQ(crossing_quads_problem(test::block_surface(3, 2, 2), {}), "");
  const QuadSurface fold = folded_box();
  const std::vector<std::array<int, 2>> pairs = crossing_quads(fold);
  ASSERT_FALSE(pairs.empty());
  EXPECT_TRUE(std::is_sorted(pairs.begin(), pairs.end()));
  for (const auto& [a, b] : pairs) {
    EXPECT_LE(a, b);
    EXPECT_LT(b, static_cast<int>(fold.quads.size()));
  }
  const std::string text = crossing_quads_problem(fold, pairs);
  // The first pair is a quad whose two halves cross (the corner pulled below the bottom bends it over).
  ASSERT_EQ(pairs[0][0], pairs[0][1]);
  EXPECT_EQ(text.find("the surface crosses itself: quad " + std::to_string(pairs[0][0]) +
                      " (centre (0.5, 0, 0.125)) is folded: its two halves cross"),
            0u)
      << text;
  EXPECT_NE(std::find_if(pairs.begin(), pairs.end(), [](const auto& p) { return p[0] != p[1]; }),
            pairs.end());
  EXPECT_NE(text.find(std::to_string(pairs.size()) + " crossing pairs in all"), std::string::npos) << text;
  // An open surface is tested too (quad check reports it as open first and does not ask).
  QuadSurface open = fold;
  open.quads.pop_back();
  EXPECT_FALSE(crossing_quads(open).empty());
}

// quad check passed a folded surface as "usable for --method sheets: yes", and `mesh` then left hexes
// inverted after the whole run. Now a problem, with `crossing_quads` in the JSON (null when not tested).
TEST(QuadCheckCli, FoldedSurfaceCrossesItself) {
  const std::string dir = test::temp_dir();
  write_quad_obj(dir + "/fold.obj", folded_box());
  write_quad_obj(dir + "/box.obj", test::block_surface(3, 1, 1));
  const auto fold = test::run_hexbite({"quad", "check", dir + "/fold.obj", "--json"});
  EXPECT_EQ(fold.exit_code, 2) << fold.err;
  const auto j = nlohmann::json::parse(fold.out);
  EXPECT_FALSE(j["usable"].get<bool>());
  EXPECT_GT(j["crossing_quads"].size(), 0u);
  EXPECT_NE(fold.err.find("fold.obj': the surface crosses itself: quad 1 (centre (0.5, 0, 0.125)) is folded"),
            std::string::npos)
      << fold.err;
  EXPECT_NE(fold.err.find("untangle the surface there"), std::string::npos) << fold.err;
  const auto box = test::run_hexbite({"quad", "check", dir + "/box.obj", "--json"});
  EXPECT_EQ(box.exit_code, 0) << box.err;
  EXPECT_TRUE(nlohmann::json::parse(box.out)["crossing_quads"].is_array());
  EXPECT_EQ(nlohmann::json::parse(box.out)["crossing_quads"].size(), 0u);
  const auto text = test::run_hexbite({"quad", "check", dir + "/box.obj"});
  EXPECT_NE(text.out.find("crosses itself        no"), std::string::npos) << text.out;
  QuadSurface open = test::block_surface(3, 1, 1);
  open.quads.pop_back();
  write_quad_obj(dir + "/open.obj", open);
  EXPECT_TRUE(nlohmann::json::parse(
                  test::run_hexbite({"quad", "check", dir + "/open.obj", "--json"}).out)["crossing_quads"]
                  .is_null());
}

// The sheet mesher refuses a folded quad surface before the work (it left hexes inverted, exit 1, after
// it); --allow-invalid meshes it anyway, saying so.
TEST(MeshSheetsCli, FoldedQuadSurfaceIsRefusedFirst) {
  const std::string dir = test::temp_dir();
  write_quad_obj(dir + "/fold.obj", folded_box());
  const auto r = test::run_hexbite(
      {"mesh", "--quad-surface", dir + "/fold.obj", "--method", "sheets", "-o", dir + "/fold.vtu"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("fold.obj': the surface crosses itself: quad 1 "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--allow-invalid meshes it anyway"), std::string::npos) << r.err;
  EXPECT_EQ(r.out.find("Meshed"), std::string::npos) << r.out;
  EXPECT_FALSE(std::filesystem::exists(dir + "/fold.vtu"));
  const auto anyway = test::run_hexbite({"mesh", "--quad-surface", dir + "/fold.obj", "--method", "sheets",
                                         "-o", dir + "/fold.vtu", "--allow-invalid"});
  EXPECT_EQ(anyway.exit_code, 0) << anyway.err;
  EXPECT_NE(anyway.err.find("hexbite: warning: '" + dir + "/fold.obj': the surface crosses itself"),
            std::string::npos)
      << anyway.err;
  EXPECT_TRUE(std::filesystem::exists(dir + "/fold.vtu"));
}

// A 2 x 2 x 1 box whose top centre vertex is pulled down next to the bottom corner (2, 2, 0): the top quads
// are bent but convex seen along their normals (a reflex corner is refused before the work), the surface
// does not cross itself, and one hex stays inverted. The message named no hex, and the quality line printed
// "nan" for the condition numbers it could not take.
TEST(MeshSheetsCli, InvertedHexesAreNamedWithTheirPlaces) {
  QuadSurface bent = test::block_surface(2, 2, 1);
  for (Vec3& v : bent.vertices)
    if (v[0] == 1 && v[1] == 1 && v[2] == 1) v = {1.9, 1.9, 0.05};
  ASSERT_TRUE(crossing_quads(bent).empty());
  ASSERT_EQ(non_convex_corners_problem(bent), "");
  const std::string dir = test::temp_dir();
  write_quad_obj(dir + "/dart.obj", bent);
  const auto r = test::run_hexbite(
      {"mesh", "--quad-surface", dir + "/dart.obj", "--method", "sheets", "-o", dir + "/dart.vtu"});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  // One hex, so "1 hex stays" ("1 hexes stay" before).
  EXPECT_NE(r.err.find("failed: 1 hex stays inverted after optimization: hex 0 at ("), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find(") mm"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("the quads there may be too bent for the hexes under them"), std::string::npos)
      << r.err;
  EXPECT_EQ(r.out.find("nan"), std::string::npos) << r.out;
  EXPECT_FALSE(std::filesystem::exists(dir + "/dart.vtu"));
}

// `quad from-mesh` writes the boundary quads of a hex mesh (.vtu or .msh): for a 2 x 3 x 4 block its 52
// outward faces on the 54 boundary nodes, a surface that `quad check` passes and the sheet mesher takes.
TEST(QuadFromMeshCli, BoundaryOfABlock) {
  const std::string dir = test::temp_dir();
  const HexMesh block = make_block_mesh(2, 3, 4);
  write_msh(dir + "/block.msh", block);
  const auto r = test::run_hexbite({"quad", "from-mesh", dir + "/block.msh", "-o", dir + "/q.obj", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["hexes"], 24);
  EXPECT_EQ(j["quads"], 52);
  EXPECT_EQ(j["vertices"], 54);
  const QuadSurface q = read_quad_surface(dir + "/q.obj");
  const HexBoundary b = extract_boundary(block);
  EXPECT_EQ(q.quads, b.surface.quads);
  EXPECT_EQ(q.vertices, b.surface.vertices);
  const QuadSurfaceReport report = check_quad_surface(q, "q.obj");
  EXPECT_TRUE(report.usable());
  EXPECT_TRUE(report.ball);
  // The surface encloses the block: positive volume means outward quads.
  const TriSurface tri = fan_triangles(q);
  double six_volume = 0;
  for (const auto& t : tri.triangles) {
    const Vec3 &a = tri.vertices[t[0]], &b2 = tri.vertices[t[1]], &c = tri.vertices[t[2]];
    six_volume += a[0] * (b2[1] * c[2] - b2[2] * c[1]) - a[1] * (b2[0] * c[2] - b2[2] * c[0]) +
                  a[2] * (b2[0] * c[1] - b2[1] * c[0]);
  }
  EXPECT_NEAR(six_volume / 6.0, 24.0, 1e-9);
  const auto bad = test::run_hexbite({"quad", "from-mesh", dir + "/block.msh", "-o", dir + "/q.vtu"});
  EXPECT_EQ(bad.exit_code, 2);
}

// A mesh with inverted hexes has inward faces (a mirrored block: all of them), so `quad from-mesh` would
// write an inward surface while saying "outward": refused as bad input (exit 2), the hexes named with their
// centroids, nothing written; as hexbite refine refuses it.
TEST(QuadFromMeshCli, InvertedHexesAreRefused) {
  const std::string dir = test::temp_dir();
  HexMesh mirrored = make_block_mesh(2, 1, 1);
  for (Vec3& v : mirrored.vertices) v[2] = -v[2];
  write_msh(dir + "/mirrored.msh", mirrored);
  const auto r = test::run_hexbite({"quad", "from-mesh", dir + "/mirrored.msh", "-o", dir + "/q.obj"});
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_NE(r.err.find("has 2 inverted hexes"), std::string::npos) << r.err;
  // With the hex's Gmsh element tag, as the input is a .msh.
  EXPECT_NE(r.err.find("hex 0 (Gmsh element 1) at (0.50, 0.50, -0.50) mm"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("nothing written"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir + "/q.obj"));
}

}  // namespace
}  // namespace hexbite
