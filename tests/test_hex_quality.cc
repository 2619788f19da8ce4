// Quality metrics against the fixtures of DESIGN.md section 3 and against VTK's vtkMeshQuality (Verdict).
#include <gtest/gtest.h>
#include <vtkHexahedron.h>
#include <vtkMeshQuality.h>
#include <vtkNew.h>
#include <vtkPoints.h>

#include <cmath>
#include <limits>
#include <random>

#include "mesher/hex_block.h"
#include "mesher/hex_quality.h"
#include "mesher/hex_quality_worst.h"

namespace hexbite {
namespace {

using Hex = std::array<Vec3, 8>;

const Hex kCube = {{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}}};

// Verdict's clamp for undefined values (VERDICT_DBL_MAX).
constexpr double kVerdictMax = 1e30;

enum class Measure { kScaledJacobian, kCondition, kOddy, kJacobian };

double verdict(const Hex& x, Measure m) {
  vtkNew<vtkHexahedron> cell;
  for (int k = 0; k < 8; ++k) {
    cell->GetPoints()->SetPoint(k, x[k].data());
    cell->GetPointIds()->SetId(k, k);
  }
  switch (m) {
    case Measure::kScaledJacobian:
      return vtkMeshQuality::HexScaledJacobian(cell);
    case Measure::kCondition:
      return vtkMeshQuality::HexCondition(cell);
    case Measure::kOddy:
      return vtkMeshQuality::HexOddy(cell);
    case Measure::kJacobian:
      return vtkMeshQuality::HexJacobian(cell);
  }
  return 0.0;
}

// The Jacobian matrix Verdict also samples at the element centre: the three principal axes.
CornerQuality centre_quality(const Hex& x) {
  Vec3 a, b, c;
  for (int d = 0; d < 3; ++d) {
    a[d] = (x[1][d] + x[2][d] + x[5][d] + x[6][d]) - (x[0][d] + x[3][d] + x[4][d] + x[7][d]);
    b[d] = (x[2][d] + x[3][d] + x[6][d] + x[7][d]) - (x[0][d] + x[1][d] + x[4][d] + x[5][d]);
    c[d] = (x[4][d] + x[5][d] + x[6][d] + x[7][d]) - (x[0][d] + x[1][d] + x[2][d] + x[3][d]);
  }
  return corner_quality(a, b, c);
}

struct Fixture {
  const char* name;
  Hex hex;
  double scaled_jacobian, condition_verdict, oddy;
};

Hex sheared() {
  Hex x = kCube;
  for (int k = 4; k < 8; ++k) x[k][0] += 0.5;
  return x;
}

Hex box311() {
  Hex x = kCube;
  for (Vec3& p : x) p[0] *= 3.0;
  return x;
}

TEST(HexQuality, DesignFixtures) {
  const Fixture fixtures[] = {{"unit cube", kCube, 1.0, 1.0, 0.0},
                              {"top face shifted 0.5 in x", sheared(), 0.8944, 1.0833, 0.5417},
                              {"3:1:1 box", box311(), 1.0, 1.6063, 9.8611}};
  for (const Fixture& f : fixtures) {
    SCOPED_TRACE(f.name);
    const HexQuality q = hex_quality(f.hex);
    EXPECT_FALSE(q.inverted);
    EXPECT_NEAR(q.scaled_jacobian, f.scaled_jacobian, 1e-4);
    EXPECT_NEAR(q.condition / 3.0, f.condition_verdict, 1e-4);
    EXPECT_NEAR(q.oddy, f.oddy, 1e-4);
    EXPECT_NEAR(verdict(f.hex, Measure::kScaledJacobian), f.scaled_jacobian, 1e-4);
    EXPECT_NEAR(verdict(f.hex, Measure::kCondition), f.condition_verdict, 1e-4);
    EXPECT_NEAR(verdict(f.hex, Measure::kOddy), f.oddy, 1e-4);
  }
  // The cube's corner matrix is the identity: kappa = |I|_F |I|_F = 3 exactly, Oddy exactly 0.
  const HexQuality cube = hex_quality(kCube);
  EXPECT_EQ(cube.condition, 3.0);
  EXPECT_EQ(cube.oddy, 0.0);
  EXPECT_EQ(cube.jacobian, 1.0);
}

// Corner 6 moved to the centre: -0.7698 = -4 / (3 sqrt(3)) is the scaled Jacobian of corner 6 itself
// (det -0.5 over three edges of length sqrt(0.75)), which is also the element minimum. Its three neighbours
// 2, 5, 7 lose a third of their volume (scaled Jacobian 1/sqrt(3)); the centre sample stays positive.
TEST(HexQuality, CornerSixAtCentreIsInverted) {
  Hex x = kCube;
  x[6] = {0.5, 0.5, 0.5};
  const CornerQuality c6 = hex_corner_quality(x.data(), 6);
  EXPECT_NEAR(c6.jacobian, -0.5, 1e-15);
  EXPECT_NEAR(c6.scaled_jacobian, -0.5 / std::pow(0.75, 1.5), 1e-15);
  EXPECT_NEAR(c6.scaled_jacobian, -0.7698, 1e-4);
  EXPECT_EQ(c6.condition, std::numeric_limits<double>::infinity());
  EXPECT_EQ(c6.oddy, std::numeric_limits<double>::infinity());
  for (int k : {2, 5, 7})
    EXPECT_NEAR(hex_corner_quality(x.data(), k).scaled_jacobian, 1.0 / std::sqrt(3.0), 1e-15);
  for (int k : {0, 1, 3, 4}) EXPECT_NEAR(hex_corner_quality(x.data(), k).scaled_jacobian, 1.0, 1e-15);
  EXPECT_GT(centre_quality(x).scaled_jacobian, 0.8);

  const HexQuality q = hex_quality(x);
  EXPECT_TRUE(q.inverted);
  EXPECT_EQ(q.scaled_jacobian, c6.scaled_jacobian);
  EXPECT_NEAR(verdict(x, Measure::kScaledJacobian), -0.7698, 1e-4);
  // Verdict clamps undefined values to VERDICT_DBL_MAX = 1e30 and divides the condition number by 3.
  EXPECT_DOUBLE_EQ(verdict(x, Measure::kCondition), kVerdictMax / 3.0);
  EXPECT_DOUBLE_EQ(verdict(x, Measure::kOddy), kVerdictMax);
}

TEST(HexQuality, DegenerateHexes) {
  Hex collapsed = kCube;  // edge 0-1 collapsed to a point
  collapsed[1] = collapsed[0];
  const HexQuality q = hex_quality(collapsed);
  EXPECT_TRUE(q.inverted);
  EXPECT_EQ(q.jacobian, 0.0);
  EXPECT_EQ(q.scaled_jacobian, 0.0);
  EXPECT_EQ(q.condition, std::numeric_limits<double>::infinity());
  // Verdict returns its clamp value 1e30 for a zero-length edge: the degenerate hex would look better than a
  // cube. We report 0 instead (see docs/quality.md).
  EXPECT_DOUBLE_EQ(verdict(collapsed, Measure::kScaledJacobian), kVerdictMax);

  Hex mirrored = kCube;  // all eight corners negative: Gmsh's mirror-ordered hexes
  for (Vec3& p : mirrored) p[0] = -p[0];
  const HexQuality m = hex_quality(mirrored);
  EXPECT_TRUE(m.inverted);
  EXPECT_DOUBLE_EQ(m.scaled_jacobian, -1.0);
  EXPECT_DOUBLE_EQ(verdict(mirrored, Measure::kScaledJacobian), -1.0);

  Hex with_nan = kCube;
  with_nan[3][1] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(hex_quality(with_nan).inverted);
}

// Random perturbations of the unit cube (and twists of its top face), from mild to strong enough to invert,
// compared hex by hex with Verdict.
TEST(HexQuality, AgreesWithVerdictOnRandomHexes) {
  std::mt19937 rng(20240611);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int valid = 0, inverted = 0, centre_decides = 0;
  const int kHexes = 3000;
  for (int t = 0; t < kHexes; ++t) {
    Hex x = kCube;
    const double twist = (t % 3 == 0) ? 1.2 * unit(rng) : 0.0;
    for (int k = 4; k < 8; ++k) {
      const double px = x[k][0] - 0.5, py = x[k][1] - 0.5;
      x[k][0] = 0.5 + std::cos(twist) * px - std::sin(twist) * py;
      x[k][1] = 0.5 + std::sin(twist) * px + std::cos(twist) * py;
    }
    const double amplitude = 0.6 * (t % 10) / 9.0;
    for (Vec3& p : x)
      for (double& c : p) c += amplitude * unit(rng);
    SCOPED_TRACE("random hex " + std::to_string(t));

    const HexQuality q = hex_quality(x);
    const double v_sj = verdict(x, Measure::kScaledJacobian);
    const double v_cond = verdict(x, Measure::kCondition);
    const double v_oddy = verdict(x, Measure::kOddy);
    // Verdict's Jacobian is the minimum over corners and centre; the corners decide for these hexes too.
    const CornerQuality centre = centre_quality(x);
    if (centre.scaled_jacobian < q.scaled_jacobian || (!q.inverted && centre.condition > q.condition))
      ++centre_decides;

    // The scaled Jacobian agrees on valid and inverted hexes (no zero-length edges occur here).
    EXPECT_NEAR(v_sj, q.scaled_jacobian, 1e-12);
    if (q.inverted) {
      ++inverted;
      // Undefined on inverted hexes: Verdict clamps to 1e30 (condition 1e30 / 3), we report +infinity.
      EXPECT_DOUBLE_EQ(v_cond, kVerdictMax / 3.0);
      EXPECT_DOUBLE_EQ(v_oddy, kVerdictMax);
      EXPECT_EQ(q.condition, std::numeric_limits<double>::infinity());
      EXPECT_EQ(q.oddy, std::numeric_limits<double>::infinity());
    } else {
      ++valid;
      EXPECT_NEAR(v_cond, q.condition / 3.0, 1e-12 * v_cond);
      EXPECT_NEAR(v_oddy, q.oddy, 1e-12 * (1.0 + v_oddy));
      EXPECT_GE(q.condition, 3.0 * (1.0 - 1e-12));
      EXPECT_GE(q.oddy, -1e-12);
      EXPECT_LE(q.scaled_jacobian, 1.0 + 1e-12);
    }
  }
  // Both kinds must be well represented for the comparison to mean something.
  EXPECT_GE(valid, 1000);
  EXPECT_GE(inverted, 200);
  // The centre sample never decided an element value on these hexes (see docs/quality.md).
  EXPECT_EQ(centre_decides, 0);
  std::printf("random hexes: %d valid, %d inverted, centre sample decided %d\n", valid, inverted,
              centre_decides);
}

TEST(HexQuality, CornerConditionSquaredMatchesKernel) {
  Hex x = sheared();
  x[6][2] += 0.3;
  for (int k = 0; k < 8; ++k) {
    Vec3 a, b, c;
    hex_corner_columns(x.data(), k, a, b, c);
    const double kappa = corner_quality(a, b, c).condition;
    EXPECT_NEAR(corner_condition_squared(a, b, c), kappa * kappa, 1e-12 * kappa * kappa);
    EXPECT_DOUBLE_EQ(corner_jacobian(a, b, c), corner_quality(a, b, c).jacobian);
  }
}

TEST(HexQuality, SummaryOfABlock) {
  HexMesh mesh = make_block_mesh(3, 3, 3);
  // Invert hex 0 as in the fixture: its corner 6 (the interior vertex at (1, 1, 1)) moves to its centre.
  mesh.vertices[mesh.hexes[0][6]] = {0.5, 0.5, 0.5};
  const QualitySummary s = summarize_quality(mesh);
  EXPECT_EQ(s.hexes, 27);
  EXPECT_EQ(s.nodes, 64);
  ASSERT_GE(s.inverted, 1);
  EXPECT_EQ(s.inverted, static_cast<int>(s.inverted_hexes.size()));
  EXPECT_EQ(s.inverted_hexes.front(), 0);
  EXPECT_EQ(s.scaled_jacobian.count, 27);
  EXPECT_EQ(s.condition.count, 27 - s.inverted);
  EXPECT_EQ(s.condition_verdict.max, s.condition.max / 3.0);
  EXPECT_TRUE(std::isfinite(s.condition.mean));
  EXPECT_EQ(s.scaled_jacobian.max, 1.0);
  // The 8 interior vertices of a 3x3x3 block are regular: 6 edges and 8 hexes each.
  EXPECT_EQ(s.node_degree.interior_nodes, 8);
  EXPECT_EQ(s.node_degree.max_edges, 6);
  EXPECT_EQ(s.node_degree.max_hexes, 8);
  EXPECT_EQ(s.node_degree.edges.at(6), 8);
  EXPECT_EQ(s.node_degree.hexes.at(8), 8);
  int total = s.scaled_jacobian_histogram.below + s.scaled_jacobian_histogram.above;
  for (int c : s.scaled_jacobian_histogram.counts) total += c;
  EXPECT_EQ(total, 27);
  EXPECT_EQ(s.condition_histogram.above, s.inverted);  // +inf lands above the range
}

// hexbite quality --worst N: lowest scaled Jacobian first, ties by the larger condition number, then index.
TEST(HexQuality, WorstHexesAreOrderedBySJThenCondition) {
  HexMesh mesh = make_block_mesh(3, 3, 3);
  mesh.vertices[mesh.hexes[0][6]] = {0.5, 0.5, 0.5};  // hex 0 inverted (the fixture), its 7 neighbours bent
  const HexQualityField field = compute_hex_quality(mesh);
  const std::vector<WorstHex> worst = worst_hexes(mesh, field, 5);
  ASSERT_EQ(worst.size(), 5u);
  EXPECT_EQ(worst[0].hex, 0);
  EXPECT_NEAR(worst[0].scaled_jacobian, -4.0 / (3.0 * std::sqrt(3.0)), 1e-12);
  EXPECT_TRUE(std::isinf(worst[0].condition));
  for (std::size_t i = 0; i < worst.size(); ++i) {
    const int h = worst[i].hex;
    EXPECT_EQ(worst[i].scaled_jacobian, field.scaled_jacobian[h]);
    EXPECT_EQ(worst[i].condition, field.condition[h]);
    const Vec3 c = hex_centroid(mesh, h);
    for (int a = 0; a < 3; ++a) EXPECT_EQ(worst[i].centroid[a], c[a]);
    if (i > 0) EXPECT_LE(worst[i - 1].scaled_jacobian, worst[i].scaled_jacobian);
  }
  // No hex outside the list is worse than the last one listed.
  for (std::size_t h = 0; h < mesh.hexes.size(); ++h) {
    bool listed = false;
    for (const WorstHex& w : worst) listed |= w.hex == static_cast<int>(h);
    if (!listed) EXPECT_GE(field.scaled_jacobian[h], worst.back().scaled_jacobian) << h;
  }
  EXPECT_TRUE(worst_hexes(mesh, field, 0).empty());
  EXPECT_EQ(worst_hexes(mesh, field, 1000).size(), 27u);

  // Equal scaled Jacobians (boxes are all 1): the more stretched box first, then the lower index.
  HexMesh row = make_block_mesh(3, 1, 1);
  for (Vec3& p : row.vertices)
    if (p[0] > 2.5) p[0] += 2.0;  // hex 2 becomes a 3 x 1 x 1 box
  const std::vector<WorstHex> ties = worst_hexes(row, compute_hex_quality(row), 3);
  ASSERT_EQ(ties.size(), 3u);
  EXPECT_EQ(ties[0].hex, 2);
  EXPECT_GT(ties[0].condition, 3.0 + 1e-9);
  EXPECT_EQ(ties[1].hex, 0);
  EXPECT_EQ(ties[2].hex, 1);
  EXPECT_EQ(ties[0].scaled_jacobian, ties[1].scaled_jacobian);
}

TEST(HexQuality, HistogramEdges) {
  const Histogram h = make_histogram({-1.0, 0.0, 0.5, 1.0, 2.0, std::nan("")}, -1.0, 1.0, 4);
  EXPECT_EQ(h.counts, (std::vector<int>{1, 0, 1, 2}));
  EXPECT_EQ(h.above, 1);
  EXPECT_EQ(h.below, 1);
}

}  // namespace
}  // namespace hexbite
