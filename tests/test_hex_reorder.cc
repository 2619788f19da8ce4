// Breadth-first and reverse Cuthill-McKee reordering (mesher/hex_reorder.h) and the `hexbite reorder`
// command.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <random>
#include <set>

#include <vtkType.h>

#include "mesher/grid_mesher.h"
#include "mesher/hex_block.h"
#include "mesher/hex_boundary.h"
#include "mesher/hex_mesh_io.h"
#include "mesher/hex_reorder.h"
#include "tests/test_util.h"

namespace hexbite {
namespace {

using test::run_hexbite;
using test::temp_dir;

// The block with its nodes and hexes randomly renumbered (a fixed seed): the worst case for bandwidth.
HexMesh shuffled(const HexMesh& mesh, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<int> node(mesh.vertices.size()), hex(mesh.hexes.size());
  for (std::size_t i = 0; i < node.size(); ++i) node[i] = static_cast<int>(i);
  for (std::size_t i = 0; i < hex.size(); ++i) hex[i] = static_cast<int>(i);
  std::shuffle(node.begin(), node.end(), rng);
  std::shuffle(hex.begin(), hex.end(), rng);
  HexMesh out;
  out.vertices.resize(mesh.vertices.size());
  for (std::size_t v = 0; v < node.size(); ++v) out.vertices[node[v]] = mesh.vertices[v];
  for (int h : hex) {
    std::array<int, 8> e;
    for (int k = 0; k < 8; ++k) e[k] = node[mesh.hexes[h][k]];
    out.hexes.push_back(e);
  }
  return out;
}

// Bandwidth and profile from the explicit set of adjacent node pairs, independent of the library's per-hex
// shortcut.
AdjacencyProfile brute_force_profile(const HexMesh& mesh) {
  std::set<std::pair<int, int>> pairs;
  for (const auto& hex : mesh.hexes)
    for (int a : hex)
      for (int b : hex) pairs.insert({a, b});
  AdjacencyProfile p;
  std::vector<int> lowest(mesh.vertices.size());
  for (std::size_t v = 0; v < lowest.size(); ++v) lowest[v] = static_cast<int>(v);
  for (const auto& [a, b] : pairs) {
    p.bandwidth = std::max<long long>(p.bandwidth, std::abs(a - b));
    lowest[a] = std::min(lowest[a], b);
  }
  for (std::size_t v = 0; v < lowest.size(); ++v) p.profile += static_cast<long long>(v) - lowest[v];
  return p;
}

// Checks that `r` renumbers `mesh`: both orders are permutations, and each new hex is its old hex with the
// same corner positions in the same order.
void expect_permutation(const HexMesh& mesh, const ReorderResult& r) {
  ASSERT_EQ(r.hex_order.size(), mesh.hexes.size());
  ASSERT_EQ(r.node_order.size(), mesh.vertices.size());
  std::vector<int> h = r.hex_order, n = r.node_order;
  std::sort(h.begin(), h.end());
  std::sort(n.begin(), n.end());
  for (std::size_t i = 0; i < h.size(); ++i) ASSERT_EQ(h[i], static_cast<int>(i));
  for (std::size_t i = 0; i < n.size(); ++i) ASSERT_EQ(n[i], static_cast<int>(i));
  for (std::size_t i = 0; i < r.node_order.size(); ++i)
    ASSERT_EQ(r.mesh.vertices[i], mesh.vertices[r.node_order[i]]);
  for (std::size_t i = 0; i < r.hex_order.size(); ++i)
    for (int k = 0; k < 8; ++k)
      ASSERT_EQ(r.mesh.vertices[r.mesh.hexes[i][k]], mesh.vertices[mesh.hexes[r.hex_order[i]][k]]);
  EXPECT_DOUBLE_EQ(hex_mesh_volume(r.mesh), hex_mesh_volume(mesh));
}

TEST(HexReorder, BothMethodsArePermutations) {
  const HexMesh mesh = shuffled(make_block_mesh(6, 5, 4), 11);
  expect_permutation(mesh, reorder_breadth_first(mesh, 17));
  expect_permutation(mesh, reorder_reverse_cuthill_mckee(mesh));
}

TEST(HexReorder, UnusedNodesGoLast) {
  HexMesh mesh = make_block_mesh(2, 2, 2);
  mesh.vertices.insert(mesh.vertices.begin() + 3, Vec3{9, 9, 9});
  for (auto& hex : mesh.hexes)
    for (int& v : hex)
      if (v >= 3) ++v;
  for (const ReorderResult& r : {reorder_breadth_first(mesh, 0), reorder_reverse_cuthill_mckee(mesh)}) {
    expect_permutation(mesh, r);
    EXPECT_EQ(r.node_order.back(), 3);
  }
}

TEST(HexReorder, ReverseCuthillMcKeeShrinksTheBandwidthOfAShuffledBlock) {
  // An elongated block, like a mandible: Cuthill-McKee's level sets are then cross-sections (6 x 7 x 7 nodes
  // at most two levels apart), while random numbering spreads neighbours over the whole range.
  const HexMesh mesh = shuffled(make_block_mesh(30, 6, 6), 5);
  const ReorderResult r = reorder_reverse_cuthill_mckee(mesh);
  expect_permutation(mesh, r);
  EXPECT_GT(r.before.bandwidth, 1400);
  EXPECT_LT(r.after.bandwidth, 150);
  EXPECT_GE(r.before.bandwidth, 10 * r.after.bandwidth);
  EXPECT_GE(r.before.profile, 10 * r.after.profile);
  // Breadth-first over hexes from one end also orders the block by cross-sections.
  const ReorderResult b = reorder_breadth_first(mesh, smallest_x_boundary_hex(mesh));
  EXPECT_GE(b.before.bandwidth, 5 * b.after.bandwidth);
}

TEST(HexReorder, ReportedBandwidthEqualsBruteForce) {
  const HexMesh mesh = shuffled(make_block_mesh(5, 4, 3), 2);
  const ReorderResult r = reorder_reverse_cuthill_mckee(mesh);
  const AdjacencyProfile before = brute_force_profile(mesh), after = brute_force_profile(r.mesh);
  EXPECT_EQ(r.before.bandwidth, before.bandwidth);
  EXPECT_EQ(r.before.profile, before.profile);
  EXPECT_EQ(r.after.bandwidth, after.bandwidth);
  EXPECT_EQ(r.after.profile, after.profile);
  const ReorderResult b = reorder_breadth_first(mesh, 0);
  EXPECT_EQ(b.after.bandwidth, brute_force_profile(b.mesh).bandwidth);
  EXPECT_EQ(b.after.profile, brute_force_profile(b.mesh).profile);
}

TEST(HexReorder, BreadthFirstStartsAtTheBoundaryHexNearestThePoint) {
  const HexMesh mesh = shuffled(make_block_mesh(6, 6, 6), 9);
  // Boundary hexes by brute force: a hex with a face whose vertex set no other hex shares.
  std::vector<char> boundary(mesh.hexes.size(), 0);
  for (const auto& qf : extract_boundary(mesh).quad_face) boundary[qf[0]] = 1;
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> coord(-2.0, 8.0);
  for (int trial = 0; trial < 20; ++trial) {
    const Vec3 p{coord(rng), coord(rng), coord(rng)};
    int expected = -1;
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t h = 0; h < mesh.hexes.size(); ++h) {
      if (!boundary[h]) continue;
      Vec3 c{0, 0, 0};
      for (int v : mesh.hexes[h])
        for (int a = 0; a < 3; ++a) c[a] += mesh.vertices[v][a] / 8;
      const double d = std::hypot(c[0] - p[0], c[1] - p[1], c[2] - p[2]);
      if (d < best - 1e-12) {
        best = d;
        expected = static_cast<int>(h);
      }
    }
    const int start = nearest_boundary_hex(mesh, p);
    ASSERT_EQ(start, expected);
    const ReorderResult r = reorder_breadth_first(mesh, start);
    EXPECT_EQ(r.start_hex, start);
    EXPECT_EQ(r.hex_order[0], start);
    // The start hex's nodes come first.
    for (int k = 0; k < 8; ++k) EXPECT_LT(r.mesh.hexes[0][k], 8);
  }
}

TEST(HexReorder, Deterministic) {
  const HexMesh mesh = shuffled(make_block_mesh(5, 5, 5), 4);
  const ReorderResult a = reorder_reverse_cuthill_mckee(mesh), b = reorder_reverse_cuthill_mckee(mesh);
  EXPECT_EQ(a.node_order, b.node_order);
  EXPECT_EQ(a.hex_order, b.hex_order);
}

TEST(HexReorderCommand, ReordersAndReports) {
  const std::string dir = temp_dir();
  const HexMesh mesh = shuffled(make_block_mesh(6, 6, 6), 3);
  write_vtu(dir + "/in.vtu", mesh);
  auto r = run_hexbite({"reorder", dir + "/in.vtu", "-o", dir + "/rcm.vtu", "--method", "rcm", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(r.out);
  const ReorderResult expected = reorder_reverse_cuthill_mckee(mesh);
  EXPECT_EQ(j["before"]["bandwidth"], expected.before.bandwidth);
  EXPECT_EQ(j["after"]["bandwidth"], expected.after.bandwidth);
  EXPECT_EQ(j["after"]["profile"], expected.after.profile);
  const HexMesh out = read_vtu(dir + "/rcm.vtu");
  EXPECT_EQ(out.hexes, expected.mesh.hexes);
  EXPECT_EQ(out.vertices, expected.mesh.vertices);

  r = run_hexbite({"reorder", dir + "/in.vtu", "-o", dir + "/bfs.vtu", "--method", "bfs", "--from", "6,6,6"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("bandwidth"), std::string::npos) << r.out;
  const HexMesh bfs = read_vtu(dir + "/bfs.vtu");
  EXPECT_EQ(bfs.hexes, reorder_breadth_first(mesh, nearest_boundary_hex(mesh, {6, 6, 6})).mesh.hexes);

  test::write_file(dir + "/landmarks.yaml", "landmarks:\n  left_condyle_tmj_point: [0, 0, 0]\n");
  r = run_hexbite(
      {"reorder", dir + "/in.vtu", "-o", dir + "/lm.vtu", "--landmarks", dir + "/landmarks.yaml", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["start"]["hex"], nearest_boundary_hex(mesh, {0, 0, 0}));
}

// `mesh` with one cell and one point array written to DIR/in.vtu, reordered by `hexbite reorder --method rcm`
// and read back: the two arrays as they came out (an empty array when missing).
struct ReorderedArrays {
  MeshArray cell, point;
};
ReorderedArrays reorder_with_arrays(const std::string& dir, const HexMesh& mesh, const MeshArray& cell,
                                    const MeshArray& point) {
  write_vtu(dir + "/in.vtu", mesh, {cell}, {point});
  const auto r = run_hexbite({"reorder", dir + "/in.vtu", "-o", dir + "/rcm.vtu", "--method", "rcm", "-q"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  std::vector<MeshArray> cells, points;
  read_vtu(dir + "/rcm.vtu", &cells, &points);
  const auto named = [](const std::vector<MeshArray>& arrays, const std::string& name) {
    const auto it =
        std::find_if(arrays.begin(), arrays.end(), [&](const MeshArray& a) { return a.name == name; });
    EXPECT_NE(it, arrays.end()) << name;
    return it == arrays.end() ? MeshArray{} : *it;
  };
  return {named(cells, cell.name), named(points, point.name)};
}

// The input's arrays come out in the new order and with their own types: an Int32 material id stays Int32 (it
// was written back as Float64, which readers that expect integer ids refuse).
TEST(HexReorderCommand, ArraysKeepTheirValuesAndTypes) {
  const std::string dir = temp_dir();
  const HexMesh mesh = shuffled(make_block_mesh(3, 3, 3), 5);
  MeshArray material{"material", 1, {}, VTK_INT};
  for (std::size_t h = 0; h < mesh.hexes.size(); ++h) material.values.push_back(double(h));
  MeshArray node_id{"node_id", 1, {}, VTK_LONG_LONG};
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) node_id.values.push_back(double(v) + 1e12);
  const auto [cell, point] = reorder_with_arrays(dir, mesh, material, node_id);
  const ReorderResult expected = reorder_reverse_cuthill_mckee(mesh);
  EXPECT_EQ(cell.vtk_type, VTK_INT);
  EXPECT_EQ(point.vtk_type, VTK_LONG_LONG);
  ASSERT_EQ(cell.values.size(), mesh.hexes.size());
  ASSERT_EQ(point.values.size(), mesh.vertices.size());
  for (std::size_t i = 0; i < expected.hex_order.size(); ++i)
    EXPECT_EQ(cell.values[i], double(expected.hex_order[i]));
  for (std::size_t i = 0; i < expected.node_order.size(); ++i)
    EXPECT_EQ(point.values[i], double(expected.node_order[i]) + 1e12);
  const std::string text = test::read_file(dir + "/rcm.vtu");
  EXPECT_NE(text.find("type=\"Int32\" Name=\"material\""), std::string::npos);
  EXPECT_NE(text.find("type=\"Int64\" Name=\"node_id\""), std::string::npos);
}

// 64-bit integer ids above 2^53 come through exactly: they went through doubles, so 2^60 + 1 came out as
// 2^60 and 2^64 - 1 as 0, with exit 0.
TEST(HexReorderCommand, SixtyFourBitIntegersKeepEveryDigit) {
  const std::string dir = temp_dir();
  const HexMesh mesh = shuffled(make_block_mesh(2, 2, 2), 3);
  MeshArray big{"big", 1, {}, VTK_LONG_LONG}, ubig{"ubig", 1, {}, VTK_UNSIGNED_LONG_LONG};
  for (std::size_t h = 0; h < mesh.hexes.size(); ++h) {
    big.bits64.push_back((std::uint64_t{1} << 60) + h);
    big.values.push_back(std::ldexp(1.0, 60));
  }
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    ubig.bits64.push_back(~std::uint64_t{0} - v);
    ubig.values.push_back(std::ldexp(1.0, 64));
  }
  const auto [cell, point] = reorder_with_arrays(dir, mesh, big, ubig);
  const ReorderResult expected = reorder_reverse_cuthill_mckee(mesh);
  ASSERT_EQ(cell.bits64.size(), mesh.hexes.size());
  ASSERT_EQ(point.bits64.size(), mesh.vertices.size());
  for (std::size_t i = 0; i < expected.hex_order.size(); ++i)
    EXPECT_EQ(cell.bits64[i], (std::uint64_t{1} << 60) + static_cast<std::uint64_t>(expected.hex_order[i]));
  for (std::size_t i = 0; i < expected.node_order.size(); ++i)
    EXPECT_EQ(point.bits64[i], ~std::uint64_t{0} - static_cast<std::uint64_t>(expected.node_order[i]));
  EXPECT_EQ(point.vtk_type, VTK_UNSIGNED_LONG_LONG);
}

// What reorder cannot carry (text arrays, field data) is named in a warning: it was dropped without a word.
TEST(HexReorderCommand, WhatIsNotCarriedOverIsNamed) {
  const std::string dir = temp_dir();
  test::write_file(
      dir + "/in.vtu",
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\">\n<UnstructuredGrid>"
      "<FieldData><DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" "
      "format=\"ascii\">2.5</DataArray></FieldData>\n"
      "<Piece NumberOfPoints=\"8\" NumberOfCells=\"1\">\n"
      "<CellData><DataArray type=\"String\" Name=\"label\" format=\"ascii\">98 111 110 101 0"
      "</DataArray><DataArray type=\"Int32\" Name=\"material\" format=\"ascii\">3</DataArray>"
      "</CellData>\n<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">"
      "0 0 0 1 0 0 1 1 0 0 1 0 0 0 1 1 0 1 1 1 1 0 1 1</DataArray></Points>\n<Cells>"
      "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">0 1 2 3 4 5 6 7</DataArray>"
      "<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">8</DataArray>"
      "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">12</DataArray>"
      "</Cells></Piece></UnstructuredGrid></VTKFile>\n");
  const auto r = run_hexbite({"reorder", dir + "/in.vtu", "-o", dir + "/out.vtu", "-q"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("hexbite: warning: not carried over to " + dir +
                       "/out.vtu: cell array 'label' (text), field data 'TimeValue'"),
            std::string::npos)
      << r.err;
  std::vector<MeshArray> cells;
  read_vtu(dir + "/out.vtu", &cells);
  ASSERT_EQ(cells.size(), 5u);  // the four quality arrays and the material
  EXPECT_EQ(cells.back().name, "material");
  EXPECT_EQ(cells.back().vtk_type, VTK_INT);
  // A .msh or .inp carries no arrays: the numeric ones were dropped without a word, and the warning said
  // "(reorder carries the numeric cell and point arrays only)".
  for (const char* ext : {".msh", ".inp"}) {
    const auto lost = run_hexbite({"reorder", dir + "/in.vtu", "-o", dir + "/out" + ext, "-q"});
    ASSERT_EQ(lost.exit_code, 0) << lost.err;
    EXPECT_NE(lost.err.find("hexbite: warning: not carried over to " + dir + "/out" + ext +
                            ": cell array 'material', cell array 'label' (text), field data 'TimeValue' "
                            "(only a .vtu output carries arrays)."),
              std::string::npos)
        << lost.err;
  }
}

// Arrays named like hexbite's quality arrays: a point array 'oddy' vanished (it cannot clash with the cell
// arrays), and a user's Int32 cell array 'condition' was replaced by hexbite's without a word. An input that
// hexbite wrote reorders without a warning.
TEST(HexReorderCommand, ArraysNamedLikeQualityArrays) {
  const std::string dir = temp_dir();
  test::write_file(
      dir + "/in.vtu",
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\">\n<UnstructuredGrid>"
      "<Piece NumberOfPoints=\"8\" NumberOfCells=\"1\">\n"
      "<PointData><DataArray type=\"Float64\" Name=\"oddy\" format=\"ascii\">0 1 2 3 4 5 6 7</DataArray>"
      "</PointData>\n<CellData><DataArray type=\"Int32\" Name=\"condition\" format=\"ascii\">7"
      "</DataArray></CellData>\n<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" "
      "format=\"ascii\">0 0 0 1 0 0 1 1 0 0 1 0 0 0 1 1 0 1 1 1 1 0 1 1</DataArray></Points>\n<Cells>"
      "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">0 1 2 3 4 5 6 7</DataArray>"
      "<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">8</DataArray>"
      "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">12</DataArray>"
      "</Cells></Piece></UnstructuredGrid></VTKFile>\n");
  auto r = run_hexbite({"reorder", dir + "/in.vtu", "-o", dir + "/out.vtu", "-q"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("hexbite: warning: cell array 'condition' of " + dir +
                       "/in.vtu is not hexbite's quality array of that name (its values differ): " + dir +
                       "/out.vtu holds hexbite's 'condition' (Float64) in its place; rename the array in " +
                       dir + "/in.vtu to keep it."),
            std::string::npos)
      << r.err;
  std::vector<MeshArray> cells, points;
  read_vtu(dir + "/out.vtu", &cells, &points);
  ASSERT_EQ(points.size(), 1u);
  EXPECT_EQ(points[0].name, "oddy");
  EXPECT_EQ(points[0].values.size(), 8u);
  ASSERT_EQ(cells.size(), 4u);  // hexbite's quality arrays
  EXPECT_EQ(cells[1].name, "condition");
  EXPECT_EQ(cells[1].vtk_type, VTK_DOUBLE);
  EXPECT_EQ(cells[1].values, std::vector<double>{3.0});

  // hexbite's own output, with its quality arrays and the point array 'oddy': no warning.
  r = run_hexbite({"reorder", dir + "/out.vtu", "-o", dir + "/again.vtu", "--method", "rcm", "-q"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  HexMesh mesh = shuffled(make_block_mesh(3, 2, 2), 7);
  mesh.vertices[0][0] -= 0.4;  // distorted hexes: quality values other than a cube's
  write_vtu(dir + "/block.vtu", mesh);
  r = run_hexbite({"reorder", dir + "/block.vtu", "-o", dir + "/block_rcm.vtu", "--method", "rcm", "-q"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");
}

TEST(HexReorderCommand, BadInput) {
  const std::string dir = temp_dir();
  write_vtu(dir + "/in.vtu", make_block_mesh(2, 2, 2));
  EXPECT_EQ(run_hexbite({"reorder", dir + "/missing.vtu", "-o", dir + "/o.vtu"}).exit_code, 2);
  auto r = run_hexbite({"reorder", dir + "/in.vtu", "-o", dir + "/o.vtu", "--from", "1,2"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("x,y,z"), std::string::npos) << r.err;
  EXPECT_EQ(
      run_hexbite({"reorder", dir + "/in.vtu", "-o", dir + "/o.vtu", "--method", "rcm", "--from", "1,2,3"})
          .exit_code,
      2);
  test::write_file(dir + "/landmarks.yaml", "landmarks:\n  menton: [0, 0, 0]\n");
  r = run_hexbite({"reorder", dir + "/in.vtu", "-o", dir + "/o.vtu", "--landmarks", dir + "/landmarks.yaml"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("left_condyle_tmj_point"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace hexbite
