// The arch frame (mesher/arch_frame.h, `--grid-frame arch`) on what users feed it: every mandible the
// generator makes within its ranges follows the arch (the narrow, the deep and the steep-angled ones too),
// and the real jaw turned about z either meshes valid along the arch or is refused with a clear reason,
// never meshed inverted.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "common/error.h"
#include "mesher/arch_frame.h"
#include "mesher/grid_mesher.h"
#include "mesher/hex_quality.h"
#include "mesher/mandible_generator.h"
#include "mesher/surface_check.h"
#include "tests/test_util.h"

namespace hexbite {
namespace {

// The surface turned by `degrees` about the vertical axis through the origin.
TriSurface turned(TriSurface surface, double degrees) {
  const double c = std::cos(degrees * M_PI / 180), s = std::sin(degrees * M_PI / 180);
  for (Vec3& p : surface.vertices) p = {c * p[0] - s * p[1], s * p[0] + c * p[1], p[2]};
  return surface;
}

// Each variant at its defaults, and the corners of the generator's ranges that bend the arch most: a
// narrow arch, a narrow and deep one, a wide and shallow one, the gonial angle at both ends. The first arch
// frame (commit 8eda747) refused the narrow, the deep and the 105-degree ones ("lies too far across the
// arch's curve"), and with them a scenario's own built-in mandible at arch_width_mm: 75.
TEST(ArchFrameInputs, EveryGeneratorMandibleFollowsTheArch) {
  std::vector<std::pair<std::string, MandibleParameters>> cases;
  for (const MandibleVariant v :
       {MandibleVariant::kDentate, MandibleVariant::kEdentulous, MandibleVariant::kAtrophic}) {
    MandibleParameters p;
    p.variant = v;
    cases.emplace_back(variant_name(v), p);
  }
  MandibleParameters p;
  p.arch_width_mm = 75;
  cases.emplace_back("arch width 75", p);
  p.arch_depth_mm = 75;
  cases.emplace_back("arch width 75, depth 75", p);
  p = {};
  p.arch_width_mm = 120;
  p.arch_depth_mm = 40;
  cases.emplace_back("arch width 120, depth 40", p);
  p = {};
  p.gonial_angle_deg = 105;
  cases.emplace_back("gonial angle 105", p);
  p.gonial_angle_deg = 140;
  cases.emplace_back("gonial angle 140", p);

  for (const auto& [name, parameters] : cases) {
    SCOPED_TRACE(name);
    const GeneratedMandible g = generate_mandible(parameters);
    try {
      const ArchFrame frame(g.surface);
      EXPECT_GT(frame.length(), 100.0);
    } catch (const InputError& e) {
      ADD_FAILURE() << e.what();
      continue;
    }
    // The one that bends most (the narrow, deep arch) meshes valid along the arch.
    if (name == "arch width 75, depth 75") {
      GridMeshOptions options;
      options.target_hexes = 2500;
      options.arch_frame = true;
      const QualitySummary q = summarize_quality(grid_mesh(g.surface, options));
      EXPECT_EQ(q.inverted, 0);
      EXPECT_GE(q.scaled_jacobian.min, 0.2);
      EXPECT_GE(q.scaled_jacobian.mean, 0.78);
    }
  }
}

// The frame assumes the mandible frame. The real jaw turned 20 degrees about z either meshes valid along
// the arch or is refused naming the arch frame and the way out (--grid-frame axes); turned 180 degrees (the
// chin towards +y) it is refused.
TEST(ArchFrameInputs, ATurnedJawMeshesValidOrIsRefusedClearly) {
  const TriSurface jaw = load_closed_surface(test::shared_data("jaw/jaw_smooth.stl"), 1.0);
  GridMeshOptions options;
  options.target_hexes = 1500;
  options.arch_frame = true;
  try {
    const QualitySummary q = summarize_quality(grid_mesh(turned(jaw, 20), options));
    EXPECT_EQ(q.inverted, 0);
    EXPECT_GE(q.scaled_jacobian.min, 0.1);
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("arch frame: "), std::string::npos) << message;
    EXPECT_NE(message.find("--grid-frame axes"), std::string::npos) << message;
  }
  const std::string message = test::message_of<InputError>([&] { ArchFrame frame(turned(jaw, 180)); });
  EXPECT_NE(message.find("arch frame: "), std::string::npos) << message;
  EXPECT_NE(message.find("mandible frame"), std::string::npos) << message;
}

}  // namespace
}  // namespace hexbite
