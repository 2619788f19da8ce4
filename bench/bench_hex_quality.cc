// Speed of the quality kernels (per hex, per corner) and of a whole-mesh summary on a 100,000-hex grid.
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "mesher/hex_block.h"
#include "mesher/hex_quality.h"

namespace {

using hexbite::HexMesh;
using hexbite::Vec3;

// An nx x ny x nz grid of unit cubes whose vertices are moved randomly by up to 0.2, so that the kernels see
// general (valid) hexes rather than the special case of a cube.
HexMesh perturbed_grid(int nx, int ny, int nz) {
  HexMesh mesh = hexbite::make_block_mesh(nx, ny, nz);
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  for (Vec3& v : mesh.vertices)
    for (double& c : v) c += u(rng);
  return mesh;
}

// The 8 positions of each hex, gathered once so that the kernel benchmarks measure arithmetic, not gathers.
std::vector<std::array<Vec3, 8>> gathered(const HexMesh& mesh, std::size_t count) {
  std::vector<std::array<Vec3, 8>> out(count);
  for (std::size_t h = 0; h < count; ++h)
    for (int k = 0; k < 8; ++k) out[h][k] = mesh.vertices[mesh.hexes[h][k]];
  return out;
}

const HexMesh& grid_100k() {
  static const HexMesh mesh = perturbed_grid(50, 50, 40);
  return mesh;
}

void BM_HexQualityKernel(benchmark::State& state) {
  const auto hexes = gathered(grid_100k(), 4096);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(hexbite::hex_quality(hexes[i].data()));
    i = (i + 1) & 4095;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_HexQualityKernel);

void BM_CornerConditionSquared(benchmark::State& state) {
  const auto hexes = gathered(grid_100k(), 4096);
  std::size_t i = 0;
  for (auto _ : state) {
    Vec3 a, b, c;
    hexbite::hex_corner_columns(hexes[i >> 3].data(), static_cast<int>(i & 7), a, b, c);
    benchmark::DoNotOptimize(hexbite::corner_condition_squared(a, b, c));
    i = (i + 1) & (4096 * 8 - 1);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_CornerConditionSquared);

void BM_ComputeHexQuality100k(benchmark::State& state) {
  const HexMesh& mesh = grid_100k();
  for (auto _ : state) benchmark::DoNotOptimize(hexbite::compute_hex_quality(mesh));
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(mesh.hexes.size()));
}
BENCHMARK(BM_ComputeHexQuality100k)->Unit(benchmark::kMillisecond);

void BM_SummarizeQuality100k(benchmark::State& state) {
  const HexMesh& mesh = grid_100k();
  for (auto _ : state) benchmark::DoNotOptimize(hexbite::summarize_quality(mesh));
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(mesh.hexes.size()));
}
BENCHMARK(BM_SummarizeQuality100k)->Unit(benchmark::kMillisecond);

}  // namespace
