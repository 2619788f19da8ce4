// The automatic core choice (mesher/auto_core.h): the swept core for a coarse mesh of a mandible, the grid
// core for a solid without a dental arch, above the size bound, and where the swept mesh misses the bounds
// and the grid core's mesh is better.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>

#include "mesher/auto_core.h"
#include "mesher/hex_quality.h"
#include "mesher/mandible_generator.h"
#include "mesher/surface_io.h"
#include "tests/test_shapes.h"
#include "tests/test_util.h"

namespace hexbite {
namespace {

GridMeshOptions target(long hexes) {
  GridMeshOptions options;
  options.target_hexes = hexes;
  return options;
}

double worst_measure(const HexMesh& mesh) {
  return worst_element_measure(summarize_quality(mesh));
}

TEST(AutoCore, CoarseMandibleKeepsTheSweptCore) {
  GridMeshReport report;
  AutoCoreChoice choice;
  grid_mesh_auto_core(generate_mandible({}).surface, target(1500), &report, &choice);
  EXPECT_TRUE(choice.swept);
  EXPECT_TRUE(report.swept);
  EXPECT_EQ(choice.reason, "");
}

TEST(AutoCore, SolidWithoutAnArchGetsTheGridCore) {
  GridMeshReport report;
  AutoCoreChoice choice;
  const HexMesh mesh = grid_mesh_auto_core(test::torus(48, 24), target(400), &report, &choice);
  EXPECT_FALSE(choice.swept);
  EXPECT_FALSE(report.swept);
  EXPECT_EQ(choice.reason, "the surface follows no dental arch");
  EXPECT_EQ(summarize_quality(mesh).inverted, 0);
}

// A box passes for a straight arch, but one swept hex across it keeps inverted hexes where the box's ends
// meet the top and bottom (measured: 11), which the grid core does not.
TEST(AutoCore, SweptMeshWithInvertedHexesGivesWayToTheGridCore) {
  GridMeshReport report;
  AutoCoreChoice choice;
  const HexMesh mesh = grid_mesh_auto_core(test::box(40, 20, 10), target(400), &report, &choice);
  EXPECT_FALSE(choice.swept);
  EXPECT_NE(choice.reason.find("inverted hexes; the grid core did better"), std::string::npos)
      << choice.reason;
  EXPECT_EQ(summarize_quality(mesh).inverted, 0);
}

TEST(AutoCore, AboveTheSizeBoundTheGridCore) {
  AutoCoreOptions bounds;
  bounds.swept_up_to_hexes = 500;
  GridMeshReport report;
  AutoCoreChoice choice;
  grid_mesh_auto_core(generate_mandible({}).surface, target(600), &report, &choice, bounds);
  EXPECT_FALSE(choice.swept);
  EXPECT_FALSE(report.swept);
  EXPECT_EQ(choice.reason, "600 target hexes: the swept core is for up to 500");
}

// Bounds no mesh meets (scaled Jacobian 0.99) make the choice mesh both cores and keep the one with the
// larger worst-element measure, whichever it is.
TEST(AutoCore, SweptMeshMissingTheBoundsKeepsTheBetterOfBoth) {
  const TriSurface surface = generate_mandible({}).surface;
  AutoCoreOptions bounds;
  bounds.min_scaled_jacobian = 0.99;
  GridMeshReport report;
  AutoCoreChoice choice;
  const HexMesh kept = grid_mesh_auto_core(surface, target(800), &report, &choice, bounds);
  GridMeshOptions swept = target(800);
  swept.swept_core = true;
  const double swept_measure = worst_measure(grid_mesh(surface, swept));
  const double grid_measure = worst_measure(grid_mesh(surface, target(800)));
  EXPECT_EQ(choice.swept, swept_measure >= grid_measure);
  EXPECT_EQ(report.swept, choice.swept);
  EXPECT_DOUBLE_EQ(worst_measure(kept), std::max(swept_measure, grid_measure));
  EXPECT_NE(choice.reason.find("the swept core left a scaled Jacobian of"), std::string::npos)
      << choice.reason;
}

// `hexbite mesh --core auto` names the kept core and the reason in its JSON, and its frame.
TEST(AutoCore, MeshCommandReportsTheKeptCore) {
  const std::string dir = test::temp_dir();
  write_surface(dir + "/torus.stl", test::torus(48, 24));
  const auto r = test::run_hexbite({"mesh", dir + "/torus.stl", "--core", "auto", "--target-hexes", "400",
                                    "-o", dir + "/torus.vtu", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["core"], "grid");
  EXPECT_EQ(j["core_requested"], "auto");
  EXPECT_EQ(j["core_reason"], "the surface follows no dental arch");
  EXPECT_EQ(j["grid_frame"], "axes");
  EXPECT_TRUE(std::ifstream(dir + "/torus.vtu").good());
}

}  // namespace
}  // namespace hexbite
