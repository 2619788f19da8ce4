// Meshing the real jaw (../shared/data/jaw/jaw_smooth.stl) and the built-in mandible (generate_mandible with
// its defaults) with the grid + pillow mesher at the paper's coarse size and at a fine size. Counters: hexes,
// inverted hexes, scaled Jacobian min and mean, max condition number (cube = 3), volume difference, Hausdorff
// distance relative to the mean edge length (the target is at most 0.5), optimizer sweeps, the grids tried
// and the seconds of the whole run (every grid).
#include <benchmark/benchmark.h>

#include "mesher/grid_mesher.h"
#include "mesher/mandible_generator.h"
#include "mesher/surface_check.h"

namespace {

void mesh_and_count(benchmark::State& state, const hexbite::TriSurface& surface) {
  hexbite::GridMeshOptions options;
  options.target_hexes = state.range(0);
  hexbite::GridMeshReport report;
  hexbite::HexMesh mesh;
  for (auto _ : state) {
    mesh = hexbite::grid_mesh(surface, options, &report);
    benchmark::DoNotOptimize(mesh);
  }
  const hexbite::QualitySummary& q = report.optimize.phases.back().quality;
  state.counters["hexes"] = double(mesh.hexes.size());
  state.counters["inverted"] = q.inverted;
  state.counters["sj_min"] = q.scaled_jacobian.min;
  state.counters["sj_mean"] = q.scaled_jacobian.mean;
  state.counters["kappa_max"] = q.condition.max;
  state.counters["volume_diff"] = report.fidelity.volume_difference;
  state.counters["hausdorff_per_edge"] = report.fidelity.hausdorff / report.fidelity.mean_edge_length;
  state.counters["sweeps"] = report.optimize.iterations;
  state.counters["grids"] = report.attempts;
  state.counters["seconds"] = report.seconds_total;
}

void BM_GridMeshJaw(benchmark::State& state) {
  static const hexbite::TriSurface jaw =
      hexbite::load_closed_surface(std::string(HEXBITE_SHARED_DATA) + "/jaw/jaw_smooth.stl", 1.0);
  mesh_and_count(state, jaw);
}

void BM_GridMeshBuiltInMandible(benchmark::State& state) {
  static const hexbite::TriSurface mandible = hexbite::generate_mandible({}).surface;
  mesh_and_count(state, mandible);
}

BENCHMARK(BM_GridMeshJaw)->Arg(2500)->Arg(30000)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK(BM_GridMeshBuiltInMandible)->Arg(2500)->Arg(30000)->Iterations(1)->Unit(benchmark::kSecond);

}  // namespace
