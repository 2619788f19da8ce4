// Properties every solution must have (DESIGN.md section 6, rung 5, and issue 5's verification list):
// equilibrium of loads and reactions with fixed and spring supports, mirror symmetry, the algebraic
// multigrid's iteration counts under refinement and its agreement with the direct solver, and clear errors
// for malformed problems.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "common/error.h"
#include "solver/elasticity.h"
#include "solver/mpi_session.h"
#include "tests/solver_test_meshes.h"

namespace hexbite {
namespace {

const MpiSession mpi_session;

Vec3 sum_of_reactions(const ElasticitySolution& s) {
  Vec3 total{0.0, 0.0, 0.0};
  for (const SupportReaction& r : s.reactions)
    for (int c = 0; c < 3; ++c) total[c] += r.force[c];
  return total;
}

double norm3(const Vec3& v) {
  return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

// applied + all reactions, summed in the solver's order (the applied force, then the supports in turn): the
// sum is round-off, so another order would change it in the leading digits.
Vec3 applied_plus_reactions(const ElasticitySolution& s) {
  Vec3 total = s.applied_force;
  for (const SupportReaction& r : s.reactions)
    for (int c = 0; c < 3; ++c) total[c] += r.force[c];
  return total;
}

// A distorted 30 x 6 x 6 mm bar with two oblique muscle-like loads, a fully fixed end (the "bite"), a
// patch fixed only in z near the other end, and optionally a spring patch that shares edges with the fixed
// end (the case where spring and constraint act on the same DoFs).
ElasticityProblem bar_problem(const test::BoxGrid& grid, int degree, bool with_spring) {
  ElasticityProblem problem;
  problem.mesh = &grid.mesh;
  problem.degree = degree;
  TractionPatch a;
  a.name = "top";
  a.faces = grid.side(5, [&](int i, int) { return i >= grid.nx / 2; });
  a.force = {40.0, -25.0, 180.0};
  TractionPatch b;
  b.name = "side";
  b.faces = grid.side(3, [&](int i, int k) { return i >= grid.nx / 3 && i < 2 * grid.nx / 3 && k >= 1; });
  b.force = {-10.0, 60.0, 35.0};
  problem.loads = {a, b};

  SupportPatch end;
  end.name = "bite";
  end.is_bite = true;
  end.faces = grid.side(0);
  SupportPatch roller;
  roller.name = "roller";
  roller.components = {false, false, true};
  roller.faces = grid.side(4, [&](int i, int) { return i >= grid.nx - 2; });
  problem.supports = {end, roller};
  if (with_spring) {
    SupportPatch spring;
    spring.name = "spring";
    spring.spring_stiffness = 50.0;
    spring.faces = grid.side(4, [&](int i, int) { return i < grid.nx / 3; });
    problem.supports.push_back(spring);
  }
  return problem;
}

void check_equilibrium(int degree, bool with_spring) {
  test::BoxGrid grid = test::box_grid(10, 3, 3, {0.0, 0.0, 0.0}, {30.0, 6.0, 6.0});
  test::distort_interior(grid, 0.15, 11);
  const ElasticityProblem problem = bar_problem(grid, degree, with_spring);
  const ElasticitySolution s = solve_elasticity(problem);
  const Vec3 reactions = sum_of_reactions(s);
  std::printf(
      "Q%d%s: applied (%.3f, %.3f, %.3f) N, reactions (%.6f, %.6f, %.6f) N, residual %.3e, %d CG its\n",
      degree, with_spring ? " with spring" : "", s.applied_force[0], s.applied_force[1], s.applied_force[2],
      reactions[0], reactions[1], reactions[2], s.equilibrium_residual, s.iterations);
  for (const SupportReaction& r : s.reactions)
    std::printf("  %-7s (%9.4f, %9.4f, %9.4f) N\n", r.name.c_str(), r.force[0], r.force[1], r.force[2]);
  // The applied force is the sum of the patches' forces, whatever their areas.
  EXPECT_NEAR(s.applied_force[0], 30.0, 1e-12);
  EXPECT_NEAR(s.applied_force[1], 35.0, 1e-12);
  EXPECT_NEAR(s.applied_force[2], 215.0, 1e-12);
  EXPECT_LT(s.equilibrium_residual, 1e-8);
  // Issue 5's definition, from the solution's own fields: |applied + all reactions| / |applied|. Here the
  // reactions' magnitudes add up to more than |applied| (the roller pushes against the bite), so a
  // different denominator shows.
  double reaction_magnitudes = 0.0;
  for (const SupportReaction& r : s.reactions) reaction_magnitudes += r.magnitude;
  EXPECT_GT(reaction_magnitudes, 1.01 * norm3(s.applied_force));
  const double defined = norm3(applied_plus_reactions(s)) / norm3(s.applied_force);
  EXPECT_NEAR(s.equilibrium_residual, defined, 1e-12 * defined);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(reactions[c], -s.applied_force[c], 1e-8 * 215.0);
  // The roller acts in z only, and the bite force is the bite support's reaction.
  EXPECT_EQ(s.reactions[1].force[0], 0.0);
  EXPECT_EQ(s.reactions[1].force[1], 0.0);
  EXPECT_GT(std::abs(s.reactions[1].force[2]), 1.0);
  EXPECT_DOUBLE_EQ(s.bite_force, s.reactions[0].magnitude);
  if (with_spring) EXPECT_GT(s.reactions[2].magnitude, 1.0);
}

TEST(SolverEquilibrium, TractionsAndFixedSupportsQ1) {
  check_equilibrium(1, false);
}
TEST(SolverEquilibrium, TractionsAndFixedSupportsQ2) {
  check_equilibrium(2, false);
}
TEST(SolverEquilibrium, SpringsSharingDofsWithFixedSupportQ1) {
  check_equilibrium(1, true);
}
TEST(SolverEquilibrium, SpringsSharingDofsWithFixedSupportQ2) {
  check_equilibrium(2, true);
}

// Loads that cancel: the net applied force is 0, so issue 5's |applied + all reactions| / |applied| has no
// scale. The residual is then relative to the larger of the sum of the reaction magnitudes (here about 0,
// the solver's tolerance) and the largest load, and stays small; relative to the reactions alone it would be
// of order 1 whatever the solve.
TEST(SolverEquilibrium, CancellingLoadsKeepAFiniteScale) {
  const test::BoxGrid grid = test::box_grid(8, 2, 2, {0.0, 0.0, 0.0}, {24.0, 6.0, 6.0});
  ElasticityProblem problem;
  problem.mesh = &grid.mesh;
  TractionPatch pull;
  pull.name = "pull";
  pull.faces = grid.side(1);
  pull.force = {100.0, 0.0, 0.0};
  TractionPatch push;
  push.name = "push";
  push.faces = grid.side(5, [](int i, int) { return i >= 4; });
  push.force = {-100.0, 0.0, 0.0};
  problem.loads = {pull, push};
  SupportPatch end;
  end.name = "end";
  end.faces = grid.side(0);
  problem.supports = {end};
  const ElasticitySolution s = solve_elasticity(problem);
  double reaction_magnitudes = 0.0;
  for (const SupportReaction& r : s.reactions) reaction_magnitudes += r.magnitude;
  const double total = norm3(applied_plus_reactions(s));
  std::printf("cancelling loads: applied |%.3e| N, reactions %.3e N, residual %.3e\n", norm3(s.applied_force),
              reaction_magnitudes, s.equilibrium_residual);
  EXPECT_EQ(norm3(s.applied_force), 0.0);
  const double expected = total / std::max(reaction_magnitudes, 100.0);
  EXPECT_NEAR(s.equilibrium_residual, expected, 1e-12 * expected);
  EXPECT_LT(s.equilibrium_residual, 1e-8);
}

// Springs alone: a bar on an elastic foundation under its whole bottom, pushed down in the middle. The
// spring reaction must equal -k times the integral of u over the patch, which for Q1 on the flat,
// rectangular bottom faces is exactly the face area times the mean of the corner values.
TEST(SolverEquilibrium, SpringReactionIsMinusStiffnessTimesIntegralOfDisplacement) {
  const test::BoxGrid grid = test::box_grid(12, 4, 3, {0.0, 0.0, 0.0}, {24.0, 8.0, 6.0});
  const double k = 20.0;
  ElasticityProblem problem;
  problem.mesh = &grid.mesh;
  SupportPatch foundation;
  foundation.name = "foundation";
  foundation.spring_stiffness = k;
  foundation.faces = grid.side(4);
  TractionPatch press;
  press.name = "press";
  press.faces = grid.side(5, [](int i, int) { return i >= 4 && i < 8; });
  press.force = {5.0, 3.0, -100.0};
  problem.supports = {foundation};
  problem.loads = {press};
  const ElasticitySolution s = solve_elasticity(problem);

  Vec3 expected{0.0, 0.0, 0.0};
  const double face_area = 2.0 * 2.0;
  for (const BoundaryQuad& q : foundation.faces)
    for (int v : q)
      for (int c = 0; c < 3; ++c) expected[c] -= k * face_area / 4.0 * s.vertex_displacement[v][c];
  std::printf(
      "springs only: reaction (%.6f, %.6f, %.6f) N, from -k int u: (%.6f, %.6f, %.6f) N, residual %.3e\n",
      s.reactions[0].force[0], s.reactions[0].force[1], s.reactions[0].force[2], expected[0], expected[1],
      expected[2], s.equilibrium_residual);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(s.reactions[0].force[c], expected[c], 1e-9 * 100.0);
  EXPECT_LT(s.equilibrium_residual, 1e-8);
  EXPECT_NEAR(s.reactions[0].force[2], 100.0, 1e-6);
}

// @sect{Mirror symmetry}
//
// A mesh that is mirror-symmetric about x = 0 (including its random interior distortion), and a problem
// whose loads and supports are all on one side; the mirrored problem (patches mirrored, x components of the
// forces negated) must give the mirrored displacements, reactions and stresses. Mistakes in vertex
// numbering, face matching or orientation handling break the symmetry.
TEST(SolverSymmetry, MirroredProblemGivesMirroredSolution) {
  test::BoxGrid grid = test::box_grid(12, 4, 4, {-30.0, 0.0, 0.0}, {30.0, 8.0, 8.0});
  test::distort_interior(grid, 0.15, 5, true);
  auto mirror_vertex = [&](int v) {
    const int i = v % (grid.nx + 1), rest = v / (grid.nx + 1);
    return grid.nx - i + (grid.nx + 1) * rest;
  };
  auto mirror_faces = [&](std::vector<BoundaryQuad> faces) {
    for (BoundaryQuad& q : faces)
      for (int& v : q) v = mirror_vertex(v);
    return faces;
  };
  for (std::size_t v = 0; v < grid.mesh.vertices.size(); ++v) {
    const Vec3& a = grid.mesh.vertices[v];
    const Vec3& b = grid.mesh.vertices[mirror_vertex(static_cast<int>(v))];
    ASSERT_NEAR(a[0], -b[0], 1e-12);
    ASSERT_EQ(a[1], b[1]);
    ASSERT_EQ(a[2], b[2]);
  }

  ElasticityProblem right;
  right.mesh = &grid.mesh;
  right.solver.relative_tolerance = 1e-12;
  TractionPatch muscle;
  muscle.name = "muscle";
  muscle.faces = grid.side(5, [](int i, int) { return i >= 7 && i < 10; });
  muscle.force = {25.0, -15.0, 120.0};
  SupportPatch bite;
  bite.name = "bite";
  bite.is_bite = true;
  bite.faces = grid.side(4, [](int i, int j) { return i >= 8 && i < 11 && j >= 1 && j < 3; });
  SupportPatch condyle;
  condyle.name = "condyle";
  condyle.faces = grid.side(0);
  SupportPatch spring;
  spring.name = "spring";
  spring.spring_stiffness = 10.0;
  spring.components = {true, false, true};
  spring.faces = grid.side(2, [](int i, int) { return i >= 2 && i < 5; });
  right.loads = {muscle};
  right.supports = {bite, condyle, spring};
  right.probes = {{20.0, 4.0, 4.0}};

  ElasticityProblem left = right;
  left.loads[0].faces = mirror_faces(right.loads[0].faces);
  left.loads[0].force[0] = -right.loads[0].force[0];
  for (SupportPatch& s : left.supports) s.faces = mirror_faces(s.faces);
  left.probes = {{-20.0, 4.0, 4.0}};

  const ElasticitySolution a = solve_elasticity(right), b = solve_elasticity(left);
  std::vector<Vec3> mirrored(a.vertex_displacement.size());
  for (std::size_t v = 0; v < mirrored.size(); ++v) {
    const Vec3& u = b.vertex_displacement[mirror_vertex(static_cast<int>(v))];
    mirrored[v] = {-u[0], u[1], u[2]};
  }
  const double difference = test::relative_difference(a.vertex_displacement, mirrored);
  std::printf("mirror: max displacement %.6e mm, relative difference %.3e, bite force %.6f / %.6f N\n",
              a.max_displacement, difference, a.bite_force, b.bite_force);
  EXPECT_LT(difference, 1e-8);
  EXPECT_GT(a.max_displacement, 1e-4);
  EXPECT_NEAR(a.bite_force, b.bite_force, 1e-8 * a.bite_force);
  for (std::size_t r = 0; r < a.reactions.size(); ++r) {
    EXPECT_NEAR(a.reactions[r].force[0], -b.reactions[r].force[0], 1e-7 * a.bite_force);
    EXPECT_NEAR(a.reactions[r].force[1], b.reactions[r].force[1], 1e-7 * a.bite_force);
    EXPECT_NEAR(a.reactions[r].force[2], b.reactions[r].force[2], 1e-7 * a.bite_force);
  }
  EXPECT_NEAR(a.von_mises_max, b.von_mises_max, 1e-7 * a.von_mises_max);
  EXPECT_NEAR(a.von_mises_max_at[0], -b.von_mises_max_at[0], 1e-9);
  EXPECT_NEAR(a.strain_energy, b.strain_energy, 1e-8 * a.strain_energy);
  ASSERT_TRUE(a.probes[0].found && b.probes[0].found);
  EXPECT_NEAR(a.probes[0].displacement[0], -b.probes[0].displacement[0], 1e-8 * a.max_displacement);
  EXPECT_NEAR(a.probes[0].von_mises, b.probes[0].von_mises, 1e-7 * a.von_mises_max);
}

// @sect{Algebraic multigrid}
//
// With the six rigid-body modes as ML's null space, CG iterations must stay nearly flat when the mesh is
// refined twice (8x the DoFs each time), and AMG and the direct solver must agree to solver tolerance.
ElasticityProblem block_problem(const test::BoxGrid& grid) {
  ElasticityProblem problem;
  problem.mesh = &grid.mesh;
  SupportPatch clamp;
  clamp.name = "clamp";
  clamp.faces = grid.side(0);
  TractionPatch load;
  load.name = "end";
  load.faces = grid.side(1);
  load.force = {20.0, -100.0, 50.0};
  problem.supports = {clamp};
  problem.loads = {load};
  return problem;
}

TEST(SolverAmg, IterationsStayNearlyFlatUnderRefinement) {
  // The coarsest mesh (3,675 DoFs) is already above ML's coarse-grid size, so every level is a real
  // multigrid hierarchy rather than one direct coarse solve.
  std::vector<int> iterations;
  for (int n = 1; n <= 4; n *= 2) {
    test::BoxGrid grid = test::box_grid(24 * n, 6 * n, 6 * n, {0.0, 0.0, 0.0}, {80.0, 20.0, 20.0});
    test::distort_interior(grid, 0.1, 3);
    const ElasticitySolution s = solve_elasticity(block_problem(grid));
    std::printf("AMG: %7lld DoFs, %d CG iterations, %.2f s (setup %.2f, assembly %.2f, solve %.2f)\n", s.dofs,
                s.iterations, s.seconds, s.setup_seconds, s.assembly_seconds, s.solve_seconds);
    iterations.push_back(s.iterations);
  }
  EXPECT_GT(iterations.front(), 3);
  EXPECT_LE(iterations.back(), 1.5 * iterations.front());
}

TEST(SolverAmg, AgreesWithDirectSolver) {
  for (int degree = 1; degree <= 2; ++degree) {
    test::BoxGrid grid = test::box_grid(16, 4, 4, {0.0, 0.0, 0.0}, {80.0, 20.0, 20.0});
    test::distort_interior(grid, 0.15, 9);
    ElasticityProblem problem = block_problem(grid);
    problem.degree = degree;
    problem.solver.relative_tolerance = 1e-12;
    const ElasticitySolution amg = solve_elasticity(problem);
    problem.solver.linear_solver = LinearSolver::kDirect;
    const ElasticitySolution direct = solve_elasticity(problem);
    const double difference = test::relative_difference(direct.vertex_displacement, amg.vertex_displacement);
    std::printf("Q%d: AMG (%d iterations) vs direct: relative difference %.3e, equilibrium %.2e / %.2e\n",
                degree, amg.iterations, difference, amg.equilibrium_residual, direct.equilibrium_residual);
    EXPECT_GT(amg.iterations, 0);
    EXPECT_EQ(direct.iterations, 0);
    EXPECT_LT(difference, 1e-9);
    EXPECT_NEAR(amg.strain_energy, direct.strain_energy, 1e-9 * direct.strain_energy);
    EXPECT_LT(direct.equilibrium_residual, 1e-10);
  }
}

// @sect{Results that must be consistent with each other}
TEST(SolverResults, StrainEnergyEqualsWorkOfLoadsAndStressesAreConsistent) {
  // With homogeneous supports, the strain energy equals half the work of the loads, (1/2) f . u. For one
  // uniform traction on a face of a Q1 mesh of equal rectangles, f . u = F . (mean of the patch's vertex
  // displacements weighted by their share of the face area); on a uniform grid that is an exact sum.
  const test::BoxGrid grid = test::box_grid(20, 2, 2, {0.0, 0.0, 0.0}, {100.0, 10.0, 10.0});
  ElasticityProblem problem = block_problem(grid);
  const ElasticitySolution s = solve_elasticity(problem);
  double work = 0.0;
  const auto& faces = problem.loads[0].faces;
  for (const BoundaryQuad& q : faces)
    for (int v : q)
      for (int c = 0; c < 3; ++c)
        work += problem.loads[0].force[c] / (4.0 * faces.size()) * s.vertex_displacement[v][c];
  std::printf("strain energy %.9f mJ, half the work of the load %.9f mJ\n", s.strain_energy, 0.5 * work);
  EXPECT_NEAR(s.strain_energy, 0.5 * work, 1e-8 * s.strain_energy);

  // Von Mises: the per-hex values lie between zero and the maximum, the 99th percentile too, the principal
  // stresses are ordered, and the vertex field is defined everywhere.
  ASSERT_EQ(s.hex_von_mises.size(), grid.mesh.hexes.size());
  ASSERT_EQ(s.vertex_von_mises.size(), grid.mesh.vertices.size());
  for (std::size_t h = 0; h < s.hex_von_mises.size(); ++h) {
    EXPECT_LE(s.hex_von_mises[h], s.hex_von_mises_max[h] + 1e-12);
    EXPECT_LE(s.hex_von_mises_max[h], s.von_mises_max + 1e-12);
    EXPECT_GE(s.hex_principal_stress[h][0], s.hex_principal_stress[h][1]);
    EXPECT_GE(s.hex_principal_stress[h][1], s.hex_principal_stress[h][2]);
  }
  EXPECT_GT(s.von_mises_p99, 0.0);
  EXPECT_LE(s.von_mises_p99, s.von_mises_max);
  // Bending stress is largest at the clamp.
  EXPECT_LT(s.von_mises_max_at[0], 10.0);
  // The largest displacement is at the loaded end.
  EXPECT_NEAR(s.max_displacement_at[0], 100.0, 1e-12);
  // A probe at a vertex reports that vertex's displacement, one 0.1 mm outside (2 % of its 5 mm hex) that of
  // the nearest point of the hex (the same vertex here); a probe well outside the mesh is not found.
  problem.probes = {{100.0, 5.0, 5.0}, {150.0, 5.0, 5.0}, {100.1, 5.0, 5.0}};
  const ElasticitySolution p = solve_elasticity(problem);
  const Vec3& tip = p.vertex_displacement[grid.vertex(20, 1, 1)];
  ASSERT_TRUE(p.probes[0].found);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(p.probes[0].displacement[c], tip[c], 1e-12);
  EXPECT_FALSE(p.probes[1].found);
  ASSERT_TRUE(p.probes[2].found);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(p.probes[2].displacement[c], tip[c], 1e-12);
}

TEST(SolverInput, MalformedProblemsAreRejectedWithClearMessages) {
  const test::BoxGrid grid = test::box_grid(4, 2, 2, {0.0, 0.0, 0.0}, {4.0, 2.0, 2.0});
  auto message_of = [](const ElasticityProblem& p) -> std::string {
    try {
      solve_elasticity(p);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  ElasticityProblem ok = block_problem(grid);

  ElasticityProblem no_support = ok;
  no_support.supports.clear();
  EXPECT_NE(message_of(no_support).find("no support"), std::string::npos);

  ElasticityProblem interior_face = ok;
  interior_face.loads[0].faces = {
      {grid.vertex(1, 0, 0), grid.vertex(1, 1, 0), grid.vertex(1, 1, 1), grid.vertex(1, 0, 1)}};
  EXPECT_NE(message_of(interior_face).find("is not a boundary face"), std::string::npos);

  ElasticityProblem bad_poisson = ok;
  bad_poisson.material.poisson_ratio = 0.5;
  EXPECT_NE(message_of(bad_poisson).find("Poisson"), std::string::npos);

  ElasticityProblem bad_degree = ok;
  bad_degree.degree = 3;
  EXPECT_NE(message_of(bad_degree).find("degree"), std::string::npos);

  ElasticityProblem bad_materials = ok;
  bad_materials.hex_material.resize(3);
  EXPECT_NE(message_of(bad_materials).find("per-hex materials"), std::string::npos);
}

// Per-hex materials: a bar of two materials in series under tension has the hex stresses of a uniform bar
// (the force is the same) but the softer half stretches more, in proportion to 1/E.
TEST(SolverResults, PerHexMaterialsAreUsedByTheirHexes) {
  const test::BoxGrid grid = test::box_grid(10, 2, 2, {0.0, 0.0, 0.0}, {20.0, 4.0, 4.0});
  ElasticityProblem problem = block_problem(grid);
  problem.material.poisson_ratio = 0.0;
  problem.supports[0].components = {true, false, false};
  // Hold the bar against rigid motion in y and z without restraining its lateral contraction.
  SupportPatch side;
  side.name = "side";
  side.components = {false, true, true};
  side.faces = {grid.side(0)[0]};
  problem.supports.push_back(side);
  problem.loads[0].force = {100.0, 0.0, 0.0};
  problem.hex_material.assign(grid.mesh.hexes.size(), Material{11000.0, 0.0});
  for (std::size_t h = 0; h < grid.mesh.hexes.size(); ++h)
    if (h % 10 >= 5) problem.hex_material[h].youngs_modulus = 2200.0;
  const ElasticitySolution s = solve_elasticity(problem);
  const double stress = 100.0 / 16.0;
  const double u_middle = s.vertex_displacement[grid.vertex(5, 1, 1)][0];
  const double u_end = s.vertex_displacement[grid.vertex(10, 1, 1)][0];
  std::printf("two materials: u(middle) %.6e mm, u(end) %.6e mm\n", u_middle, u_end);
  EXPECT_NEAR(u_middle, stress / 11000.0 * 10.0, 1e-9);
  EXPECT_NEAR(u_end - u_middle, stress / 2200.0 * 10.0, 1e-9);
  for (const Stress6& sigma : s.hex_stress) EXPECT_NEAR(sigma[0], stress, 1e-7);
}

}  // namespace
}  // namespace hexbite
