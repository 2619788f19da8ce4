// Speed of `hexbite surface clean` on the real jaw (41,760 triangles): at the defaults (remove the
// triangles below 5 degrees within 0.1 mm), and reduced to 20,000 triangles. Each run includes the
// final Hausdorff measurement; the counters report the result so the numbers can be quoted together.
#include <benchmark/benchmark.h>

#include <string>

#include "mesher/surface_check.h"
#include "mesher/surface_clean.h"

namespace {

const hexbite::TriSurface& real_jaw() {
  static const hexbite::TriSurface jaw =
      hexbite::load_closed_surface(std::string(HEXBITE_SHARED_DATA) + "/jaw/jaw_smooth.stl", 1.0);
  return jaw;
}

void run(benchmark::State& state, const hexbite::CleanOptions& options) {
  const hexbite::TriSurface& jaw = real_jaw();
  hexbite::CleanReport report;
  for (auto _ : state) {
    hexbite::TriSurface cleaned = hexbite::clean_surface(jaw, options, &report);
    benchmark::DoNotOptimize(cleaned.triangles.data());
  }
  state.counters["triangles_after"] = double(report.triangles_after);
  state.counters["min_angle_after_deg"] = report.min_angle_after_deg;
  state.counters["hausdorff_mm"] = report.hausdorff_mm;
  state.counters["unfixed"] = double(report.unfixed.size());
}

void BM_CleanRealJawDefaults(benchmark::State& state) {
  run(state, hexbite::CleanOptions{});
}
BENCHMARK(BM_CleanRealJawDefaults)->Unit(benchmark::kMillisecond)->MinTime(2.0);

void BM_CleanRealJawTo20000(benchmark::State& state) {
  hexbite::CleanOptions options;
  options.target_triangles = 20000;
  run(state, options);
}
BENCHMARK(BM_CleanRealJawTo20000)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace
