// Speed of the sheet mesher (mesher/cycle_elimination.h) at the jaw's size, about 1,300 boundary quads (issue
// 4 target: elimination <= 2 s, the whole command <= 15 s on the 2-core machine), in each elimination order.
// Surfaces: a 15 x 15 x 15 cubed sphere (1,350 quads, 45 chords), a 14 x 14 x 16 block (1,288 quads) and a
// box chain turning twice (a Z of four 7 x 7 x 14 boxes of unit cubes: 1,372 quads). Counters: quads,
// eliminations, k-steps, hexes, and for the full mesh the internal sheets, the seconds per stage, the
// inverted count and the scaled Jacobian min and mean. Run alone: two benchmarks at once slow each other
// 2-3x.
#include <benchmark/benchmark.h>

#include "mesher/cycle_elimination.h"
#include "tests/quad_test_surfaces.h"

namespace {

using hexbite::QuadSurface;

const QuadSurface& surface(int which) {
  static const QuadSurface sphere = hexbite::test::sphere_surface(15, 10.0);
  static const QuadSurface block = hexbite::test::block_surface(14, 14, 16);
  static const QuadSurface chain = hexbite::test::box_chain_surface(7);
  return which == 0 ? sphere : which == 1 ? block : chain;
}

const char* surface_name(int which) {
  return which == 0 ? "sphere" : which == 1 ? "block" : "box_chain";
}

void BM_EliminateChords(benchmark::State& state) {
  const QuadSurface& s = surface(static_cast<int>(state.range(0)));
  hexbite::EliminationOptions options;
  options.order = static_cast<hexbite::EliminationOrder>(state.range(1));
  hexbite::EliminationScheme scheme;
  for (auto _ : state) {
    scheme = hexbite::eliminate_chords(s, options);
    benchmark::DoNotOptimize(scheme);
  }
  state.SetLabel(std::string(surface_name(static_cast<int>(state.range(0)))) + ", " +
                 hexbite::elimination_order_name(options.order));
  int hexes = 1;
  for (const auto& e : scheme.eliminations) hexes += static_cast<int>(e.hexes.size());
  state.counters["quads"] = static_cast<double>(s.quads.size());
  int k_steps = 0;
  for (const auto& e : scheme.eliminations) k_steps += e.chords > 1;
  state.counters["eliminations"] = static_cast<double>(scheme.eliminations.size());
  state.counters["k_steps"] = k_steps;
  state.counters["hexes"] = hexes;
}
BENCHMARK(BM_EliminateChords)
    ->ArgsProduct({{0, 1, 2}, {0, 1, 2}})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);

void BM_SheetMesh(benchmark::State& state) {
  const QuadSurface& s = surface(static_cast<int>(state.range(0)));
  hexbite::SheetMeshOptions options;
  options.elimination.order = static_cast<hexbite::EliminationOrder>(state.range(1));
  hexbite::SheetMeshReport report;
  for (auto _ : state) benchmark::DoNotOptimize(hexbite::mesh_by_cycle_elimination(s, options, &report));
  state.SetLabel(std::string(surface_name(static_cast<int>(state.range(0)))) + ", " +
                 hexbite::elimination_order_name(options.elimination.order));
  state.counters["quads"] = report.quads;
  state.counters["hexes"] = report.hexes;
  state.counters["k_steps"] = report.eliminations_k_step;
  state.counters["internal_sheets"] = report.internal_sheets;
  state.counters["seconds_elimination"] = report.seconds_elimination;
  state.counters["seconds_embedding"] = report.seconds_embedding;
  state.counters["inverted"] = report.quality.inverted;
  state.counters["sj_min"] = report.quality.scaled_jacobian.min;
  state.counters["sj_mean"] = report.quality.scaled_jacobian.mean;
}
BENCHMARK(BM_SheetMesh)->ArgsProduct({{0, 1, 2}, {0, 1, 2}})->Iterations(1)->Unit(benchmark::kSecond);

}  // namespace
