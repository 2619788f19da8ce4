// Speed of uniform refinement (20 x 20 x 20 block -> 64,000 hexes) and of reordering the refined mesh
// (reverse Cuthill-McKee and breadth-first), separately and as one pipeline.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <random>
#include <vector>

#include "mesher/hex_block.h"
#include "mesher/hex_refine.h"
#include "mesher/hex_reorder.h"

namespace {

using hexbite::HexMesh;

// An n x n x n block of unit cubes with randomly numbered nodes, so that reordering has work to do.
HexMesh shuffled_block(int n) {
  HexMesh mesh = hexbite::make_block_mesh(n, n, n);
  std::vector<int> perm(mesh.vertices.size());
  for (std::size_t i = 0; i < perm.size(); ++i) perm[i] = static_cast<int>(i);
  std::shuffle(perm.begin(), perm.end(), std::mt19937(42));
  HexMesh out = mesh;
  for (std::size_t v = 0; v < perm.size(); ++v) out.vertices[perm[v]] = mesh.vertices[v];
  for (auto& hex : out.hexes)
    for (int& v : hex) v = perm[v];
  return out;
}

const HexMesh& block20() {
  static const HexMesh mesh = shuffled_block(20);
  return mesh;
}

const HexMesh& refined20() {
  static const HexMesh mesh = hexbite::refine_uniform(block20());
  return mesh;
}

void BM_RefineUniform20(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(hexbite::refine_uniform(block20()));
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(refined20().hexes.size()));
}
BENCHMARK(BM_RefineUniform20)->Unit(benchmark::kMillisecond);

void BM_ReverseCuthillMcKee64k(benchmark::State& state) {
  hexbite::AdjacencyProfile before, after;
  for (auto _ : state) {
    const hexbite::ReorderResult r = hexbite::reorder_reverse_cuthill_mckee(refined20());
    before = r.before;
    after = r.after;
  }
  state.counters["bandwidth_before"] = static_cast<double>(before.bandwidth);
  state.counters["bandwidth_after"] = static_cast<double>(after.bandwidth);
  state.counters["profile_before"] = static_cast<double>(before.profile);
  state.counters["profile_after"] = static_cast<double>(after.profile);
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(refined20().hexes.size()));
}
BENCHMARK(BM_ReverseCuthillMcKee64k)->Unit(benchmark::kMillisecond);

void BM_BreadthFirst64k(benchmark::State& state) {
  const int start = hexbite::smallest_x_boundary_hex(refined20());
  hexbite::AdjacencyProfile after;
  for (auto _ : state) after = hexbite::reorder_breadth_first(refined20(), start).after;
  state.counters["bandwidth_after"] = static_cast<double>(after.bandwidth);
  state.counters["profile_after"] = static_cast<double>(after.profile);
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(refined20().hexes.size()));
}
BENCHMARK(BM_BreadthFirst64k)->Unit(benchmark::kMillisecond);

void BM_RefineThenReverseCuthillMcKee20(benchmark::State& state) {
  for (auto _ : state) {
    const HexMesh fine = hexbite::refine_uniform(block20());
    benchmark::DoNotOptimize(hexbite::reorder_reverse_cuthill_mckee(fine));
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(refined20().hexes.size()));
}
BENCHMARK(BM_RefineThenReverseCuthillMcKee20)->Unit(benchmark::kMillisecond);

}  // namespace
