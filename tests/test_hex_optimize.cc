// Embedding and optimization (mesher/hex_optimize.h): untangling, condition-number optimization, the
// analytic gradient, and boundary sliding on a surface.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "mesher/hex_block.h"
#include "mesher/hex_boundary.h"
#include "mesher/hex_optimize.h"
#include "mesher/hex_quality.h"
#include "mesher/surface_projector.h"

namespace hexbite {
namespace {

// A structured n x n x n grid of cubes of size h, VTK node order.
HexMesh make_grid(int n, double h) {
  return make_block_mesh(n, n, n, {0, 0, 0}, {n * h, n * h, n * h});
}

bool on_grid_boundary(const Vec3& p, double size) {
  for (double c : p)
    if (std::fabs(c) < 1e-12 || std::fabs(c - size) < 1e-12) return true;
  return false;
}

// The closed box [0, s]^3 as 12 outward triangles.
TriSurface box_surface(double s) {
  TriSurface t;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) t.vertices.push_back({i * s, j * s, k * s});
  // Each face as two triangles, counter-clockwise seen from outside.
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    t.triangles.push_back({q[0], q[1], q[2]});
    t.triangles.push_back({q[0], q[2], q[3]});
  }
  return t;
}

void perturb_interior(HexMesh& m, double size, double amplitude, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-amplitude, amplitude);
  for (Vec3& p : m.vertices)
    if (!on_grid_boundary(p, size))
      for (double& c : p) c += u(rng);
}

TEST(HexOptimize, UntanglingRepairsNodesPushedThroughFaces) {
  HexMesh m = make_grid(5, 1.0);
  // Push three interior nodes through the opposite faces of their hexes.
  auto id = [](int i, int j, int k) { return (k * 6 + j) * 6 + i; };
  m.vertices[id(2, 2, 2)][2] += 1.4;
  m.vertices[id(3, 2, 3)][0] -= 1.3;
  m.vertices[id(1, 3, 2)][1] += 1.5;
  ASSERT_GT(summarize_quality(m).inverted, 0);
  OptimizeOptions options;
  options.barycentric_iterations = 0;  // the repair must come from untangling and optimization
  const OptimizeReport r = optimize_hex_mesh(m, nullptr, {}, options);
  EXPECT_GT(r.phases.front().quality.inverted, 0);
  EXPECT_EQ(r.inverted, 0);
  EXPECT_EQ(summarize_quality(m).inverted, 0);
  EXPECT_GT(summarize_quality(m).scaled_jacobian.min, 0.5);
}

TEST(HexOptimize, OptimizationLowersEnergyAndNeverInverts) {
  HexMesh m = make_grid(6, 1.0);
  perturb_interior(m, 6.0, 0.3, 7);
  ASSERT_EQ(summarize_quality(m).inverted, 0);
  const double before = condition_energy(m, nullptr);
  ASSERT_TRUE(std::isfinite(before));
  std::vector<char> movable(m.vertices.size()), sliding;
  for (std::size_t v = 0; v < m.vertices.size(); ++v) movable[v] = !on_grid_boundary(m.vertices[v], 6.0);
  OptimizeOptions options;
  options.max_iterations = 300;
  optimize_condition(m, movable, sliding, nullptr, options);
  const double after = condition_energy(m, nullptr);
  EXPECT_LT(after, before);
  // The unperturbed grid is the optimum: 216 hexes x 8 corners x 9.
  EXPECT_NEAR(after, 216 * 8 * 9.0, 1.0);
  EXPECT_EQ(summarize_quality(m).inverted, 0);
}

// The per-node Newton sweeps stop on their own criteria (relative movement or energy decrease), well before
// the sweep cap, and reach the optimum of a perturbed grid (the earlier global L-BFGS always ran to its cap).
TEST(HexOptimize, NewtonSweepsConvergeBeforeTheCap) {
  HexMesh m = make_grid(8, 1.0);
  perturb_interior(m, 8.0, 0.2, 13);
  ASSERT_EQ(summarize_quality(m).inverted, 0);
  std::vector<char> movable(m.vertices.size()), sliding;
  for (std::size_t v = 0; v < m.vertices.size(); ++v) movable[v] = !on_grid_boundary(m.vertices[v], 8.0);
  const OptimizeOptions options;
  const int sweeps = optimize_condition(m, movable, sliding, nullptr, options);
  EXPECT_LT(sweeps, options.max_iterations / 4);
  EXPECT_NEAR(condition_energy(m, nullptr), 512 * 8 * 9.0, 1.0);
}

TEST(HexOptimize, GradientMatchesFiniteDifferences) {
  HexMesh m = make_grid(3, 1.0);
  perturb_interior(m, 3.0, 0.25, 11);
  for (Vec3& p : m.vertices) p[1] *= 1.7;  // anisotropic, so no term is at its minimum
  std::vector<Vec3> g;
  condition_energy(m, &g);
  const double eps = 1e-6;
  for (std::size_t v = 0; v < m.vertices.size(); v += 5)
    for (int a = 0; a < 3; ++a) {
      HexMesh p = m, q = m;
      p.vertices[v][a] += eps;
      q.vertices[v][a] -= eps;
      const double fd = (condition_energy(p, nullptr) - condition_energy(q, nullptr)) / (2 * eps);
      EXPECT_NEAR(g[v][a], fd, 1e-5 * std::max(1.0, std::fabs(fd))) << "vertex " << v << " axis " << a;
    }
}

TEST(HexOptimize, BoundaryNodesSlideAndStayOnTheSurface) {
  const double size = 5.0;
  HexMesh m = make_grid(5, 1.0);
  // Move boundary nodes within their faces (away from edges) so that sliding has something to repair.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  for (Vec3& p : m.vertices) {
    int on = 0, axis = -1;
    for (int a = 0; a < 3; ++a)
      if (std::fabs(p[a]) < 1e-12 || std::fabs(p[a] - size) < 1e-12) ++on, axis = a;
    if (on == 1)
      for (int a = 0; a < 3; ++a)
        if (a != axis) p[a] += u(rng);
  }
  const HexMesh start = m;
  const SurfaceProjector box(box_surface(size));
  const OptimizeReport r = optimize_hex_mesh(m, &box, {});
  EXPECT_EQ(r.inverted, 0);
  EXPECT_LT(r.energy_after, r.energy_before);
  double moved = 0;
  const std::vector<char> boundary = boundary_vertex_mask(m);
  for (std::size_t v = 0; v < m.vertices.size(); ++v) {
    if (!boundary[v]) continue;
    EXPECT_LT(box.distance(m.vertices[v]), 1e-6 * size) << "vertex " << v;
    moved = std::max(
        moved, std::hypot(m.vertices[v][0] - start.vertices[v][0], m.vertices[v][1] - start.vertices[v][1],
                          m.vertices[v][2] - start.vertices[v][2]));
  }
  EXPECT_GT(moved, 0.05);  // boundary quality is not frozen
  EXPECT_GT(r.phases.back().quality.scaled_jacobian.min, 0.9);
}

TEST(HexOptimize, FixedNodesDoNotMove) {
  HexMesh m = make_grid(4, 1.0);
  perturb_interior(m, 4.0, 0.3, 5);
  std::vector<char> fixed(m.vertices.size(), 0);
  fixed[31] = fixed[32] = 1;
  const HexMesh start = m;
  optimize_hex_mesh(m, nullptr, fixed);
  EXPECT_EQ(m.vertices[31], start.vertices[31]);
  EXPECT_EQ(m.vertices[32], start.vertices[32]);
}

TEST(HexOptimize, Deterministic) {
  HexMesh a = make_grid(5, 1.0);
  perturb_interior(a, 5.0, 0.35, 9);
  HexMesh b = a;
  optimize_hex_mesh(a, nullptr, {});
  optimize_hex_mesh(b, nullptr, {});
  EXPECT_EQ(a.vertices, b.vertices);
}

}  // namespace
}  // namespace hexbite
