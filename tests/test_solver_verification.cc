// Verification of the elasticity solver against exact answers (DESIGN.md section 6, rungs 2 to 4): the patch
// test on distorted hexes, manufactured solutions converging at the theoretical rates, and a cantilever
// against Timoshenko beam theory.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "solver/elasticity.h"
#include "solver/mpi_session.h"
#include "tests/solver_test_meshes.h"

namespace hexbite {
namespace {

const MpiSession mpi_session;

constexpr double kPi = 3.14159265358979323846;

// @sect{Patch test}
//
// A linear displacement field u = A x + b prescribed on the whole boundary of a block whose interior
// vertices were moved at random must be reproduced exactly (to round-off) inside, and give the same constant
// stress C : sym(A) in every hex. Element formulations that are not consistent (wrong vertex numbering,
// a wrong Jacobian on distorted cells, wrong Lamé constants) fail it.
void patch_test(int degree) {
  test::BoxGrid grid = test::box_grid(4, 4, 4, {0.0, 0.0, 0.0}, {10.0, 10.0, 10.0});
  test::distort_interior(grid, 0.15, 7);
  const double A[3][3] = {{1.0e-3, 2.0e-4, -3.0e-4}, {-5.0e-4, 2.0e-3, 4.0e-4}, {6.0e-4, -1.0e-4, -1.5e-3}};
  const Vec3 b{0.01, -0.02, 0.03};
  auto linear = [&](const Vec3& x) {
    Vec3 u = b;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) u[i] += A[i][j] * x[j];
    return u;
  };

  ElasticityProblem problem;
  problem.mesh = &grid.mesh;
  problem.degree = degree;
  problem.solver.linear_solver = LinearSolver::kDirect;
  SupportPatch boundary;
  boundary.name = "boundary";
  boundary.faces = grid.all_sides();
  boundary.displacement = linear;
  problem.supports.push_back(boundary);
  const ElasticitySolution solution = solve_elasticity(problem);

  double error = 0.0, scale = 0.0;
  int interior = 0;
  for (int k = 1; k < grid.nz; ++k)
    for (int j = 1; j < grid.ny; ++j)
      for (int i = 1; i < grid.nx; ++i) {
        const int v = grid.vertex(i, j, k);
        const Vec3 exact = linear(grid.mesh.vertices[v]);
        const Vec3& u = solution.vertex_displacement[v];
        error = std::max(error, test::norm({u[0] - exact[0], u[1] - exact[1], u[2] - exact[2]}));
        scale = std::max(scale, test::norm(exact));
        ++interior;
      }
  std::printf("patch test Q%d: %d interior vertices, max relative error %.3e\n", degree, interior,
              error / scale);
  EXPECT_EQ(interior, 27);
  EXPECT_LT(error / scale, 1e-10);

  // The exact stress: eps = sym(A), sigma = lambda tr(eps) I + 2 mu eps.
  const double E = problem.material.youngs_modulus, nu = problem.material.poisson_ratio;
  const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
  const double tr = A[0][0] + A[1][1] + A[2][2];
  const Stress6 exact{lambda * tr + 2 * mu * A[0][0], lambda * tr + 2 * mu * A[1][1],
                      lambda * tr + 2 * mu * A[2][2], mu * (A[0][1] + A[1][0]),
                      mu * (A[1][2] + A[2][1]),       mu * (A[0][2] + A[2][0])};
  double stress_error = 0.0;
  for (const Stress6& s : solution.hex_stress)
    for (int c = 0; c < 6; ++c) stress_error = std::max(stress_error, std::abs(s[c] - exact[c]));
  std::printf("patch test Q%d: max stress error %.3e MPa (stress xx %.4f MPa)\n", degree, stress_error,
              exact[0]);
  EXPECT_LT(stress_error, 1e-8 * std::abs(exact[0]));
}

TEST(SolverPatchTest, LinearFieldIsExactOnDistortedHexesQ1) {
  patch_test(1);
}
TEST(SolverPatchTest, LinearFieldIsExactOnDistortedHexesQ2) {
  patch_test(2);
}

// @sect{Manufactured solution}
//
// u = sum of plane waves A sin(k . x + phi). For each wave, div sigma = -[mu |k|^2 A + (lambda + mu)(A . k)
// k] sin(k . x + phi), so the body force b = -div sigma is known in closed form, and so is grad u. The exact
// u is prescribed on the whole boundary of the unit cube; on meshes of 2, 4, 8 and 16 cells per side the L2
// error must fall like h^(p+1) and the H1-seminorm error like h^p.
struct Wave {
  Vec3 amplitude, k;
  double phase;
};
const Wave kWaves[2] = {{{1.0e-3, 5.0e-4, -3.0e-4}, {1.0 * kPi, 0.5 * kPi, 0.75 * kPi}, 0.3},
                        {{-4.0e-4, 8.0e-4, 6.0e-4}, {-0.5 * kPi, 1.0 * kPi, 0.5 * kPi}, 1.1}};

void manufactured_rates(int degree) {
  const Material material;
  const double nu = material.poisson_ratio, E = material.youngs_modulus;
  const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
  auto exact = [](const Vec3& x) {
    Vec3 u{0.0, 0.0, 0.0};
    for (const Wave& w : kWaves) {
      const double s = std::sin(w.k[0] * x[0] + w.k[1] * x[1] + w.k[2] * x[2] + w.phase);
      for (int i = 0; i < 3; ++i) u[i] += w.amplitude[i] * s;
    }
    return u;
  };
  auto gradient = [](const Vec3& x) {
    std::array<Vec3, 3> g{};
    for (const Wave& w : kWaves) {
      const double c = std::cos(w.k[0] * x[0] + w.k[1] * x[1] + w.k[2] * x[2] + w.phase);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) g[i][j] += w.amplitude[i] * w.k[j] * c;
    }
    return g;
  };
  auto body_force = [=](const Vec3& x) {
    Vec3 b{0.0, 0.0, 0.0};
    for (const Wave& w : kWaves) {
      const double s = std::sin(w.k[0] * x[0] + w.k[1] * x[1] + w.k[2] * x[2] + w.phase);
      const double k2 = w.k[0] * w.k[0] + w.k[1] * w.k[1] + w.k[2] * w.k[2];
      const double ak = w.amplitude[0] * w.k[0] + w.amplitude[1] * w.k[1] + w.amplitude[2] * w.k[2];
      for (int i = 0; i < 3; ++i) b[i] += (mu * k2 * w.amplitude[i] + (lambda + mu) * ak * w.k[i]) * s;
    }
    return b;
  };

  std::vector<double> l2, h1;
  for (int n = 2; n <= 16; n *= 2) {
    const test::BoxGrid grid = test::box_grid(n, n, n, {0.0, 0.0, 0.0}, {1.0, 1.0, 1.0});
    ElasticityProblem problem;
    problem.mesh = &grid.mesh;
    problem.degree = degree;
    problem.solver.relative_tolerance = 1e-12;
    SupportPatch boundary;
    boundary.name = "boundary";
    boundary.faces = grid.all_sides();
    boundary.displacement = exact;
    problem.supports.push_back(boundary);
    problem.body_force = body_force;
    problem.reference_displacement = exact;
    problem.reference_gradient = gradient;
    const ElasticitySolution solution = solve_elasticity(problem);
    l2.push_back(solution.l2_error);
    h1.push_back(solution.h1_seminorm_error);
    std::printf("Q%d n=%2d dofs=%6lld  L2 error %.4e  H1 error %.4e  CG iterations %d\n", degree, n,
                solution.dofs, solution.l2_error, solution.h1_seminorm_error, solution.iterations);
  }
  for (std::size_t i = 1; i < l2.size(); ++i)
    std::printf("Q%d rates %d->%d: L2 %.3f  H1 %.3f\n", degree, 1 << i, 2 << i, std::log2(l2[i - 1] / l2[i]),
                std::log2(h1[i - 1] / h1[i]));
  // The asymptotic rates, from the two finest refinements (the coarsest meshes resolve the waves poorly).
  for (std::size_t i = l2.size() - 2; i < l2.size(); ++i) {
    EXPECT_NEAR(std::log2(l2[i - 1] / l2[i]), degree + 1.0, 0.15) << "L2 rate at refinement " << i;
    EXPECT_NEAR(std::log2(h1[i - 1] / h1[i]), degree, 0.15) << "H1 rate at refinement " << i;
  }
}

TEST(SolverManufacturedSolution, Q1ConvergesAtRatesTwoAndOne) {
  manufactured_rates(1);
}
TEST(SolverManufacturedSolution, Q2ConvergesAtRatesThreeAndTwo) {
  manufactured_rates(2);
}

// @sect{Cantilever}
//
// A 100 x 10 x 10 mm bar clamped at x = 0 carries a shear force P = 100 N in -y on its end face. Timoshenko
// beam theory: tip deflection P L^3 / (3 E I) + P L / (kappa G A), with Cowper's shear coefficient
// kappa = 10 (1 + nu) / (12 + 11 nu) for a rectangle. We measure the mean y displacement of the end face's
// vertices. Q2 must agree within 2%; Q1, which locks in bending on coarse meshes, must approach it.
double cantilever_tip_deflection(int degree, int nx, int nyz) {
  const test::BoxGrid grid = test::box_grid(nx, nyz, nyz, {0.0, 0.0, 0.0}, {100.0, 10.0, 10.0});
  ElasticityProblem problem;
  problem.mesh = &grid.mesh;
  problem.degree = degree;
  SupportPatch clamp;
  clamp.name = "clamp";
  clamp.faces = grid.side(0);
  problem.supports.push_back(clamp);
  TractionPatch load;
  load.name = "end";
  load.faces = grid.side(1);
  load.force = {0.0, -100.0, 0.0};
  problem.loads.push_back(load);
  const ElasticitySolution solution = solve_elasticity(problem);
  EXPECT_LT(solution.equilibrium_residual, 1e-8);

  double sum = 0.0;
  int count = 0;
  for (int k = 0; k <= grid.nz; ++k)
    for (int j = 0; j <= grid.ny; ++j) {
      sum += solution.vertex_displacement[grid.vertex(grid.nx, j, k)][1];
      ++count;
    }
  return -sum / count;
}

double timoshenko_tip_deflection() {
  const Material m;
  const double P = 100.0, L = 100.0, b = 10.0, h = 10.0;
  const double I = b * h * h * h / 12.0, A = b * h, G = m.youngs_modulus / (2.0 * (1.0 + m.poisson_ratio));
  const double kappa = 10.0 * (1.0 + m.poisson_ratio) / (12.0 + 11.0 * m.poisson_ratio);
  return P * L * L * L / (3.0 * m.youngs_modulus * I) + P * L / (kappa * G * A);
}

TEST(SolverCantilever, Q2MatchesTimoshenkoWithinTwoPercent) {
  const double reference = timoshenko_tip_deflection();
  const double q2 = cantilever_tip_deflection(2, 40, 4);
  std::printf("cantilever Q2 40x4x4: tip %.6f mm, Timoshenko %.6f mm, error %+.3f%%\n", q2, reference,
              100.0 * (q2 - reference) / reference);
  EXPECT_NEAR(q2, reference, 0.02 * reference);
}

TEST(SolverCantilever, Q1ConvergesTowardTimoshenko) {
  const double reference = timoshenko_tip_deflection();
  double previous_error = 1.0;
  for (int n = 1; n <= 4; n *= 2) {
    const double q1 = cantilever_tip_deflection(1, 20 * n, 2 * n);
    const double error = std::abs(q1 - reference) / reference;
    std::printf("cantilever Q1 %dx%dx%d: tip %.6f mm, Timoshenko %.6f mm, error %+.3f%%\n", 20 * n, 2 * n,
                2 * n, q1, reference, 100.0 * (q1 - reference) / reference);
    // Locking makes Q1 too stiff: the deflection stays below the beam value and the gap closes.
    EXPECT_LT(q1, reference);
    EXPECT_LT(error, 0.7 * previous_error);
    previous_error = error;
  }
  EXPECT_LT(previous_error, 0.02);
}

}  // namespace
}  // namespace hexbite
