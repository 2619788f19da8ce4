// Local refinement of a quad surface by nested pillowing (mesher/quad_local_refinement.h): on a block's
// boundary (exact counts, flat geometry) and on the built-in mandible around its bite point, through the
// sheet mesher (mesher/mandible_sheet_mesher.h) and the scenario key mesh.refine_at_bite.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "common/error.h"
#include "mesher/cycle_elimination.h"
#include "mesher/hex_boundary.h"
#include "mesher/mandible_generator.h"
#include "mesher/mandible_sheet_mesher.h"
#include "mesher/quad_check.h"
#include "mesher/quad_local_refinement.h"
#include "mesher/surface_projector.h"
#include "scenarios/scenario.h"
#include "tests/quad_test_surfaces.h"
#include "tests/test_util.h"

namespace hexbite {
namespace {

double distance(const Vec3& a, const Vec3& b) {
  return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
}

// The boundary of a 6 x 6 x 6 block of unit cubes, and the triangles it lies on.
const QuadSurface& box() {
  static const QuadSurface s = test::block_surface(6, 6, 6);
  return s;
}
const SurfaceProjector& box_projector() {
  static const SurfaceProjector p(fan_triangles(box()));
  return p;
}

const Vec3 kTopCentre{3, 3, 6};

QuadSurfaceReport expect_usable(const QuadSurface& q) {
  const QuadSurfaceReport r = check_quad_surface(q, "refined");
  EXPECT_TRUE(r.usable()) << (r.problems.empty() ? "" : r.problems.front());
  EXPECT_TRUE(r.ball);
  EXPECT_TRUE(r.even);
  EXPECT_TRUE(r.simple);
  EXPECT_TRUE(r.three_connected);
  EXPECT_TRUE(r.self_intersecting_chords.empty());
  EXPECT_EQ(r.unused_vertices, 0);
  return r;
}

// The smallest and largest length of the edges whose midpoint lies within `radius` of `center`.
std::pair<double, double> edge_range_near(const QuadSurface& q, const Vec3& center, double radius) {
  double lo = 1e300, hi = 0;
  for (const auto& [a, b] : build_quad_edges(q.quads).edges) {
    const Vec3 mid{(q.vertices[a][0] + q.vertices[b][0]) / 2, (q.vertices[a][1] + q.vertices[b][1]) / 2,
                   (q.vertices[a][2] + q.vertices[b][2]) / 2};
    if (distance(mid, center) > radius) continue;
    lo = std::min(lo, distance(q.vertices[a], q.vertices[b]));
    hi = std::max(hi, distance(q.vertices[a], q.vertices[b]));
  }
  return {lo, hi};
}

LocalRefinementOptions at(const std::vector<Vec3>& points, double radius, int levels) {
  LocalRefinementOptions o;
  o.points = points;
  o.radius_mm = radius;
  o.levels = levels;
  return o;
}

TEST(QuadLocalRefinement, PillowsACrossOnTheBoxThreeTimes) {
  // Quads with their centroid within 1.6 of the top face's centre: the 4 x 4 square without its corners
  // (12 quads), grown at its 4 concave corners (3 of the 4 quads at the vertex in the patch) to the whole
  // square (16 quads, perimeter 16). Three levels add 3 x 16 quads, 3 x 16 vertices and 3 chords.
  LocalRefinementReport report;
  const QuadSurface fine =
      refine_quads_locally(box(), box_projector(), {}, at({kTopCentre}, 1.6, 3), &report);
  EXPECT_EQ(report.patches, 1);
  EXPECT_EQ(report.patch_quads, 16);
  EXPECT_EQ(report.patch_perimeter, 16);
  EXPECT_EQ(report.quads_added, 48);
  EXPECT_EQ(report.vertices_added, 48);
  EXPECT_EQ(fine.quads.size(), box().quads.size() + 48);
  EXPECT_EQ(fine.vertices.size(), box().vertices.size() + 48);
  const QuadSurfaceReport before = check_quad_surface(box(), "box");
  const QuadSurfaceReport after = expect_usable(fine);
  EXPECT_EQ(after.chords.size(), before.chords.size() + 3);
  EXPECT_EQ(report.folded_quads, 0);
}

TEST(QuadLocalRefinement, QuadsNearThePointShrinkAndTheRestStays) {
  LocalRefinementReport report;
  const QuadSurface fine =
      refine_quads_locally(box(), box_projector(), {}, at({kTopCentre}, 1.6, 3), &report);
  ASSERT_EQ(report.sites.size(), 1u);
  const LocalRefinementSite& site = report.sites[0];
  EXPECT_NEAR(site.mean_edge_before_mm, 1.0, 1e-12);  // unit quads
  EXPECT_LT(site.mean_edge_after_mm, 0.6 * site.mean_edge_before_mm);
  EXPECT_GT(site.edges_after, 2 * site.edges_before);
  EXPECT_NEAR(mean_edge_near(fine, kTopCentre, 1.6), site.mean_edge_after_mm, 1e-12);
  // Really spread out, not copies left on top of their originals: no edge near the point collapsed, none
  // grew.
  const auto [shortest, longest] = edge_range_near(fine, kTopCentre, 1.6);
  EXPECT_GT(shortest, 0.1);
  EXPECT_LE(longest, 1.0 + 1e-9);
  // Every vertex stays on the top face, and old vertices away from the patch keep their place exactly.
  for (std::size_t v = 0; v < fine.vertices.size(); ++v) {
    EXPECT_LT(box_projector().distance(fine.vertices[v]), 1e-9) << v;
    if (v < box().vertices.size() && distance(box().vertices[v], kTopCentre) > 2.9)
      EXPECT_EQ(fine.vertices[v], box().vertices[v]) << v;
  }
  EXPECT_EQ(mean_edge_near(fine, {3, 3, 0}, 2.0), mean_edge_near(box(), {3, 3, 0}, 2.0));  // bottom face
}

TEST(QuadLocalRefinement, FixedVerticesStayAndIdsAreKept) {
  // The box vertex at (3, 4, 6), inside the patch: pulled toward the centre unless it is held.
  int centre = -1;
  for (std::size_t v = 0; v < box().vertices.size(); ++v)
    if (distance(box().vertices[v], {3, 3.0 + 1.0, 6}) < 1e-12) centre = static_cast<int>(v);
  ASSERT_GE(centre, 0);
  const QuadSurface free = refine_quads_locally(box(), box_projector(), {}, at({kTopCentre}, 1.6, 2));
  const QuadSurface held = refine_quads_locally(box(), box_projector(), {centre}, at({kTopCentre}, 1.6, 2));
  EXPECT_NE(free.vertices[centre], box().vertices[centre]);  // pulled toward the centre without the hold
  EXPECT_EQ(held.vertices[centre], box().vertices[centre]);
  expect_usable(held);
}

// The box scaled by 3 (3 mm quads), so that a radius of 1 mm selects single quads.
const QuadSurface& big_box() {
  static const QuadSurface s = [] {
    QuadSurface b = box();
    for (Vec3& p : b.vertices)
      for (double& c : p) c *= 3;
    return b;
  }();
  return s;
}
const SurfaceProjector& big_box_projector() {
  static const SurfaceProjector p(fan_triangles(big_box()));
  return p;
}

TEST(QuadLocalRefinement, GrowsPatchesThatTouchAtAVertexOrHaveAHole) {
  // Two quads meeting only at the vertex (9, 9, 18): grown by the quads around it to a 2 x 2 disk.
  LocalRefinementReport pinch;
  expect_usable(refine_quads_locally(big_box(), big_box_projector(), {},
                                     at({{7.5, 7.5, 18}, {10.5, 10.5, 18}}, 1.0, 1), &pinch));
  EXPECT_EQ(pinch.patches, 1);
  EXPECT_EQ(pinch.patch_quads, 4);
  EXPECT_EQ(pinch.patch_perimeter, 8);
  // The ring of 8 quads around the centre quad of a 3 x 3 square: the hole is filled (9 quads, perimeter 12).
  std::vector<Vec3> ring;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i)
      if (i != 1 || j != 1) ring.push_back({4.5 + 3 * i, 4.5 + 3 * j, 18});
  LocalRefinementReport hole;
  expect_usable(refine_quads_locally(big_box(), big_box_projector(), {}, at(ring, 1.0, 1), &hole));
  EXPECT_EQ(hole.patches, 1);
  EXPECT_EQ(hole.patch_quads, 9);
  EXPECT_EQ(hole.patch_perimeter, 12);
  // Two patches far apart: two chords per level.
  LocalRefinementReport two;
  const QuadSurface fine =
      refine_quads_locally(big_box(), big_box_projector(), {}, at({{9, 9, 18}, {9, 9, 0}}, 1.0, 2), &two);
  EXPECT_EQ(two.patches, 2);
  EXPECT_EQ(expect_usable(fine).chords.size(), check_quad_surface(big_box(), "box").chords.size() + 4);
}

TEST(QuadLocalRefinement, TheRefinedBoxBoundsAValidHexMesh) {
  const QuadSurface fine = refine_quads_locally(box(), box_projector(), {}, at({kTopCentre}, 1.6, 3));
  SheetMeshReport report;
  const HexMesh mesh = mesh_by_cycle_elimination(fine, SheetMeshOptions{}, &report);
  EXPECT_EQ(report.quality.inverted, 0);
  EXPECT_GT(report.quality.scaled_jacobian.min, 0.2);
  EXPECT_EQ(extract_boundary(mesh).surface.quads.size(), fine.quads.size());
}

TEST(QuadLocalRefinement, BadInputIsAnInputErrorNamingThePoint) {
  LocalRefinementOptions far = at({{3, 3, 20}}, 1.6, 2);
  far.point_names = {"--refine-at 3,3,20"};
  try {
    refine_quads_locally(box(), box_projector(), {}, far);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--refine-at 3,3,20 is 14.0 mm from the surface"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(refine_quads_locally(box(), box_projector(), {}, at({kTopCentre}, 0.5, 2)), InputError);
  EXPECT_THROW(refine_quads_locally(box(), box_projector(), {}, at({kTopCentre}, 1.6, 0)), InputError);
  EXPECT_THROW(refine_quads_locally(box(), box_projector(), {}, at({kTopCentre}, 1.6, 7)), InputError);
  try {
    refine_quads_locally(box(), box_projector(), {}, at({kTopCentre}, 30, 1));
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cover the whole surface"), std::string::npos) << e.what();
  }
  // No points: the surface unchanged.
  const QuadSurface same = refine_quads_locally(box(), box_projector(), {}, LocalRefinementOptions{});
  EXPECT_EQ(same.quads, box().quads);
}

// The built-in mandible, generated once for the suite.
const GeneratedMandible& mandible() {
  static const GeneratedMandible m = generate_mandible(MandibleParameters{});
  return m;
}

TEST(QuadLocalRefinement, MandibleBitePointQuadsHalveAndTheHexMeshIsValid) {
  const Vec3 bite = *mandible().landmarks.find("right_first_molar_bite_point");
  MandibleQuadReport plain_report;
  QuadSurfaceReport plain_check;
  const QuadSurface plain = checked_mandible_quads(mandible().surface, &mandible().landmarks, 1300,
                                                   "mandible", "landmarks", &plain_report, &plain_check);
  MandibleSheetOptions options;
  options.refinement = at({bite}, 8.0, 3);
  MandibleSheetReport report;
  const HexMesh mesh = mesh_mandible_by_sheets(mandible().surface, &mandible().landmarks, options, &report);
  const LocalRefinementReport& r = report.refinement;
  ASSERT_EQ(r.sites.size(), 1u);
  EXPECT_EQ(r.quads_added, 3 * r.patch_perimeter);
  EXPECT_EQ(report.quad.quads, plain_report.quads + r.quads_added);
  EXPECT_EQ(report.quad_check.quads, report.quad.quads);
  EXPECT_EQ(report.quad.chords, plain_report.chords + 3);
  EXPECT_TRUE(report.quad_check.usable());
  EXPECT_TRUE(report.quad_check.self_intersecting_chords.empty());
  EXPECT_NEAR(r.sites[0].mean_edge_before_mm, mean_edge_near(plain, r.sites[0].on_surface, 8.0), 1e-12);
  EXPECT_LT(r.sites[0].mean_edge_after_mm, 0.6 * r.sites[0].mean_edge_before_mm);
  // Landmark nodes keep their ids and places; far from the bite point the quad surface is the same.
  EXPECT_EQ(report.quad.landmark_vertices, plain_report.landmark_vertices);
  EXPECT_EQ(report.quad.landmark_nodes, plain_report.landmark_nodes);
  // The hex mesh: valid, within the budget and the degree bound.
  EXPECT_EQ(report.inverted, 0);
  EXPECT_GT(report.sheets.quality.scaled_jacobian.min, 0.2);
  EXPECT_LE(report.sheets.hexes, 3000);
  EXPECT_LE(report.sheets.quality.node_degree.max_edges, 8);
  EXPECT_EQ(static_cast<int>(mesh.hexes.size()), report.sheets.hexes);
  EXPECT_EQ(report.pillow_hexes, report.quad.quads);
  // The ring chords are eliminated first (EliminationOptions::first_rungs), each with the patch as its
  // side; what remains is the unrefined surface, eliminated as without refinement: 3 more steps, whose
  // sheets the construction places inside (internal sheets under a pillowed patch), more hexes than the
  // larger pillow layer alone.
  MandibleSheetReport plain_mesh;
  mesh_mandible_by_sheets(mandible().surface, &mandible().landmarks, MandibleSheetOptions{}, &plain_mesh);
  EXPECT_EQ(report.sheets.eliminations, plain_mesh.sheets.eliminations + 3);
  EXPECT_EQ(report.sheets.external_sheets, plain_mesh.sheets.external_sheets);
  EXPECT_EQ(report.sheets.internal_sheets, plain_mesh.sheets.internal_sheets + 3);
  EXPECT_GT(report.sheets.hexes, plain_mesh.sheets.hexes + r.quads_added);
}

TEST(QuadLocalRefinement, MandibleFarFromTheBitePointIsUnchanged) {
  const Vec3 bite = *mandible().landmarks.find("left_first_molar_bite_point");
  MandibleQuadReport plain_report, fine_report;
  QuadSurfaceReport plain_check, fine_check;
  const QuadSurface plain = checked_mandible_quads(mandible().surface, &mandible().landmarks, 1300,
                                                   "mandible", "landmarks", &plain_report, &plain_check);
  LocalRefinementReport r;
  const QuadSurface fine =
      checked_mandible_quads(mandible().surface, &mandible().landmarks, 1300, "mandible", "landmarks",
                             &fine_report, &fine_check, at({bite}, 8.0, 2), &r);
  ASSERT_GE(fine.vertices.size(), plain.vertices.size());
  int moved_far = 0, moved_near = 0;
  for (std::size_t v = 0; v < plain.vertices.size(); ++v) {
    const bool moved = fine.vertices[v] != plain.vertices[v];
    (distance(plain.vertices[v], r.sites[0].on_surface) > 8.0 + 2 * plain_report.mean_edge_mm ? moved_far
                                                                                              : moved_near) +=
        moved;
  }
  EXPECT_EQ(moved_far, 0);
  EXPECT_GT(moved_near, 0);
  // The landmark nodes (the bite point's among them, inside the patch) keep their ids and places.
  EXPECT_EQ(fine_report.landmark_vertices, plain_report.landmark_vertices);
  for (int v : fine_report.landmark_vertices) EXPECT_EQ(fine.vertices[v], plain.vertices[v]) << v;
  // The quads keep their ids; the patch quads only take copies of their boundary vertices.
  ASSERT_EQ(fine.quads.size(), plain.quads.size() + r.quads_added);
  int same_quads = 0;
  for (std::size_t q = 0; q < plain.quads.size(); ++q) same_quads += fine.quads[q] == plain.quads[q];
  EXPECT_GE(same_quads, static_cast<int>(plain.quads.size()) - r.patch_quads);  // all outside the patch
  EXPECT_LT(same_quads, static_cast<int>(plain.quads.size()));                  // the patch's rim changed
  // A point in the air next to the jaw is refused, naming the option.
  LocalRefinementOptions air = at({{bite[0], bite[1], bite[2] + 20}}, 8.0, 2);
  air.point_names = {"--refine-at left_first_molar_bite_point"};
  try {
    checked_mandible_quads(mandible().surface, &mandible().landmarks, 1300, "mandible", "landmarks",
                           &fine_report, &fine_check, air);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--refine-at left_first_molar_bite_point is"), std::string::npos)
        << e.what();
  }
}

// The CLI: a landmark name that the file lacks, and --refine-at with --method grid, are input errors (exit
// 2) that name the option and what to do; nothing is meshed.
TEST(QuadLocalRefinement, CommandLineRefusesUnknownNamesAndGrid) {
  const std::string jaw = test::shared_data("jaw/jaw_smooth.stl");
  const std::string landmarks = test::shared_data("jaw/landmarks.yaml");
  const std::string out = test::temp_dir() + "/q.obj";
  const test::CommandResult unknown = test::run_hexbite(
      {"quad", "from-mandible", jaw, "--landmarks", landmarks, "-o", out, "--refine-at", "left_molar"});
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_NE(unknown.err.find("--refine-at 'left_molar' is not a point of the landmark file"),
            std::string::npos)
      << unknown.err;
  EXPECT_NE(unknown.err.find("left_first_molar_bite_point"), std::string::npos) << unknown.err;
  const test::CommandResult no_file =
      test::run_hexbite({"quad", "from-mandible", jaw, "-o", out, "--refine-at", "left_molar"});
  EXPECT_EQ(no_file.exit_code, 2);
  EXPECT_NE(no_file.err.find("add --landmarks"), std::string::npos) << no_file.err;
  const test::CommandResult grid = test::run_hexbite(
      {"mesh", jaw, "--method", "grid", "-o", test::temp_dir() + "/m.vtu", "--refine-at", "1,2,3"});
  EXPECT_EQ(grid.exit_code, 2);
  EXPECT_NE(grid.err.find("--refine-at 1,2,3 refines the quad surface"), std::string::npos) << grid.err;
  EXPECT_NE(grid.err.find("--method grid places no quad surface"), std::string::npos) << grid.err;
  const test::CommandResult levels =
      test::run_hexbite({"mesh", jaw, "--method", "sheets", "-o", test::temp_dir() + "/m.vtu", "--refine-at",
                         "1,2,3", "--refine-levels", "9"});
  EXPECT_EQ(levels.exit_code, 2);
  EXPECT_NE(levels.err.find("--refine-levels"), std::string::npos) << levels.err;
}

// mesh.refine_at_bite in a scenario: read with its radius and levels, refused with method: grid and
// without a bite support, at the key's line.
std::string write_scenario(const std::string& name, const std::string& mesh, const std::string& bite) {
  const std::string path = test::temp_dir() + "/" + name;
  test::write_file(path,
                   "format_version: 1\nname: t\ngeometry:\n  mandible: {variant: dentate}\nmesh:\n" + mesh +
                       "supports:\n  - {name: nut, at: right_first_molar_bite_point, radius_mm: 4" + bite +
                       "}\n  - {name: c, at: right_condyle_tmj_point, radius_mm: 6}\n"
                       "activation_pattern: {superficial_masseter: 0.5}\n" +
                       (bite.empty() ? "outputs: {bite_force: false}\n" : ""));
  return path;
}

TEST(QuadLocalRefinement, ScenarioKeyIsReadAndCheckedAtItsLine) {
  const Scenario s = load_scenario(
      write_scenario("refine_ok.yaml",
                     "  method: sheets\n  refine_at_bite: true\n  refine_radius_mm: 6\n  refine_levels: 2\n",
                     ", bite: true"));
  EXPECT_TRUE(s.mesh.refine_at_bite);
  EXPECT_EQ(s.mesh.refine_radius_mm, 6.0);
  EXPECT_EQ(s.mesh.refine_levels, 2);
  const auto message = [](const std::string& path) {
    try {
      load_scenario(path);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string grid =
      message(write_scenario("refine_grid.yaml", "  method: grid\n  refine_at_bite: true\n", ", bite: true"));
  EXPECT_NE(grid.find("refine_grid.yaml:7:"), std::string::npos) << grid;
  EXPECT_NE(grid.find("method: sheets"), std::string::npos) << grid;
  const std::string no_bite =
      message(write_scenario("refine_nobite.yaml", "  method: sheets\n  refine_at_bite: true\n", ""));
  EXPECT_NE(no_bite.find("refine_nobite.yaml:7:"), std::string::npos) << no_bite;
  EXPECT_NE(no_bite.find("bite: true"), std::string::npos) << no_bite;
  const std::string levels = message(
      write_scenario("refine_levels.yaml", "  method: sheets\n  refine_at_bite: true\n  refine_levels: 9\n",
                     ", bite: true"));
  EXPECT_NE(levels.find("refine_levels.yaml:8:"), std::string::npos) << levels;
}

}  // namespace
}  // namespace hexbite
