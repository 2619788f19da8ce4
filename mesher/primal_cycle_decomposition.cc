#include "mesher/primal_cycle_decomposition.h"

#include <algorithm>
#include <tuple>

#include "mesher/elimination_feasibility.h"
#include "mesher/quad_check.h"

namespace hexbite {

namespace {

using Quad = std::array<int, 4>;

// The simple cycles of exactly `length` edges, each once: started at its smallest vertex, second vertex
// smaller than the last.
std::vector<std::vector<int>> cycles_of_length(const std::vector<std::vector<int>>& adjacency, int length) {
  const int n = static_cast<int>(adjacency.size());
  std::vector<std::vector<int>> out;
  std::vector<int> dist(static_cast<std::size_t>(n)), queue;
  std::vector<char> on_path(static_cast<std::size_t>(n), 0);
  std::vector<int> path;
  std::vector<std::size_t> next;  // per path vertex: the next neighbour to try
  for (int s = 0; s < n; ++s) {
    if (adjacency[s].empty()) continue;
    std::fill(dist.begin(), dist.end(), n);
    dist[s] = 0;
    queue.assign(1, s);
    for (std::size_t h = 0; h < queue.size(); ++h)
      for (int u : adjacency[queue[h]])
        if (dist[u] == n) {
          dist[u] = dist[queue[h]] + 1;
          queue.push_back(u);
        }
    path.assign(1, s);
    next.assign(1, 0);
    on_path[s] = 1;
    while (!path.empty()) {
      const int v = path.back();
      const int k = static_cast<int>(path.size());  // vertices on the path
      if (k == length) {
        if (path[1] < v && std::binary_search(adjacency[v].begin(), adjacency[v].end(), s))
          out.push_back(path);
      } else if (next.back() < adjacency[v].size()) {
        const int u = adjacency[v][next.back()++];
        if (u > s && !on_path[u] && dist[u] <= length - k) {
          path.push_back(u);
          next.push_back(0);
          on_path[u] = 1;
        }
        continue;
      }
      on_path[v] = 0;
      path.pop_back();
      next.pop_back();
    }
  }
  return out;
}

// The internal disk `variant` spanning the cycle c, oriented along the cycle; new vertices from `first_new`,
// their positions appended to `positions`. Empty when the variant does not exist for this length.
std::vector<Quad> disk_variant(const std::vector<int>& c, int variant, int first_new,
                               const std::vector<Vec3>& surface_positions, std::vector<Vec3>& positions) {
  const int len = static_cast<int>(c.size()), m = len / 2;
  Vec3 centroid{0.0, 0.0, 0.0};
  for (int v : c)
    for (int d = 0; d < 3; ++d) centroid[d] += surface_positions[v][d] / len;
  auto ladder = [m, len](const std::vector<int>& r, int shift, std::vector<Quad>& quads) {
    auto at = [&](int i) { return r[(i + shift) % len]; };
    for (int i = 0; i + 1 < m; ++i) quads.push_back({at(i), at(i + 1), at(len - 2 - i), at(len - 1 - i)});
  };
  auto fan = [m, len, &positions, &centroid](const std::vector<int>& r, int shift, int centre,
                                             std::vector<Quad>& quads) {
    for (int i = 0; i < m; ++i)
      quads.push_back(
          {r[(2 * i + shift) % len], r[(2 * i + 1 + shift) % len], r[(2 * i + 2 + shift) % len], centre});
    positions.push_back(centroid);
  };
  std::vector<Quad> quads;
  if (variant < m) {
    ladder(c, variant, quads);
  } else if (variant < m + 2) {
    if (m >= 3) fan(c, variant - m, first_new, quads);
  } else if (variant < m + 4) {
    std::vector<int> inner(static_cast<std::size_t>(len));
    for (int i = 0; i < len; ++i) {
      inner[i] = first_new + i;
      Vec3 p = surface_positions[c[i]];
      for (int d = 0; d < 3; ++d) p[d] = 0.5 * (p[d] + centroid[d]);
      positions.push_back(p);
    }
    for (int i = 0; i < len; ++i) quads.push_back({c[i], c[(i + 1) % len], inner[(i + 1) % len], inner[i]});
    if (variant == m + 2)
      ladder(inner, 0, quads);
    else if (m >= 3)
      fan(inner, 0, first_new + len, quads);
    else
      quads.clear();
  }
  if (quads.empty()) positions.clear();
  return quads;
}

// Even, simple, planar, 3-connected, every chord simple: what check_quad_surface() asks, without its
// O(V (V + E)) connectivity test.
bool usable_part(const std::vector<Quad>& quads) {
  if (quads.size() % 2 != 0 || !is_polyhedral_ball(quads)) return false;
  for (const Chord& chord : find_chords(quads, build_quad_edges(quads)))
    if (!chord.simple()) return false;
  return true;
}

}  // namespace

DecompositionSearch search_primal_cycle_splits(const QuadSurface& surface,
                                               const DecompositionOptions& options,
                                               const std::function<bool(const PrimalCycleSplit&)>& accept) {
  DecompositionSearch search;
  const int n = static_cast<int>(surface.vertices.size());
  const QuadEdges qe = build_quad_edges(surface.quads);
  std::vector<std::vector<int>> adjacency(static_cast<std::size_t>(n));
  for (const auto& e : qe.edges) {
    adjacency[e[0]].push_back(e[1]);
    adjacency[e[1]].push_back(e[0]);
  }
  for (auto& a : adjacency) std::sort(a.begin(), a.end());
  const int nq = static_cast<int>(surface.quads.size());
  auto edge_id = [&qe](int a, int b) {
    const std::array<int, 2> key{std::min(a, b), std::max(a, b)};
    return static_cast<int>(std::lower_bound(qe.edges.begin(), qe.edges.end(), key) - qe.edges.begin());
  };
  // The quads on either side of a cycle: side[q] = 0 or 1 (the side of quad 0 is 0); false unless two.
  std::vector<char> cut(qe.edges.size(), 0);
  auto sides_of = [&](const std::vector<int>& cycle, std::vector<int>& side) {
    const int length = static_cast<int>(cycle.size());
    std::fill(cut.begin(), cut.end(), 0);
    for (int i = 0; i < length; ++i) cut[edge_id(cycle[i], cycle[(i + 1) % length])] = 1;
    return quad_components(
               qe, [](int) { return true; }, [&cut](int e) { return !cut[e]; }, side) == 2;
  };
  // (smaller side, cycle): the most balanced first, then the shorter.
  std::vector<std::pair<int, std::vector<int>>> candidates;
  std::vector<int> side;
  for (int length = 4; length <= options.max_cycle_length; length += 2)
    for (std::vector<int>& cycle : cycles_of_length(adjacency, length)) {
      ++search.cycles;
      if (!sides_of(cycle, side)) continue;
      const int first = static_cast<int>(std::count(side.begin(), side.end(), 0));
      if (std::min(first, nq - first) >= 2)
        candidates.emplace_back(std::min(first, nq - first), std::move(cycle));
    }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  {
    for (const auto& [smaller, cycle] : candidates) {
      sides_of(cycle, side);
      const int length = static_cast<int>(cycle.size());
      // Side 0's quad on the edge c_0 c_1 runs along the cycle or against it; part 0's disk runs the other
      // way.
      bool along = false;
      for (const auto& [q, local] : qe.edge_quads[edge_id(cycle[0], cycle[1])])
        if (side[q] == 0) along = surface.quads[q][local] == cycle[0];
      for (int variant = 0; variant < length / 2 + 4; ++variant) {
        PrimalCycleSplit split;
        split.cycle = cycle;
        split.disk = disk_variant(cycle, variant, n, surface.vertices, split.disk_positions);
        if (split.disk.empty()) continue;
        if (along)
          for (Quad& q : split.disk) std::reverse(q.begin(), q.end());
        split.disk_vertices = static_cast<int>(split.disk_positions.size());
        std::array<std::vector<Quad>, 2> part_quads;
        for (int q = 0; q < nq; ++q) part_quads[side[q]].push_back(surface.quads[q]);
        split.side_quads = {static_cast<int>(part_quads[0].size()), static_cast<int>(part_quads[1].size())};
        for (const Quad& q : split.disk) {
          part_quads[0].push_back(q);
          part_quads[1].push_back({q[3], q[2], q[1], q[0]});
        }
        if (!usable_part(part_quads[0]) || !usable_part(part_quads[1])) continue;
        bool usable = true;
        for (int s = 0; s < 2 && usable; ++s) {
          std::vector<int>& ids = split.ids[s];
          for (const Quad& q : part_quads[s]) ids.insert(ids.end(), q.begin(), q.end());
          std::sort(ids.begin(), ids.end());
          ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
          QuadSurface& part = split.parts[s];
          for (int v : ids)
            part.vertices.push_back(v < n ? surface.vertices[v] : split.disk_positions[v - n]);
          for (Quad q : part_quads[s]) {
            for (int& v : q) v = static_cast<int>(std::lower_bound(ids.begin(), ids.end(), v) - ids.begin());
            part.quads.push_back(q);
          }
          usable = check_quad_surface(part, "").usable();
        }
        if (!usable) continue;
        ++search.splits;
        if (accept(split)) {
          search.accepted = true;
          return search;
        }
        if (search.splits >= options.max_splits) return search;
      }
    }
  }
  return search;
}

}  // namespace hexbite
