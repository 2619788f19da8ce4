// Reading and checking the real jaw (41,760 triangles, binary STL): the cost of `hexbite surface
// check` on a typical input, split into the read alone and read + check (repairs included).
#include <benchmark/benchmark.h>

#include "mesher/surface_check.h"
#include "mesher/surface_io.h"

namespace {

const std::string kJaw = std::string(HEXBITE_SHARED_DATA) + "/jaw/jaw_smooth.stl";

void read_jaw(benchmark::State& state) {
  for (auto _ : state) {
    hexbite::TriSurface s = hexbite::read_surface(kJaw);
    benchmark::DoNotOptimize(s.vertices.data());
  }
}
BENCHMARK(read_jaw)->Unit(benchmark::kMillisecond);

void read_and_check_jaw(benchmark::State& state) {
  for (auto _ : state) {
    hexbite::TriSurface s = hexbite::read_surface(kJaw);
    const hexbite::SurfaceReport r = hexbite::check_surface(s, kJaw);
    if (!r.usable()) state.SkipWithError("the jaw did not check clean");
    benchmark::DoNotOptimize(r.volume_mm3);
  }
}
BENCHMARK(read_and_check_jaw)->Unit(benchmark::kMillisecond);

}  // namespace
