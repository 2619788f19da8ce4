// Assembly plus CG/AMG solve of a Q1 cantilever block with about 200,000 degrees of freedom: the size at
// which issue 5 compares us with CalculiX. One iteration per run (a solve takes seconds); run it alone.
//   build/bench/bench_solver --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include "mesher/hex_block.h"
#include "mesher/hex_mesh.h"
#include "solver/elasticity.h"
#include "solver/mpi_session.h"

namespace {

const hexbite::MpiSession mpi_session;

// An nx x ny x nz block of hexes on [0, 100] x [0, 25] x [0, 25] mm, in VTK node order.

void BM_SolveQ1Cantilever(benchmark::State& state) {
  const int nx = 100, ny = 25, nz = 25;
  const hexbite::HexMesh mesh = hexbite::make_block_mesh(nx, ny, nz, {0.0, 0.0, 0.0}, {100.0, 25.0, 25.0});
  auto id = [&](int i, int j, int k) { return i + (nx + 1) * (j + (ny + 1) * k); };
  hexbite::ElasticityProblem problem;
  problem.mesh = &mesh;
  hexbite::SupportPatch clamp;
  clamp.name = "clamp";
  hexbite::TractionPatch load;
  load.name = "end";
  load.force = {0.0, -500.0, 100.0};
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j) {
      clamp.faces.push_back({id(0, j, k), id(0, j + 1, k), id(0, j + 1, k + 1), id(0, j, k + 1)});
      load.faces.push_back({id(nx, j, k), id(nx, j + 1, k), id(nx, j + 1, k + 1), id(nx, j, k + 1)});
    }
  problem.supports = {clamp};
  problem.loads = {load};

  hexbite::ElasticitySolution solution;
  for (auto _ : state) {
    solution = hexbite::solve_elasticity(problem);
    benchmark::DoNotOptimize(solution.max_displacement);
  }
  state.counters["dofs"] = static_cast<double>(solution.dofs);
  state.counters["cg_iterations"] = solution.iterations;
  state.counters["setup_s"] = solution.setup_seconds;
  state.counters["assembly_s"] = solution.assembly_seconds;
  state.counters["solve_s"] = solution.solve_seconds;
  state.counters["total_s"] = solution.seconds;
  state.counters["equilibrium"] = solution.equilibrium_residual;
}
BENCHMARK(BM_SolveQ1Cantilever)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

}  // namespace
