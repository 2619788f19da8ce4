#include "mesher/elimination_feasibility.h"

#include <algorithm>

#include "mesher/quad_check.h"

namespace hexbite {

namespace {

// True when the quads `a` and `b` share at most one vertex, or exactly two that are consecutive in both
// (the ends of a common edge).
bool meet_properly(const std::array<int, 4>& a, const std::array<int, 4>& b) {
  int shared = 0;
  int ka[2] = {0, 0}, kb[2] = {0, 0};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      if (a[i] == b[j]) {
        if (shared < 2) {
          ka[shared] = i;
          kb[shared] = j;
        }
        ++shared;
      }
  if (shared <= 1) return true;
  if (shared > 2) return false;
  auto consecutive = [](int x, int y) { return (x - y + 4) % 4 == 1 || (y - x + 4) % 4 == 1; };
  return consecutive(ka[0], ka[1]) && consecutive(kb[0], kb[1]);
}

}  // namespace

bool is_polyhedral_ball(const std::vector<std::array<int, 4>>& quads) {
  const int nq = static_cast<int>(quads.size());
  if (nq < 6) return false;
  int max_id = -1;
  for (const auto& q : quads) {
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j)
        if (q[i] == q[j]) return false;
    max_id = std::max(max_id, *std::max_element(q.begin(), q.end()));
  }
  // 1. Closed, oriented, no parallel edges, connected, Euler characteristic 2.
  const QuadEdges qe = build_quad_edges(quads);
  for (const auto& list : qe.edge_quads) {
    if (list.size() != 2) return false;
    if (quads[list[0][0]][list[0][1]] == quads[list[1][0]][list[1][1]]) return false;
  }
  std::vector<int> component;
  const auto every = [](int) { return true; };
  if (quad_components(qe, every, every, component) != 1) return false;
  // Vertex -> quads incidence (compressed rows), also counting the used vertices.
  std::vector<int> start(static_cast<std::size_t>(max_id) + 2, 0);
  for (const auto& q : quads)
    for (int v : q) ++start[v + 1];
  int vertices = 0;
  for (int v = 0; v <= max_id; ++v) {
    if (start[v + 1] > 0) ++vertices;
    start[v + 1] += start[v];
  }
  if (vertices - static_cast<int>(qe.edges.size()) + nq != 2) return false;
  std::vector<int> star(start.back());
  std::vector<int> fill(start.begin(), start.end() - 1);
  for (int q = 0; q < nq; ++q)
    for (int v : quads[q]) star[fill[v]++] = q;
  // 2. Any two quads at a vertex meet in that vertex or in one common edge.
  for (int v = 0; v <= max_id; ++v)
    for (int i = start[v]; i < start[v + 1]; ++i)
      for (int j = i + 1; j < start[v + 1]; ++j)
        if (!meet_properly(quads[star[i]], quads[star[j]])) return false;
  return true;
}

}  // namespace hexbite
