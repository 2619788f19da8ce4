// Generation of the built-in mandible at the default parameters (issue 2 asks for at most 2 s):
// sampling the implicit solid on the 1 mm grid, marching cubes, and snapping the landmarks.
#include <benchmark/benchmark.h>

#include "mesher/mandible_generator.h"

namespace {

void BM_GenerateMandible(benchmark::State& state) {
  hexbite::MandibleParameters p;
  p.variant = static_cast<hexbite::MandibleVariant>(state.range(0));
  std::size_t triangles = 0;
  for (auto _ : state) {
    const hexbite::GeneratedMandible g = hexbite::generate_mandible(p);
    triangles = g.surface.triangles.size();
    benchmark::DoNotOptimize(triangles);
  }
  state.counters["triangles"] = static_cast<double>(triangles);
  state.SetLabel(hexbite::variant_name(p.variant));
}

}  // namespace

BENCHMARK(BM_GenerateMandible)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);
