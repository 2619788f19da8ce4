// Cycle elimination: the elimination scheme, the hex complex built from it and the embedded mesh.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <numeric>

#include "common/error.h"
#include "mesher/cycle_elimination.h"
#include "mesher/elimination_feasibility.h"
#include "mesher/hex_boundary.h"
#include "mesher/hex_mesh_io.h"
#include "mesher/primal_cycle_decomposition.h"
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

// Quads that all face inward bound the same solid: before, `quad check` called such a surface usable and
// `mesh --method sheets` then failed (exit 1) with every hex inverted.
TEST(CycleElimination, InwardQuadsAreMeshedAsTheSameSolid) {
  for (const std::array<int, 3> dims : {std::array<int, 3>{1, 1, 1}, {3, 2, 2}}) {
    QuadSurface s = test::block_surface(dims[0], dims[1], dims[2]);
    for (auto& q : s.quads) std::reverse(q.begin(), q.end());
    SheetMeshReport report;
    mesh_by_cycle_elimination(s, {}, &report);
    EXPECT_EQ(report.hexes, dims[0] * dims[1] * dims[2]);
    EXPECT_EQ(report.quality.inverted, 0);
    EXPECT_GT(report.quality.scaled_jacobian.min, 0.999);
  }
}

// A single elimination removes exactly one chord, so a perfect scheme of single steps has chords - 3 steps.
// On a block the smallest side is always an end face, next to the block's right-angled edges, so the
// default (geometric) order, like fewest-hexes, peels off end slabs and rebuilds the n m k grid, which
// barycentric smoothing places exactly.
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

SheetMeshReport expect_valid_sheet_mesh(const QuadSurface& s, EliminationOrder order) {
  SheetMeshOptions options;
  options.elimination.order = order;
  SheetMeshReport report;
  const HexMesh mesh = mesh_by_cycle_elimination(s, options, &report);
  EXPECT_EQ(report.chords_eliminated, chord_count(s) - 3);
  EXPECT_EQ(report.eliminations, report.eliminations_single + report.eliminations_k_step);
  EXPECT_EQ(report.chords_eliminated, report.eliminations_single + 2 * report.eliminations_k_step);
  EXPECT_EQ(report.external_sheets + report.internal_sheets, report.eliminations);
  EXPECT_EQ(report.quality.inverted, 0);
  EXPECT_GT(report.quality.scaled_jacobian.min, 0.0);
  EXPECT_EQ(report.hexes, static_cast<int>(mesh.hexes.size()));
  expect_boundary_equals_input(mesh, s);
  return report;
}

TEST(CycleElimination, PerturbedBlock) {
  expect_valid_sheet_mesh(test::perturbed(test::block_surface(3, 2, 2), 0.15),
                          EliminationOrder::kFewestHexes);
}

TEST(CycleElimination, PolycubesAllOrders) {
  const QuadSurface l = test::polycube_surface(2, 2, 1, [](int i, int j, int) { return i == 0 || j == 0; });
  // A chain of boxes turning twice (a Z in the xy plane, two cells thick).
  const QuadSurface z = test::polycube_surface(
      3, 2, 2, [](int i, int j, int) { return (j == 0 && i <= 1) || (j == 1 && i >= 1); });
  // A thick L: 3 x 3 x 2 without its 2 x 2 x 2 corner.
  const QuadSurface thick_l =
      test::polycube_surface(3, 3, 2, [](int i, int j, int) { return i == 0 || j == 0; });
  for (const QuadSurface* s : {&l, &z, &thick_l})
    for (EliminationOrder order :
         {EliminationOrder::kFewestHexes, EliminationOrder::kLookAhead, EliminationOrder::kGeometric}) {
      SCOPED_TRACE(std::string(elimination_order_name(order)) + ", " + std::to_string(s->quads.size()) +
                   " quads");
      expect_valid_sheet_mesh(test::perturbed(*s, 0.05), order);
    }
}

// The collapse of a chord as a graph operation, whichever side moves: the strip quads vanish and the two
// ends of every rung become one vertex (the smaller id). Empty when two rungs share an endpoint.
std::vector<std::array<int, 4>> contract_chord(const std::vector<std::array<int, 4>>& quads, const Chord& c) {
  const QuadEdges qe = build_quad_edges(quads);
  int n = 0;
  for (const auto& q : quads) n = std::max(n, *std::max_element(q.begin(), q.end()) + 1);
  std::vector<int> to(static_cast<std::size_t>(n));
  std::iota(to.begin(), to.end(), 0);
  std::vector<char> used(static_cast<std::size_t>(n), 0), strip(quads.size(), 0);
  for (int e : c.edges) {
    const auto [a, b] = qe.edges[e];
    if (used[a]++ || used[b]++) return {};
    to[b] = a;
  }
  for (int q : c.quads) strip[q] = 1;
  std::vector<std::array<int, 4>> out;
  for (std::size_t q = 0; q < quads.size(); ++q) {
    if (strip[q]) continue;
    auto m = quads[q];
    for (int& v : m) v = to[v];
    out.push_back(m);
  }
  return out;
}

// The near-linear face test must agree with the full check (removal of every vertex for 3-connectivity,
// Boyer-Myrvold for planarity) on every chord collapse of several surfaces, two levels deep, feasible or
// not.
TEST(CycleElimination, FaceTestAgreesWithFullCheck) {
  const std::vector<QuadSurface> surfaces = {
      test::block_surface(3, 2, 2),
      test::block_surface(3, 3, 1),  // its rim chord leaves vertices of degree 2
      test::polycube_surface(3, 3, 2, [](int i, int j, int) { return i == 0 || j == 0; }),
      test::polycube_surface(3, 2, 2,
                             [](int i, int j, int) { return (j == 0 && i <= 1) || (j == 1 && i >= 1); }),
      test::o_grid_disk_surface(),
      test::no_scheme_surface(),
      test::sphere_surface(3)};
  int feasible = 0, infeasible = 0;
  auto compare = [&](const std::vector<std::array<int, 4>>& quads, int vertices) {
    QuadSurface q;
    q.vertices.assign(static_cast<std::size_t>(vertices), Vec3{0.0, 0.0, 0.0});
    q.quads = quads;
    const QuadSurfaceReport r = check_quad_surface(q, "");
    const bool full = r.ball && r.simple && r.planar && r.three_connected;
    EXPECT_EQ(is_polyhedral_ball(quads), full) << quads.size() << " quads";
    (full ? feasible : infeasible) += 1;
    return full;
  };
  for (const QuadSurface& s : surfaces) {
    const int n = static_cast<int>(s.vertices.size());
    EXPECT_TRUE(compare(s.quads, n));
    for (const Chord& c : find_chords(s.quads, build_quad_edges(s.quads))) {
      if (!c.simple()) continue;
      const auto once = contract_chord(s.quads, c);
      if (once.empty() || !compare(once, n)) continue;
      for (const Chord& d : find_chords(once, build_quad_edges(once))) {
        if (!d.simple()) continue;
        const auto twice = contract_chord(once, d);
        if (!twice.empty()) compare(twice, n);
      }
    }
  }
  EXPECT_GT(feasible, 50);
  EXPECT_GT(infeasible, 10);
}

// The O-grid disk's wall lies between two sharp rims: the geometric order eliminates both cap rings at once
// (a 2-step with Q = the 8 wall quads, one annular sheet), then the remaining 2 x 2 x 1 block by single
// eliminations: the 12 hexes of the O-grid, with no interior vertex and no inverted hex (fewest-hexes leaves
// 8 inverted, docs/sheets.md).
TEST(CycleElimination, GeometricOrderTakesTheAnnularSheetOfAnOGridDisk) {
  const QuadSurface s = test::o_grid_disk_surface();
  ASSERT_TRUE(check_quad_surface(s, "").usable());
  ASSERT_EQ(chord_count(s), 7);
  EliminationOptions options;
  options.order = EliminationOrder::kGeometric;
  const EliminationScheme scheme = eliminate_chords(s, options);
  ASSERT_FALSE(scheme.eliminations.empty());
  EXPECT_EQ(scheme.eliminations[0].chords, 2);
  EXPECT_EQ(scheme.eliminations[0].hexes.size(), 8u);
  EXPECT_EQ(scheme.eliminations[0].chord_length, 16);
  const SheetMeshReport geometric = expect_valid_sheet_mesh(s, EliminationOrder::kGeometric);
  EXPECT_EQ(geometric.eliminations_k_step, 1);
  EXPECT_EQ(geometric.eliminations_single, 2);
  EXPECT_EQ(geometric.hexes, 12);
  EXPECT_EQ(geometric.interior_vertices, 0);
  EXPECT_EQ(geometric.pillow_hexes, 0);
  // Fewest-hexes (single eliminations only) first puts 4 hexes on a cap's 2 x 2 centre, whose rail then
  // merges into the rim in the same plane; with every vertex on the boundary nothing can repair that.
  SheetMeshOptions fewest_hexes;
  fewest_hexes.elimination.order = EliminationOrder::kFewestHexes;
  fewest_hexes.pillow_if_inverted = false;
  SheetMeshReport fewest;
  mesh_by_cycle_elimination(s, fewest_hexes, &fewest);
  EXPECT_EQ(fewest.eliminations_k_step, 0);
  EXPECT_EQ(fewest.eliminations_single, 4);
  EXPECT_EQ(fewest.quality.inverted, 8);
  EXPECT_GT(geometric.quality.scaled_jacobian.min, fewest.quality.scaled_jacobian.min);
  // The pillow rescue gives those hexes interior vertices: valid, one hex per boundary quad more.
  const SheetMeshReport rescued = expect_valid_sheet_mesh(s, EliminationOrder::kFewestHexes);
  EXPECT_EQ(rescued.inverted_without_pillow, 8);
  EXPECT_EQ(rescued.pillow_hexes, static_cast<int>(s.quads.size()));
  EXPECT_EQ(rescued.hexes, 12 + rescued.pillow_hexes);
}

// A cubed sphere with every vertex moved by up to 0.3 of the radius 10 (8 x 8 per face, 384 quads): the
// elimination's hexes keep 47 inverted whatever the interior does, mostly corner hexes with two faces on
// the boundary at a flat angle. The pillow rescue puts one layer under the boundary (384 hexes), after
// which the embedding is valid; the boundary is still exactly the input.
TEST(CycleElimination, PillowRescuesAPerturbedSphere) {
  const QuadSurface s = test::perturbed(test::sphere_surface(8, 10.0), 0.3);
  ASSERT_TRUE(check_quad_surface(s, "").usable());
  SheetMeshOptions plain;
  plain.pillow_if_inverted = false;
  SheetMeshReport without;
  mesh_by_cycle_elimination(s, plain, &without);
  EXPECT_EQ(without.hexes, 512);
  EXPECT_EQ(without.quality.inverted, 47);
  EXPECT_EQ(without.pillow_hexes, 0);
  const SheetMeshReport with = expect_valid_sheet_mesh(s, EliminationOrder::kGeometric);
  EXPECT_EQ(with.inverted_without_pillow, 47);
  EXPECT_EQ(with.pillow_hexes, 384);
  EXPECT_EQ(with.hexes, 512 + 384);
  EXPECT_GT(with.quality.scaled_jacobian.min, 0.4);
  EXPECT_GT(with.quality.scaled_jacobian.mean, 0.85);
}

// The pillowed block's ring chord has the shrunk quad as its smaller side, in the plane of the top face:
// an external sheet there is one flat hex whose 8 vertices are all on the boundary. The internal sheet
// instead wraps the block's top centre hex in 5 hexes (its 4 lower corners duplicated inside), so that
// fewest-hexes and the geometric order give 27 + 5 hexes, one internal sheet and no inverted hex; without
// internal sheets the flat hex stays.
TEST(CycleElimination, InternalSheetUnderAPillowedPatch) {
  const QuadSurface s = test::pillowed_block_surface();
  ASSERT_TRUE(check_quad_surface(s, "").usable());
  EXPECT_EQ(s.quads.size(), 58u);
  EXPECT_EQ(chord_count(s), 10);
  const SheetMeshReport internal = expect_valid_sheet_mesh(s, EliminationOrder::kFewestHexes);
  EXPECT_EQ(internal.internal_sheets, 1);
  EXPECT_EQ(internal.external_sheets, 6);
  EXPECT_EQ(internal.hexes, 32);
  EXPECT_EQ(internal.interior_vertices, 8 + 4);
  // The default order takes the flat pillow first too, while the hex below it is still interior.
  const SheetMeshReport by_default = expect_valid_sheet_mesh(s, EliminationOrder::kGeometric);
  EXPECT_EQ(by_default.internal_sheets, 1);
  EXPECT_EQ(by_default.hexes, 32);

  SheetMeshOptions external_only;
  external_only.elimination.order = EliminationOrder::kFewestHexes;
  external_only.internal_sheets = false;
  external_only.pillow_if_inverted = false;
  SheetMeshReport external;
  const HexMesh mesh = mesh_by_cycle_elimination(s, external_only, &external);
  expect_boundary_equals_input(mesh, s);
  EXPECT_EQ(external.internal_sheets, 0);
  EXPECT_EQ(external.hexes, 28);
  EXPECT_EQ(external.quality.inverted, 1);
  // With the pillow rescue the flat hex gets interior vertices and the external mesh is valid too, at the
  // price of 58 pillow hexes instead of the internal sheet's 4 more.
  external_only.pillow_if_inverted = true;
  const HexMesh rescued = mesh_by_cycle_elimination(s, external_only, &external);
  expect_boundary_equals_input(rescued, s);
  EXPECT_EQ(external.inverted_without_pillow, 1);
  EXPECT_EQ(external.pillow_hexes, 58);
  EXPECT_EQ(external.hexes, 28 + 58);
  EXPECT_EQ(external.quality.inverted, 0);

  // The two-argument construction is the external one; the overload reports the kinds in elimination
  // order (the ring, eliminated first, got the internal sheet).
  EliminationOptions fewest;
  fewest.order = EliminationOrder::kFewestHexes;
  const EliminationScheme scheme = eliminate_chords(s, fewest);
  EXPECT_EQ(build_hex_complex(s, scheme).hexes.size(), 28u);
  std::vector<SheetKind> kinds;
  EXPECT_EQ(build_hex_complex(s, scheme, true, &kinds).hexes.size(), 32u);
  ASSERT_EQ(kinds.size(), scheme.eliminations.size());
  EXPECT_EQ(kinds[0], SheetKind::kInternal);
  EXPECT_EQ(std::count(kinds.begin(), kinds.end(), SheetKind::kInternal), 1);
}

// EliminationOptions::first_rungs: chords named by a rung go first, in the given order, with ids followed
// through the collapses; rungs that are gone or no edge are skipped. On the 4 x 2 x 2 block fewest-hexes
// starts with an end face (4 hexes); named first, the y-chord through (2, 0, 0)-(2, 1, 0) takes the y = 0
// face (8 hexes); its other rung is gone after it; the z-edge at the origin, renamed by that collapse to
// (0, 1, 0)-(0, 1, 1), then gives the z = 0 face of the 4 x 1 x 2 block (4 hexes, where fewest-hexes would
// take 2). The result is still the block's 16 hexes.
TEST(CycleElimination, FirstRungsAreEliminatedFirst) {
  const QuadSurface s = test::block_surface(4, 2, 2);
  auto at = [&](const Vec3& p) { return test::vertex_at(s, p); };
  EliminationOptions options;
  options.order = EliminationOrder::kFewestHexes;
  const EliminationScheme plain = eliminate_chords(s, options);
  ASSERT_GE(plain.eliminations.size(), 2u);
  EXPECT_EQ(plain.eliminations[0].hexes.size(), 4u);
  options.first_rungs = {{at({2, 0, 0}), at({2, 1, 0})},
                         {at({3, 0, 0}), at({3, 1, 0})},
                         {0, 0},
                         {-1, 1000},
                         {at({0, 0, 0}), at({0, 0, 1})}};
  const EliminationScheme first = eliminate_chords(s, options);
  ASSERT_GE(first.eliminations.size(), 2u);
  EXPECT_EQ(first.eliminations[0].hexes.size(), 8u);
  EXPECT_EQ(first.eliminations[0].chord_length, 12);
  EXPECT_EQ(first.eliminations[1].hexes.size(), 4u);
  EXPECT_EQ(first.eliminations[1].quads_before, 40 - 12);
  EXPECT_EQ(build_hex_complex(s, first).hexes.size(), 16u);
  SheetMeshOptions mesh_options;
  mesh_options.elimination = options;
  SheetMeshReport r;
  expect_boundary_equals_input(mesh_by_cycle_elimination(s, mesh_options, &r), s);
  EXPECT_EQ(r.quality.inverted, 0);
  EXPECT_NEAR(r.quality.scaled_jacobian.min, 1.0, 1e-9);
}

TEST(CycleElimination, NoSchemeIsARunErrorNamingTheChords) {
  const QuadSurface s = test::no_scheme_surface();
  ASSERT_TRUE(check_quad_surface(s, "").usable());
  EXPECT_EQ(s.quads.size(), 30u);
  for (EliminationOrder order :
       {EliminationOrder::kFewestHexes, EliminationOrder::kLookAhead, EliminationOrder::kGeometric}) {
    SCOPED_TRACE(elimination_order_name(order));
    EliminationOptions options;
    options.order = order;
    try {
      eliminate_chords(s, options);
      ADD_FAILURE() << "no RunError";
    } catch (const RunError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("cycle elimination is stuck"), std::string::npos) << m;
      EXPECT_NE(m.find("chord 0 (length"), std::string::npos) << m;
      EXPECT_NE(m.find("--method grid"), std::string::npos) << m;
      // The look-ahead orders see at once that every feasible first step is a dead end.
      if (order != EliminationOrder::kFewestHexes)
        EXPECT_NE(m.find("after 0 eliminations"), std::string::npos);
    }
  }
}

// Decomposition along a primal cycle (mesher/primal_cycle_decomposition.h). On the 2 x 2 x 2 block the most
// balanced of the shortest cycles is an equator (8 edges, 12 quads on either side); a ladder disk (3 quads)
// would leave odd parts, so the disk is the fan of 4 quads around one new vertex at the centroid, and each
// part is the surface of a 2 x 2 x 1 block.
TEST(CycleElimination, DecompositionSplitsABlockAtAnEquatorWithAFan) {
  const QuadSurface s = test::block_surface(2, 2, 2);
  const int n = static_cast<int>(s.vertices.size());
  int handed = 0;
  const DecompositionSearch search = search_primal_cycle_splits(s, {}, [&](const PrimalCycleSplit& split) {
    ++handed;
    EXPECT_EQ(split.cycle.size(), 8u);
    int planes = 0;  // coordinates equal to 1 on the whole cycle
    for (int c = 0; c < 3; ++c)
      planes +=
          std::all_of(split.cycle.begin(), split.cycle.end(), [&](int v) { return s.vertices[v][c] == 1.0; });
    EXPECT_EQ(planes, 1);
    EXPECT_EQ(split.side_quads, (std::array<int, 2>{12, 12}));
    EXPECT_EQ(split.disk.size(), 4u);
    EXPECT_EQ(split.disk_vertices, 1);
    EXPECT_EQ(split.disk_positions, (std::vector<Vec3>{{1.0, 1.0, 1.0}}));
    for (int p = 0; p < 2; ++p) {
      const QuadSurface& part = split.parts[p];
      EXPECT_TRUE(check_quad_surface(part, "").usable());
      EXPECT_EQ(part.quads.size(), 16u);
      EXPECT_EQ(part.vertices.size(), 18u);
      EXPECT_EQ(chord_count(part), 5);
      // The part in split ids: its side's input quads plus the disk, reversed for part 1.
      std::vector<std::array<int, 4>> quads;
      for (auto q : part.quads) {
        for (int& v : q) v = split.ids[p][v];
        quads.push_back(q);
      }
      for (std::size_t v = 0; v < part.vertices.size(); ++v) {
        const int id = split.ids[p][v];
        EXPECT_EQ(part.vertices[v], id < n ? s.vertices[id] : split.disk_positions[id - n]);
      }
      std::vector<std::array<int, 4>> expected;
      for (const auto& q : split.disk)
        expected.push_back(p == 0 ? q : std::array<int, 4>{q[3], q[2], q[1], q[0]});
      for (const auto& q : s.quads)
        if (std::find(quads.begin(), quads.end(), q) != quads.end()) expected.push_back(q);
      EXPECT_EQ(test::canonical_quads(quads), test::canonical_quads(expected));
    }
    return true;
  });
  EXPECT_TRUE(search.accepted);
  EXPECT_EQ(search.splits, 1);
  EXPECT_EQ(handed, 1);
}

// The 30-quad ball without an elimination scheme (convex version) meshes through one decomposition in every
// order: an 8-cycle with 15 quads on either side, spanned by a ladder of 3 quads, leaves two 18-quad parts
// that eliminate (4 single eliminations, 10 hexes in all), and each part gets a pillow layer under its 18
// quads (36 hexes). The result must be conforming (extract_boundary() throws otherwise), bounded by exactly
// the input, every hex must have 8 distinct vertices and at most one face on the boundary, and no hex may be
// inverted without the pillow rescue. Without the part pillows the 10 hexes have no interior vertex: 6
// inverted, and the pillow rescue leaves 2 of its 40.
TEST(CycleElimination, StuckSurfaceMeshesByDecomposition) {
  const QuadSurface s = test::no_scheme_convex_surface();
  const int n = static_cast<int>(s.vertices.size());
  for (EliminationOrder order :
       {EliminationOrder::kFewestHexes, EliminationOrder::kLookAhead, EliminationOrder::kGeometric}) {
    SCOPED_TRACE(elimination_order_name(order));
    SheetMeshOptions options;
    options.elimination.order = order;
    SheetMeshReport r;
    const HexMesh mesh = mesh_by_cycle_elimination(s, options, &r);
    expect_boundary_equals_input(mesh, s);
    ASSERT_EQ(mesh.hexes.size(), 46u);
    for (const auto& hex : mesh.hexes) {
      auto sorted = hex;
      std::sort(sorted.begin(), sorted.end());
      EXPECT_EQ(std::adjacent_find(sorted.begin(), sorted.end()), sorted.end());
      EXPECT_LE(std::count_if(hex.begin(), hex.end(), [n](int v) { return v < n; }), 4);
    }
    EXPECT_EQ(r.decompositions, 1);
    EXPECT_EQ(r.hexes, 46);
    EXPECT_EQ(r.interior_vertices, 40);  // a copy of every part's vertex (32 + 8 on the cycle)
    EXPECT_EQ(r.eliminations, 4);
    EXPECT_EQ(r.eliminations_single, 4);
    EXPECT_EQ(r.chords_eliminated, 4);
    EXPECT_EQ(r.external_sheets + r.internal_sheets, 4);
    EXPECT_EQ(r.inverted_without_pillow, 0);
    EXPECT_EQ(r.pillow_hexes, 0);
    EXPECT_EQ(r.quality.inverted, 0);
    EXPECT_GT(r.quality.scaled_jacobian.min, 0.15);
  }
  SheetMeshOptions unpillowed;
  unpillowed.decomposition.pillow_parts = false;
  SheetMeshReport r;
  const HexMesh mesh = mesh_by_cycle_elimination(s, unpillowed, &r);
  expect_boundary_equals_input(mesh, s);
  EXPECT_EQ(r.decompositions, 1);
  EXPECT_EQ(r.inverted_without_pillow, 6);
  EXPECT_EQ(r.hexes, 40);
  EXPECT_EQ(r.pillow_hexes, 30);
  EXPECT_EQ(r.quality.inverted, 2);
  // A surface with a scheme is never decomposed.
  SheetMeshReport block;
  mesh_by_cycle_elimination(test::block_surface(3, 2, 2), {}, &block);
  EXPECT_EQ(block.decompositions, 0);
}

// no_scheme_surface() has 4 quads with three collinear corners (the collapsed diagonals' ends): a hex on such
// a quad has a corner Jacobian of 0 there whatever the interior, so no hex mesh with this boundary is valid.
// With the boundary fixed (optimize), mesh_by_cycle_elimination says so; the decomposition's complex,
// embedded with the boundary fixed, has exactly those 4 hexes degenerate (Jacobian 0, not negative) and the
// other 42 valid.
TEST(CycleElimination, CollinearQuadCornersAreAnInputError) {
  const QuadSurface s = test::no_scheme_surface();
  try {
    mesh_by_cycle_elimination(s, {});
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("has three collinear corners"), std::string::npos) << m;
    EXPECT_NE(m.find("corner Jacobian of 0"), std::string::npos) << m;
    EXPECT_NE(m.find("no valid hex mesh has this boundary"), std::string::npos) << m;
    EXPECT_NE(m.find("(4 such quad corners in all)"), std::string::npos) << m;
  }
  SheetMeshOptions unembedded;
  unembedded.optimize = false;
  HexMesh mesh = mesh_by_cycle_elimination(s, unembedded);
  ASSERT_EQ(mesh.hexes.size(), 46u);
  const int n = static_cast<int>(s.vertices.size());
  std::vector<char> fixed(mesh.vertices.size(), 0);
  std::fill(fixed.begin(), fixed.begin() + n, 1);
  optimize_hex_mesh(mesh, nullptr, fixed);
  const HexQualityField field = compute_hex_quality(mesh);
  const QualitySummary quality = summarize_quality(mesh, field);
  ASSERT_EQ(quality.inverted, 4);
  for (int h : quality.inverted_hexes) {
    EXPECT_EQ(field.jacobian[h], 0.0);
    // The hex's boundary face (corners 4..7, the pillow hex's quad) has three collinear corners.
    const auto& hex = mesh.hexes[h];
    bool collinear = false;
    for (int k = 0; k < 4; ++k) {
      const Vec3 a = mesh.vertices[hex[4 + (k + 3) % 4]], b = mesh.vertices[hex[4 + k]],
                 c = mesh.vertices[hex[4 + (k + 1) % 4]];
      const Vec3 u{a[0] - b[0], a[1] - b[1], a[2] - b[2]}, w{c[0] - b[0], c[1] - b[1], c[2] - b[2]};
      collinear = collinear ||
                  (u[1] * w[2] == u[2] * w[1] && u[2] * w[0] == u[0] * w[2] && u[0] * w[1] == u[1] * w[0]);
    }
    EXPECT_TRUE(collinear) << "hex " << h;
  }
}

// Where decomposition fails as well (here: only 4-cycles allowed, and every 4-cycle of this ball bounds a
// single quad), the RunError still names the chords, says what was tried and ends with the advice; with
// decomposition off it is the elimination's own message.
TEST(CycleElimination, FailedDecompositionIsARunError) {
  // The convex version: collinear quad corners are refused before the elimination.
  const QuadSurface s = test::no_scheme_convex_surface();
  SheetMeshOptions options;
  options.decomposition.max_cycle_length = 4;
  try {
    mesh_by_cycle_elimination(s, options);
    ADD_FAILURE() << "no RunError";
  } catch (const RunError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("cycle elimination is stuck"), std::string::npos) << m;
    EXPECT_NE(m.find("chord 0 (length"), std::string::npos) << m;
    EXPECT_NE(m.find("Decomposition along a primal cycle did not help either"), std::string::npos) << m;
    EXPECT_NE(m.find("even length up to 4 gave 0 splits"), std::string::npos) << m;
    EXPECT_EQ(m.substr(m.size() - 13), "--method grid") << m;
  }
  options.decomposition.max_depth = 0;
  try {
    mesh_by_cycle_elimination(s, options);
    ADD_FAILURE() << "no RunError";
  } catch (const RunError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("cycle elimination is stuck"), std::string::npos) << m;
    EXPECT_EQ(m.find("Decomposition"), std::string::npos) << m;
  }
}

// Many generated balls: every usable polycube of a 3 x 3 x 2 cell block (cell subsets from a fixed
// pseudo-random sequence) in every order, with internal sheets. The complex must be conforming, every hex
// must have 8 distinct vertices, and its boundary must be the input exactly; a complete scheme eliminates
// all chords but three.
TEST(CycleElimination, ManyGeneratedPolycubes) {
  unsigned state = 7u;
  int tested = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    state = state * 1664525u + 1013904223u;
    const unsigned mask = state >> 5;
    auto keep = [mask](int i, int j, int k) { return ((mask >> (i + 3 * j + 9 * k)) & 1u) != 0; };
    int cells = 0;
    for (int c = 0; c < 18; ++c) cells += (mask >> c) & 1u;
    if (cells < 2) continue;
    const QuadSurface s = test::polycube_surface(3, 3, 2, keep);
    if (!check_quad_surface(s, "").usable()) continue;
    ++tested;
    for (EliminationOrder order :
         {EliminationOrder::kFewestHexes, EliminationOrder::kLookAhead, EliminationOrder::kGeometric}) {
      SCOPED_TRACE("cells " + std::to_string(mask & 0x3ffffu) + ", " + elimination_order_name(order));
      EliminationOptions options;
      options.order = order;
      const EliminationScheme scheme = eliminate_chords(s, options);
      int removed = 0;
      for (const Elimination& e : scheme.eliminations) removed += e.chords;
      EXPECT_EQ(removed, chord_count(s) - 3);
      const HexMesh mesh = build_hex_complex(s, scheme, true, nullptr);
      for (const auto& hex : mesh.hexes) {
        auto sorted = hex;
        std::sort(sorted.begin(), sorted.end());
        ASSERT_EQ(std::adjacent_find(sorted.begin(), sorted.end()), sorted.end());
      }
      expect_boundary_equals_input(mesh, s);
    }
  }
  EXPECT_GT(tested, 200);
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
  EXPECT_EQ(parse_elimination_order("geometric"), EliminationOrder::kGeometric);
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
  EXPECT_EQ(j["eliminations_single"], 4);
  EXPECT_EQ(j["eliminations_k_step"], 0);
  EXPECT_EQ(j["external_sheets"], 4);
  EXPECT_EQ(j["internal_sheets"], 0);
  EXPECT_EQ(j["eliminations"]["single"], 4);
  const HexMesh mesh = read_vtu(dir + "/m.vtu");
  EXPECT_EQ(mesh.hexes.size(), 12u);
  for (std::size_t v = 0; v < s.vertices.size(); ++v) EXPECT_EQ(mesh.vertices[v], s.vertices[v]);

  write_quad_obj(dir + "/torus.obj", test::torus_surface(6, 4));
  const auto bad = test::run_hexbite(
      {"mesh", "--method", "sheets", "--quad-surface", dir + "/torus.obj", "-o", dir + "/t.vtu"});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("not a ball: genus 1"), std::string::npos) << bad.err;
  EXPECT_FALSE(std::filesystem::exists(dir + "/t.vtu"));

  // The surface without a scheme meshes by decomposition into a valid mesh; with collinear quad corners
  // (no valid mesh exists) it is an input error that says so, and nothing is written even with
  // --allow-invalid.
  write_quad_obj(dir + "/stuck.obj", test::no_scheme_convex_surface());
  const auto split = test::run_hexbite({"mesh", "--method", "sheets", "--quad-surface", dir + "/stuck.obj",
                                        "--order", "look-ahead", "-o", dir + "/s.vtu", "--json"});
  ASSERT_EQ(split.exit_code, 0) << split.err;
  const auto js = nlohmann::json::parse(split.out);
  EXPECT_EQ(js["decompositions"], 1);
  EXPECT_EQ(js["hexes"], 46);
  EXPECT_EQ(js["eliminations_single"], 4);
  EXPECT_EQ(js["quality"]["inverted"], 0);
  const HexMesh written = read_vtu(dir + "/s.vtu");
  EXPECT_EQ(written.hexes.size(), 46u);
  write_quad_obj(dir + "/flat.obj", test::no_scheme_surface());
  const auto flat = test::run_hexbite({"mesh", "--method", "sheets", "--quad-surface", dir + "/flat.obj",
                                       "-o", dir + "/f.vtu", "--allow-invalid"});
  EXPECT_EQ(flat.exit_code, 2);
  EXPECT_NE(flat.err.find("three collinear corners"), std::string::npos) << flat.err;
  EXPECT_NE(flat.err.find("no valid hex mesh has this boundary"), std::string::npos) << flat.err;
  EXPECT_FALSE(std::filesystem::exists(dir + "/f.vtu"));
  EXPECT_EQ(j["decompositions"], 0);
}

}  // namespace
}  // namespace hexbite
