// Serial against distributed: solves one problem distributed over all MPI ranks and again serially on every
// rank (MPI_COMM_SELF), and compares displacements, reactions, stresses and probes. Run it as
//   mpirun -np 2 --allow-run-as-root --oversubscribe test_solver_mpi
// (CTest: solver_mpi_np2) or without mpirun (solver_mpi_serial, where both runs are serial). Exit code 0
// when everything agrees to 1e-8 relative, 1 otherwise; rank 0 prints the figures.
#include <cmath>
#include <cstdio>
#include <string>

#include "solver/elasticity.h"
#include "solver/mpi_session.h"
#include "tests/solver_test_meshes.h"

namespace {

using namespace hexbite;

int failures = 0;

void check(bool ok, const std::string& what, double value, double limit) {
  if (MpiSession::rank() == 0)
    std::printf("%-44s %.3e (limit %.0e) %s\n", what.c_str(), value, limit, ok ? "ok" : "FAILED");
  if (!ok) ++failures;
}

double relative(double a, double b) {
  return std::abs(a - b) / std::max(std::abs(a), 1e-300);
}

void compare(int degree) {
  test::BoxGrid grid = test::box_grid(24, 6, 6, {0.0, 0.0, 0.0}, {60.0, 12.0, 12.0});
  test::distort_interior(grid, 0.15, 21);
  ElasticityProblem problem;
  problem.mesh = &grid.mesh;
  problem.degree = degree;
  problem.solver.relative_tolerance = 1e-12;
  TractionPatch muscle;
  muscle.name = "muscle";
  muscle.faces = grid.side(5, [](int i, int) { return i >= 12 && i < 20; });
  muscle.force = {30.0, -40.0, 200.0};
  problem.loads = {muscle};
  SupportPatch bite, condyle, spring;
  bite.name = "bite";
  bite.is_bite = true;
  bite.faces = grid.side(4, [](int i, int j) { return i >= 20 && j >= 2 && j < 4; });
  condyle.name = "condyle";
  condyle.faces = grid.side(0);
  spring.name = "spring";
  spring.spring_stiffness = 5.0;
  spring.faces = grid.side(2, [](int i, int) { return i < 6; });
  problem.supports = {bite, condyle, spring};
  problem.probes = {{45.0, 6.0, 6.0}, {10.0, 1.0, 11.0}};

  const ElasticitySolution distributed = solve_elasticity(problem);
  problem.distribute_over_all_ranks = false;
  const ElasticitySolution serial = solve_elasticity(problem);

  if (MpiSession::rank() == 0)
    std::printf(
        "Q%d: %lld DoFs; distributed over %d rank(s): %d CG iterations, %.2f s; serial: %d iterations, "
        "%.2f s; bite force %.4f N, equilibrium %.2e\n",
        degree, distributed.dofs, distributed.ranks, distributed.iterations, distributed.seconds,
        serial.iterations, serial.seconds, distributed.bite_force, distributed.equilibrium_residual);
  const std::string q = "Q" + std::to_string(degree) + " ";
  check(distributed.ranks == MpiSession::size(), q + "ranks used == ranks started (difference)",
        std::abs(distributed.ranks - MpiSession::size()), 0.5);
  const double du = test::relative_difference(serial.vertex_displacement, distributed.vertex_displacement);
  check(du < 1e-8, q + "vertex displacements, max relative difference", du, 1e-8);
  double dr = 0.0;
  for (std::size_t r = 0; r < serial.reactions.size(); ++r)
    for (int c = 0; c < 3; ++c)
      dr = std::max(dr, std::abs(serial.reactions[r].force[c] - distributed.reactions[r].force[c]) /
                            std::max(serial.bite_force, 1e-300));
  check(dr < 1e-8, q + "reactions, relative to the bite force", dr, 1e-8);
  check(distributed.equilibrium_residual < 1e-8, q + "equilibrium residual (distributed)",
        distributed.equilibrium_residual, 1e-8);
  const double de = relative(serial.strain_energy, distributed.strain_energy);
  check(de < 1e-8, q + "strain energy", de, 1e-8);
  const double dv = relative(serial.von_mises_max, distributed.von_mises_max);
  check(dv < 1e-8, q + "von Mises maximum", dv, 1e-8);
  double dh = 0.0;
  for (std::size_t h = 0; h < serial.hex_von_mises.size(); ++h)
    dh =
        std::max(dh, std::abs(serial.hex_von_mises[h] - distributed.hex_von_mises[h]) / serial.von_mises_max);
  check(dh < 1e-8, q + "per-hex von Mises, relative to the maximum", dh, 1e-8);
  double dp = 0.0;
  for (std::size_t p = 0; p < serial.probes.size(); ++p) {
    check(distributed.probes[p].found && distributed.probes[p].hex == serial.probes[p].hex,
          q + "probe " + std::to_string(p) + " found in the same hex (difference)",
          std::abs(distributed.probes[p].hex - serial.probes[p].hex), 0.5);
    for (int c = 0; c < 3; ++c)
      dp = std::max(dp, std::abs(serial.probes[p].displacement[c] - distributed.probes[p].displacement[c]) /
                            serial.max_displacement);
  }
  check(dp < 1e-8, q + "probe displacements", dp, 1e-8);
}

}  // namespace

int main(int argc, char** argv) {
  hexbite::MpiSession mpi(argc, argv);
  compare(1);
  compare(2);
  return failures == 0 ? 0 : 1;
}
