// Embedding and optimization (mesher/hex_optimize.h): untangling, condition-number optimization, the
// analytic gradient, and boundary sliding on a surface.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
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

// Resting nodes are skipped (OptimizeOptions::reactivate) and woken by a moving neighbour: the sweeps still
// reach the optimum of a perturbed grid, to 1e-4 of the energy.
TEST(HexOptimize, SkippingRestingNodesReachesTheSameOptimum) {
  HexMesh m = make_grid(8, 1.0);
  perturb_interior(m, 8.0, 0.2, 13);
  std::vector<char> movable(m.vertices.size()), sliding;
  for (std::size_t v = 0; v < m.vertices.size(); ++v) movable[v] = !on_grid_boundary(m.vertices[v], 8.0);
  OptimizeOptions options;
  options.reactivate = 0.01;
  const int sweeps = optimize_condition(m, movable, sliding, nullptr, options);
  EXPECT_LT(sweeps, options.max_iterations / 4);
  // Measured 1.44 above the optimum (4e-5 of it) against less than 1 when every node moves every sweep.
  EXPECT_NEAR(condition_energy(m, nullptr), 512 * 8 * 9.0, 4.0);
}

// The worst element measure of a mesh: the smaller of the minimum scaled Jacobian and 3 / the maximum
// condition number (both 1 for cubes).
double worst_measure(const HexMesh& m) {
  const QualitySummary q = summarize_quality(m);
  return std::min(q.scaled_jacobian.min, 3.0 / q.condition.max);
}

// A 5 x 5 x 5 grid with a perturbed interior and a boundary the cubes cannot fit (a shear that grows with
// height and a bulge in x); *movable receives its interior nodes.
HexMesh sheared_grid(std::vector<char>* movable) {
  HexMesh m = make_grid(5, 1.0);
  perturb_interior(m, 5.0, 0.3, 21);
  for (Vec3& p : m.vertices) {
    p[0] += 0.08 * p[2] * p[2];
    p[1] += 0.3 * std::sin(p[0]);
  }
  const std::vector<char> boundary = boundary_vertex_mask(m);
  movable->assign(m.vertices.size(), 0);
  for (std::size_t v = 0; v < m.vertices.size(); ++v) (*movable)[v] = !boundary[v];
  return m;
}

// The worst-element pass raises the worst hex of a condition-optimized mesh whose fixed boundary is sheared
// (so the optimum is not a cube grid), and never lowers it; sliding nodes stay on the surface.
TEST(HexOptimize, WorstElementPassRaisesTheWorstHex) {
  std::vector<char> movable, sliding;
  HexMesh m = sheared_grid(&movable);
  const std::vector<char> boundary = boundary_vertex_mask(m);
  optimize_condition(m, movable, sliding, nullptr, OptimizeOptions{});
  ASSERT_EQ(summarize_quality(m).inverted, 0);
  const double before = worst_measure(m);
  const double sj_mean_before = summarize_quality(m).scaled_jacobian.mean;
  OptimizeOptions options;
  options.worst_element_threshold = 0.9;
  options.scaled_jacobian_sweeps = 3;
  const HexMesh start = m;
  const int sweeps = improve_worst_elements(m, movable, sliding, nullptr, options);
  EXPECT_GT(sweeps, 0);
  const double after = worst_measure(m);
  std::cout << "worst measure " << before << " -> " << after << ", SJ mean " << sj_mean_before << " -> "
            << summarize_quality(m).scaled_jacobian.mean << '\n';
  EXPECT_GT(after, before + 0.01);
  EXPECT_EQ(summarize_quality(m).inverted, 0);
  for (std::size_t v = 0; v < m.vertices.size(); ++v)
    if (!movable[v]) EXPECT_EQ(m.vertices[v], start.vertices[v]);
  // A second round of both stages starts where the first ended and never lowers the worst measure.
  HexMesh twice = start;
  options.worst_element_rounds = 2;
  EXPECT_GT(improve_worst_elements(twice, movable, sliding, nullptr, options), sweeps);
  EXPECT_GE(worst_measure(twice), after);
  EXPECT_EQ(summarize_quality(twice).inverted, 0);
  // Off by default: optimize_hex_mesh without the option leaves the pass out.
  HexMesh again = start;
  EXPECT_EQ(optimize_hex_mesh(again, nullptr, boundary).worst_element_sweeps, 0);
}

// The condition stage (OptimizeOptions::condition_target) after stage 1: on the sheared mesh stage 1 stops
// at a largest kappa of 3.669 (measured), and a target below it lowers that (to 3.62) without lowering the
// worst measure min(scaled Jacobian, 3 / kappa); a target above every hex's kappa leaves the mesh exactly as
// the pass without the stage does (off by default).
TEST(HexOptimize, ConditionStageLowersTheLargestConditionNumber) {
  std::vector<char> movable, sliding;
  HexMesh start = sheared_grid(&movable);
  optimize_condition(start, movable, sliding, nullptr, OptimizeOptions{});
  OptimizeOptions options;
  EXPECT_EQ(options.condition_target, 0.0);
  options.worst_element_threshold = 0.5;
  options.scaled_jacobian_sweeps = 3;
  HexMesh without = start;
  improve_worst_elements(without, movable, sliding, nullptr, options);
  const QualitySummary q0 = summarize_quality(without);

  options.condition_target = 0.99 * q0.condition.max;
  HexMesh with = start;
  improve_worst_elements(with, movable, sliding, nullptr, options);
  const QualitySummary q1 = summarize_quality(with);
  std::cout << "kappa max " << q0.condition.max << " -> " << q1.condition.max << ", worst measure "
            << worst_measure(without) << " -> " << worst_measure(with) << '\n';
  EXPECT_LT(q1.condition.max, q0.condition.max - 0.02);
  EXPECT_GE(worst_measure(with), worst_measure(without));
  EXPECT_EQ(q1.inverted, 0);
  for (std::size_t v = 0; v < with.vertices.size(); ++v)
    if (!movable[v]) EXPECT_EQ(with.vertices[v], start.vertices[v]);

  options.condition_target = 2.0 * q0.condition.max;
  HexMesh above = start;
  improve_worst_elements(above, movable, sliding, nullptr, options);
  for (std::size_t v = 0; v < above.vertices.size(); ++v) EXPECT_EQ(above.vertices[v], without.vertices[v]);
}

// The mean stage raises the mean element scaled Jacobian of the same sheared mesh after the worst-element
// pass, never lowers its smallest scaled Jacobian nor raises its largest condition number, and moves no
// fixed node; optimize_hex_mesh runs it only when asked.
TEST(HexOptimize, MeanStageRaisesTheMeanScaledJacobian) {
  std::vector<char> movable, sliding;
  HexMesh m = sheared_grid(&movable);
  const std::vector<char> boundary = boundary_vertex_mask(m);
  OptimizeOptions options;
  options.worst_element_threshold = 0.5;
  options.scaled_jacobian_sweeps = 3;
  options.mean_jacobian_sweeps = 10;
  optimize_condition(m, movable, sliding, nullptr, options);
  improve_worst_elements(m, movable, sliding, nullptr, options);
  const HexMesh start = m;
  const QualitySummary before = summarize_quality(m);
  const int sweeps = improve_mean_jacobian(m, movable, sliding, nullptr, options);
  const QualitySummary after = summarize_quality(m);
  std::cout << "mean stage: " << sweeps << " sweeps, SJ " << before.scaled_jacobian.min << " / "
            << before.scaled_jacobian.mean << " -> " << after.scaled_jacobian.min << " / "
            << after.scaled_jacobian.mean << ", kappa max " << before.condition.max << " -> "
            << after.condition.max << '\n';
  EXPECT_GT(sweeps, 0);
  EXPECT_GT(after.scaled_jacobian.mean, before.scaled_jacobian.mean + 0.005);
  EXPECT_GE(after.scaled_jacobian.min, before.scaled_jacobian.min);
  EXPECT_LE(after.condition.max, before.condition.max * (1.0 + 1e-12));
  EXPECT_EQ(after.inverted, 0);
  for (std::size_t v = 0; v < m.vertices.size(); ++v)
    if (!movable[v]) EXPECT_EQ(m.vertices[v], start.vertices[v]);
  // Off by default.
  HexMesh again = start;
  EXPECT_EQ(optimize_hex_mesh(again, nullptr, boundary).mean_jacobian_sweeps, 0);
  again = start;
  EXPECT_GT(optimize_hex_mesh(again, nullptr, boundary, options).mean_jacobian_sweeps, 0);
}

// A closest-point query started from a nearby surface point finds the same distance as a plain one.
TEST(HexOptimize, HintedClosestPointMatchesThePlainQuery) {
  const SurfaceProjector box(box_surface(5.0));
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-1.0, 6.0), d(-0.5, 0.5);
  for (int i = 0; i < 200; ++i) {
    const Vec3 q{u(rng), u(rng), u(rng)};
    const SurfacePoint hint = box.closest({q[0] + d(rng), q[1] + d(rng), q[2] + d(rng)});
    const SurfacePoint a = box.closest(q), b = box.closest(q, hint);
    EXPECT_NEAR(a.distance, b.distance, 1e-12) << i;
    EXPECT_NEAR(b.distance, box.distance(q), 1e-12) << i;
  }
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
