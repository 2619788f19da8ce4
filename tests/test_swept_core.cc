// The core swept across the dental arch (mesher/swept_core.h) on boxes in arch coordinates, and the grid
// mesher with it (GridMeshOptions::swept_core) on the built-in mandible and the real jaw at the paper's
// coarse size, where the overlay grid's means stay near 0.8.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <vector>

#include "common/error.h"
#include "mesher/arch_frame.h"
#include "mesher/grid_mesher.h"
#include "mesher/hex_quality.h"
#include "mesher/mandible_generator.h"
#include "mesher/surface_check.h"
#include "mesher/surface_io.h"
#include "mesher/surface_projector.h"
#include "mesher/swept_core.h"
#include "tests/test_shapes.h"
#include "tests/test_util.h"

namespace hexbite {
namespace {

// A straight 120 x 10 x 30 mm bar (s, t, z) moved to t in [-5, 5]: one column across per cell, both faces
// a third of a cell inside, every hex a box, and the count (hexes + the pillow layer's quads) near the
// target.
TEST(SweptCore, ColumnsSpanTheBarAcrossTheArch) {
  TriSurface bar = test::box(120.0, 10.0, 30.0);
  for (Vec3& v : bar.vertices) v[1] -= 5.0;
  const SurfaceProjector surface(bar);
  const SweptCore core = swept_core(surface, {0, -5, 0}, {120, 5, 30}, 800, 0.0);
  ASSERT_GT(core.columns, 0);
  EXPECT_EQ(long(core.mesh.hexes.size()), core.columns);
  EXPECT_EQ(core.grid[1], 1);
  EXPECT_EQ(core.split_vertices, 0);
  const double inset = std::min(core.cell_size, 10.0) / 3.0;
  for (const Vec3& v : core.mesh.vertices) {
    EXPECT_NEAR(std::fabs(v[1]), 5.0 - inset, 1e-9);
    EXPECT_GE(v[0], -core.cell_size);
    EXPECT_LE(v[0], 120.0 + core.cell_size);
  }
  const QualitySummary q = summarize_quality(core.mesh);
  EXPECT_EQ(q.inverted, 0);
  EXPECT_NEAR(q.scaled_jacobian.min, 1.0, 1e-9);
  const double total = double(core.columns * 3 + core.outline_edges);
  EXPECT_NEAR(total, 800.0, 0.1 * 800.0);
}

// Two bars side by side across the arch, 4 mm apart: each line across crosses the surface four times; the
// core spans both (the outermost crossings) and reports the split lines, which the pillow layer pulls back.
TEST(SweptCore, LinesCrossingTheBoneMoreThanTwiceTakeTheOutermostCrossings) {
  TriSurface two = test::box(60.0, 6.0, 20.0);
  const TriSurface second = test::box(60.0, 6.0, 20.0);
  const int offset = int(two.vertices.size());
  for (Vec3 v : second.vertices) two.vertices.push_back({v[0], v[1] + 10.0, v[2]});
  for (const auto& t : second.triangles)
    two.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  const SurfaceProjector surface(two);
  const SweptCore core = swept_core(surface, {0, 0, 0}, {60, 16, 20}, 400, 0.0, {2, 0.25});
  ASSERT_GT(core.columns, 0);
  EXPECT_GT(core.split_vertices, 0);
  EXPECT_EQ(long(core.mesh.hexes.size()), 2 * core.columns);
  double t_min = 1e9, t_max = -1e9;
  for (const Vec3& v : core.mesh.vertices) t_min = std::min(t_min, v[1]), t_max = std::max(t_max, v[1]);
  EXPECT_LT(t_min, 3.0);
  EXPECT_GT(t_max, 13.0);
  EXPECT_EQ(summarize_quality(core.mesh).inverted, 0);
}

// A box that holds none of the bone (a caller's wrong bounds) gives no column at any size: refused.
TEST(SweptCore, NoColumnAtAnySizeIsRefused) {
  const SurfaceProjector surface(test::box(100.0, 10.0, 40.0));
  const std::string message = test::message_of<InputError>([&] {
    swept_core(surface, {300, 0, 0}, {400, 10, 40}, 500, 0.0);
  });
  EXPECT_NE(message.find("no column of the bone's side view"), std::string::npos) << message;
}

// A lone cell meeting the largest set of columns at a corner goes with its own set; the largest set keeps
// its corner cell (before, the corner rule ran first and dropped the later of the two: the largest set's).
TEST(SweptCore, ALoneCellAtACornerDoesNotTakeTheLargestSetsCell) {
  // 4 x 3 cells, row j = 0 at the bottom: the lone cell (0, 0) meets (1, 1) of the 2 x 2 block at a corner.
  std::vector<char> selected = {1, 0, 0, 0,  //
                                0, 1, 1, 0,  //
                                0, 1, 1, 0};
  EXPECT_EQ(detail::keep_manifold_columns(selected, 4, 3), 1);
  const std::vector<char> kept = {0, 0, 0, 0,  //
                                  0, 1, 1, 0,  //
                                  0, 1, 1, 0};
  EXPECT_EQ(selected, kept);
  // Two cells of the largest set meeting only at a corner: the later one goes.
  std::vector<char> corner = {1, 1, 0,  //
                              1, 0, 1,  //
                              1, 1, 1};
  EXPECT_EQ(detail::keep_manifold_columns(corner, 3, 3), 1);
  // (1, 0) and (2, 1) meet only at a corner, (2, 1) is the later: dropped, the rest stays one set.
  const std::vector<char> corner_kept = {1, 1, 0,  //
                                         1, 0, 0,  //
                                         1, 1, 1};
  EXPECT_EQ(corner, corner_kept);
}

// Fewer than one layer across is a caller's error, refused before any hex (before: vertices of NaN, no
// hexes).
TEST(SweptCore, FewerThanOneLayerIsRefused) {
  const SurfaceProjector surface(test::box(100.0, 10.0, 40.0));
  EXPECT_THROW(swept_core(surface, {0, 0, 0}, {100, 10, 40}, 500, 0.0, {0, 0.25}), std::invalid_argument);
}

// A solid that follows no arch: the arch frame's way out, --grid-frame axes, is refused with --core swept, so
// the message names the grid core (before: "use the axis-aligned grid ... (--grid-frame axes)" alone).
TEST(SweptCore, BoneWithoutAnArchNamesTheGridCore) {
  GridMeshOptions options;
  options.target_hexes = 500;
  options.swept_core = true;
  const std::string message =
      test::message_of<NotAnArchError>([&] { grid_mesh(test::torus(48, 24), options); });
  EXPECT_NE(message.find("arch frame: "), std::string::npos) << message;
  EXPECT_NE(message.find("--core grid --grid-frame axes"), std::string::npos) << message;
  EXPECT_EQ(message.find("use the axis-aligned grid"), std::string::npos) << message;
}

struct Coarse {
  QualitySummary quality;
  GridMeshReport report;
  long hexes = 0;
};

Coarse mesh_swept(const TriSurface& surface, long target_hexes = 2500) {
  GridMeshOptions options;
  options.target_hexes = target_hexes;
  options.swept_core = true;
  Coarse c;
  const HexMesh mesh = grid_mesh(surface, options, &c.report);
  c.quality = summarize_quality(mesh);
  c.hexes = long(mesh.hexes.size());
  return c;
}

// Issue 3's coarse element targets (0 inverted, scaled Jacobian min >= 0.3 and mean >= 0.85, kappa max <= 10
// at about 2,500 hexes), which the overlay grid misses on both bones (means 0.79 / 0.76 along the axes,
// 0.82 / 0.78 along the arch; docs/meshing.md). Measured 2026-11-23 on 9a7ee3d (no Newton sweeps, the tips
// reached down to the floor of 0.35, the interior relaxed around them, whole cells along the arch):
// built-in mandible 2,545 hexes, 0.353 / 0.900, kappa 8.94, Hausdorff 0.53 mean edges, volume -4.04 %; real
// jaw 2,546 hexes, 0.351 / 0.877, kappa 9.50, 0.79 mean edges, -3.55 %. The fidelity is what the swept core
// gives up (1.71 / 1.49 mean edges before the tips were reached; 0.64 along the axes), and neither bone's
// volume is within 3 % without
// --fit-volume.
TEST(SweptCore, MandibleAndJawAt2500MeetTheCoarseElementTargets) {
  const Coarse m = mesh_swept(generate_mandible({}).surface);
  const TriSurface jaw = load_closed_surface(test::shared_data("jaw/jaw_smooth.stl"), 1.0);
  const Coarse j = mesh_swept(jaw);
  for (const Coarse* c : {&m, &j}) {
    EXPECT_TRUE(c->report.swept);
    EXPECT_EQ(c->report.attempts, 2);
    EXPECT_NEAR(double(c->hexes), 2500.0, 250.0);
    EXPECT_EQ(c->quality.inverted, 0);
    EXPECT_GE(c->quality.scaled_jacobian.min, 0.34);
    EXPECT_GE(c->quality.scaled_jacobian.mean, 0.87);
    EXPECT_LE(c->quality.condition.max, 9.6);
    EXPECT_LT(std::fabs(c->report.fidelity.volume_difference), 0.045);
    EXPECT_LT(c->report.fidelity.hausdorff, 1.25 * c->report.fidelity.mean_edge_length);
  }
}

// The built-in mandible's condyle poles at 2,500 hexes: the last tips pass may take a hex down to a scaled
// Jacobian of 0.35 and up to kappa 9.5, and the interior nodes around the moved nodes then relax (the
// boundary held) before the tips go on; the Hausdorff distance 1.07 -> 0.51 mean edges (measured
// 2026-11-23 on b694489; 0.63 with the floor alone, 1.07 with the worst element never worse; 0.53 with whole
// cells along the arch, 9a7ee3d).
TEST(SweptCore, MandibleReachesItsCondylePolesAt2500) {
  const Coarse m = mesh_swept(generate_mandible({}).surface);
  EXPECT_EQ(m.quality.inverted, 0);
  EXPECT_GE(m.quality.scaled_jacobian.min, 0.34);
  EXPECT_LE(m.quality.condition.max, 9.6);
  EXPECT_LT(m.report.fidelity.hausdorff, 0.6 * m.report.fidelity.mean_edge_length);
}

// A corner of the generator's ranges (a 40 mm ramus in a 75 mm arch, 20 mm body): the swept core without
// Newton sweeps keeps inverted pillow hexes at 4,000 hexes on both grids (measured), so the retry meshes
// both grids again with the first version's optimization (Newton sweeps, no tips pass), which is valid.
TEST(SweptCore, InvertedHexesRetryWithNewtonSweeps) {
  MandibleParameters corner;
  corner.arch_width_mm = 75;
  corner.arch_depth_mm = 40;
  corner.body_height_mm = 8;
  corner.body_thickness_mm = 20;
  corner.ramus_height_mm = 40;
  corner.ramus_width_mm = 40;
  corner.gonial_angle_deg = 140;
  const Coarse c = mesh_swept(generate_mandible(corner).surface, 4000);
  EXPECT_EQ(c.report.attempts, 4);
  EXPECT_EQ(c.quality.inverted, 0);
  // Measured 0.064: valid, not good (--core auto takes the grid core there).
  EXPECT_GT(c.quality.scaled_jacobian.min, 0.0);
}

// `hexbite mesh --core swept` meshes along the arch (implied) and says so in its JSON.
TEST(SweptCore, MeshCommandReportsTheSweptCore) {
  const std::string dir = test::temp_dir();
  write_surface(dir + "/m.stl", generate_mandible({}).surface);
  const auto r = test::run_hexbite(
      {"mesh", dir + "/m.stl", "--core", "swept", "--target-hexes", "1500", "-o", dir + "/m.vtu", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["core"], "swept");
  EXPECT_EQ(j["grid_frame"], "arch");
  EXPECT_EQ(j["grid"][1], 1);
  EXPECT_EQ(j["inverted"], 0);
  EXPECT_TRUE(std::ifstream(dir + "/m.vtu").good());
}

}  // namespace
}  // namespace hexbite
