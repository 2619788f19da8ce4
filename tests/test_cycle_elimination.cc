// Cycle elimination: the elimination scheme, the hex complex built from it and the embedded mesh.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "common/error.h"
#include "mesher/cycle_elimination.h"
#include "mesher/hex_boundary.h"
#include "mesher/hex_mesh_io.h"
#include "mesher/quad_check.h"
#include "mesher/quad_surface_io.h"
#include "tests/quad_test_surfaces.h"
#include "tests/test_util.h"

namespace hexbite {
namespace {

// The output must be bounded by exactly the input: the boundary vertices are the input vertices 0..n-1 with
// the same coordinates, and the boundary quads are the input quads with the same orientation.
void expect_boundary_equals_input(const HexMesh& mesh, const QuadSurface& input) {
  const HexBoundary b = extract_boundary(mesh);  // throws on a non-conforming mesh
  const int n = static_cast<int>(input.vertices.size());
  ASSERT_EQ(static_cast<int>(b.boundary_vertices.size()), n);
  for (int v = 0; v < n; ++v) {
    ASSERT_EQ(b.boundary_vertices[v], v);
    EXPECT_EQ(mesh.vertices[v], input.vertices[v]);
  }
  std::vector<std::array<int, 4>> quads;
  for (auto q : b.surface.quads) {
    for (int& v : q) v = b.boundary_vertices[v];
    quads.push_back(q);
  }
  EXPECT_EQ(test::canonical_quads(quads), test::canonical_quads(input.quads));
}

int chord_count(const QuadSurface& s) {
  return static_cast<int>(find_chords(s.quads, build_quad_edges(s.quads)).size());
}

TEST(CycleElimination, CubeIsOneHex) {
  const QuadSurface s = test::block_surface(1, 1, 1);
  const EliminationScheme scheme = eliminate_chords(s);
  EXPECT_TRUE(scheme.eliminations.empty());
  const HexMesh mesh = build_hex_complex(s, scheme);
  ASSERT_EQ(mesh.hexes.size(), 1u);
  EXPECT_EQ(summarize_quality(mesh).inverted, 0);
  expect_boundary_equals_input(mesh, s);
}

// Each elimination removes exactly one chord, so a perfect scheme has chords - 3 steps. On a block the
// smallest side is always an end face, so fewest-hexes peels off end slabs and rebuilds the n m k grid,
// which barycentric smoothing places exactly.
TEST(CycleElimination, BlocksGiveTheStructuredGrid) {
  for (const std::array<int, 3> dims : {std::array<int, 3>{2, 1, 1}, {2, 2, 2}, {3, 2, 1}, {3, 3, 4}}) {
    const auto [n, m, k] = dims;
    SCOPED_TRACE(std::to_string(n) + "x" + std::to_string(m) + "x" + std::to_string(k));
    const QuadSurface s = test::block_surface(n, m, k);
    SheetMeshReport report;
    const HexMesh mesh = mesh_by_cycle_elimination(s, {}, &report);
    EXPECT_EQ(report.chords, n + m + k);
    EXPECT_EQ(report.eliminations, n + m + k - 3);
    EXPECT_EQ(report.hexes, n * m * k);
    EXPECT_EQ(report.interior_vertices, (n - 1) * (m - 1) * (k - 1));
    EXPECT_EQ(report.quality.inverted, 0);
    EXPECT_GT(report.quality.scaled_jacobian.min, 0.999);
    if (report.interior_vertices > 0) {
      EXPECT_EQ(report.quality.node_degree.max_edges, 6);
      EXPECT_EQ(report.quality.node_degree.max_hexes, 8);
    }
    expect_boundary_equals_input(mesh, s);
  }
}

void expect_valid_sheet_mesh(const QuadSurface& s, EliminationOrder order) {
  SheetMeshOptions options;
  options.elimination.order = order;
  SheetMeshReport report;
  const HexMesh mesh = mesh_by_cycle_elimination(s, options, &report);
  EXPECT_EQ(report.eliminations, chord_count(s) - 3);
  EXPECT_EQ(report.quality.inverted, 0);
  EXPECT_GT(report.quality.scaled_jacobian.min, 0.0);
  EXPECT_EQ(report.hexes, static_cast<int>(mesh.hexes.size()));
  expect_boundary_equals_input(mesh, s);
}

TEST(CycleElimination, PerturbedBlock) {
  expect_valid_sheet_mesh(test::perturbed(test::block_surface(3, 2, 2), 0.15),
                          EliminationOrder::kFewestHexes);
}

TEST(CycleElimination, PolycubesBothOrders) {
  const QuadSurface l = test::polycube_surface(2, 2, 1, [](int i, int j, int) { return i == 0 || j == 0; });
  // A chain of boxes turning twice (a Z in the xy plane, two cells thick).
  const QuadSurface z = test::polycube_surface(
      3, 2, 2, [](int i, int j, int) { return (j == 0 && i <= 1) || (j == 1 && i >= 1); });
  // A thick L: 3 x 3 x 2 without its 2 x 2 x 2 corner.
  const QuadSurface thick_l =
      test::polycube_surface(3, 3, 2, [](int i, int j, int) { return i == 0 || j == 0; });
  for (const QuadSurface* s : {&l, &z, &thick_l})
    for (EliminationOrder order : {EliminationOrder::kFewestHexes, EliminationOrder::kLookAhead}) {
      SCOPED_TRACE(std::string(elimination_order_name(order)) + ", " + std::to_string(s->quads.size()) +
                   " quads");
      expect_valid_sheet_mesh(test::perturbed(*s, 0.05), order);
    }
}

TEST(CycleElimination, SameBytesTwice) {
  const QuadSurface s = test::perturbed(
      test::polycube_surface(3, 3, 2, [](int i, int j, int) { return i == 0 || j == 0; }), 0.1);
  const std::string dir = test::temp_dir();
  write_vtu(dir + "/a.vtu", mesh_by_cycle_elimination(s, {}));
  write_vtu(dir + "/b.vtu", mesh_by_cycle_elimination(s, {}));
  EXPECT_EQ(test::read_file(dir + "/a.vtu"), test::read_file(dir + "/b.vtu"));
}

std::string input_error(const QuadSurface& s) {
  try {
    eliminate_chords(s);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(CycleElimination, RejectsUnusableSurfaces) {
  EXPECT_NE(input_error(test::torus_surface(6, 4)).find("not a ball: genus 1"), std::string::npos);
  EXPECT_NE(input_error(test::self_intersecting_surface()).find("self-intersects"), std::string::npos);
  EXPECT_THROW(parse_elimination_order("random"), InputError);
  EXPECT_EQ(parse_elimination_order("look-ahead"), EliminationOrder::kLookAhead);
}

}  // namespace
}  // namespace hexbite

namespace hexbite {
namespace {

TEST(MeshSheetsCli, WritesTheMeshAndRejectsBadSurfaces) {
  const std::string dir = test::temp_dir();
  const QuadSurface s = test::perturbed(test::block_surface(3, 2, 2), 0.1);
  write_quad_obj(dir + "/block.obj", s);
  const auto ok = test::run_hexbite(
      {"mesh", "--method", "sheets", "--quad-surface", dir + "/block.obj", "-o", dir + "/m.vtu", "--json"});
  ASSERT_EQ(ok.exit_code, 0) << ok.err;
  const auto j = nlohmann::json::parse(ok.out);
  EXPECT_EQ(j["hexes"], 12);
  EXPECT_EQ(j["chords"], 7);
  EXPECT_EQ(j["quality"]["inverted"], 0);
  const HexMesh mesh = read_vtu(dir + "/m.vtu");
  EXPECT_EQ(mesh.hexes.size(), 12u);
  for (std::size_t v = 0; v < s.vertices.size(); ++v) EXPECT_EQ(mesh.vertices[v], s.vertices[v]);

  write_quad_obj(dir + "/torus.obj", test::torus_surface(6, 4));
  const auto bad = test::run_hexbite(
      {"mesh", "--method", "sheets", "--quad-surface", dir + "/torus.obj", "-o", dir + "/t.vtu"});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("not a ball: genus 1"), std::string::npos) << bad.err;
  EXPECT_FALSE(std::filesystem::exists(dir + "/t.vtu"));
}

}  // namespace
}  // namespace hexbite
