#include "mesher/quad_check.h"

#include <algorithm>
#include <boost/graph/adjacency_list.hpp>
#include <boost/graph/boyer_myrvold_planar_test.hpp>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <stdexcept>

#include "mesher/vec3.h"

namespace hexbite {

namespace {

// Union-find with path halving; small and allocation-free after construction.
class DisjointSets {
 public:
  explicit DisjointSets(int n) : parent_(static_cast<std::size_t>(n)) {
    std::iota(parent_.begin(), parent_.end(), 0);
  }
  int find(int x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }
  void unite(int a, int b) {
    a = find(a);
    b = find(b);
    if (a != b) parent_[std::max(a, b)] = std::min(a, b);
  }

 private:
  std::vector<int> parent_;
};

// Compressed adjacency of the non-isolated vertices.
struct Csr {
  std::vector<int> start;
  std::vector<int> adj;
  std::vector<int> active;  // vertices with at least one edge, ascending
};

Csr make_csr(int n, const std::vector<std::array<int, 2>>& edges) {
  Csr g;
  g.start.assign(static_cast<std::size_t>(n) + 1, 0);
  for (const auto& e : edges) {
    ++g.start[e[0] + 1];
    ++g.start[e[1] + 1];
  }
  for (int v = 0; v < n; ++v) g.start[v + 1] += g.start[v];
  g.adj.resize(g.start[n]);
  std::vector<int> fill(g.start.begin(), g.start.end() - 1);
  for (const auto& e : edges) {
    g.adj[fill[e[0]]++] = e[1];
    g.adj[fill[e[1]]++] = e[0];
  }
  for (int v = 0; v < n; ++v)
    if (g.start[v + 1] > g.start[v]) g.active.push_back(v);
  return g;
}

// -1 when the active vertices other than `removed` form a connected graph without articulation points;
// else an articulation point of that graph (removing it too disconnects the graph), or -2 when the graph
// without `removed` is not connected. Iterative Tarjan low-point search; the work arrays are passed in so
// that the n calls of the 3-connectivity test do not allocate.
int articulation_without(const Csr& g, int removed, std::vector<int>& disc, std::vector<int>& low,
                         std::vector<std::array<int, 2>>& stack) {
  std::fill(disc.begin(), disc.end(), -1);
  int root = -1;
  for (int v : g.active)
    if (v != removed) {
      root = v;
      break;
    }
  if (root < 0) return -1;
  int time = 0;
  int root_children = 0;
  disc[root] = low[root] = time++;
  stack.clear();
  stack.push_back({root, g.start[root]});
  while (!stack.empty()) {
    auto& [v, next] = stack.back();
    if (next < g.start[v + 1]) {
      const int w = g.adj[next++];
      if (w == removed) continue;
      if (disc[w] < 0) {
        disc[w] = low[w] = time++;
        if (v == root) ++root_children;
        stack.push_back({w, g.start[w]});
      } else {
        low[v] = std::min(low[v], disc[w]);
      }
    } else {
      const int child = v;
      stack.pop_back();
      if (stack.empty()) break;
      const int parent = stack.back()[0];
      low[parent] = std::min(low[parent], low[child]);
      // A non-root vertex is an articulation point when some child cannot reach above it.
      if (parent != root && low[child] >= disc[parent]) return parent;
    }
  }
  for (int v : g.active)
    if (v != removed && disc[v] < 0) return -2;  // disconnected
  return root_children > 1 ? root : -1;
}

// "vertex 4 at (0.5, 0, 0.5)": a vertex by its 0-based index and its place.
std::string vertex_at(const QuadSurface& surface, int v) {
  const Vec3& p = surface.vertices[static_cast<std::size_t>(v)];
  char text[128];
  std::snprintf(text, sizeof text, "vertex %d at (%g, %g, %g)", v, p[0], p[1], p[2]);
  return text;
}

// "quad 5 (vertices 3, 7, 8, 4; centre (0.5, 1, 2))".
std::string quad_at(const QuadSurface& surface, std::size_t q) {
  const std::array<int, 4>& quad = surface.quads[q];
  const Vec3 c = quad_centre(surface, static_cast<int>(q));
  char centre[96];
  std::snprintf(centre, sizeof centre, "; centre (%g, %g, %g))", c[0], c[1], c[2]);
  return "quad " + std::to_string(q) + " (vertices " + std::to_string(quad[0]) + ", " +
         std::to_string(quad[1]) + ", " + std::to_string(quad[2]) + ", " + std::to_string(quad[3]) + centre;
}

// "edge 3-7 of quad 5, from (...) to (...)".
std::string edge_at(const QuadSurface& surface, const std::array<int, 2>& e, int quad) {
  const Vec3 &a = surface.vertices[static_cast<std::size_t>(e[0])],
             &b = surface.vertices[static_cast<std::size_t>(e[1])];
  char text[192];
  std::snprintf(text, sizeof text, "edge %d-%d of quad %d, from (%g, %g, %g) to (%g, %g, %g)", e[0], e[1],
                quad, a[0], a[1], a[2], b[0], b[1], b[2]);
  return text;
}

}  // namespace

Vec3 quad_centre(const QuadSurface& surface, int q) {
  Vec3 c{0, 0, 0};
  for (int v : surface.quads[static_cast<std::size_t>(q)]) c = vec3::add(c, surface.vertices[v]);
  return vec3::scale(c, 0.25);
}

std::string non_convex_corners_problem(const QuadSurface& surface) {
  int collinear = 0, reflex = 0;
  std::string first_collinear, first_reflex;
  for (std::size_t q = 0; q < surface.quads.size(); ++q) {
    const std::array<int, 4>& quad = surface.quads[q];
    const auto at = [&](int k) { return surface.vertices[static_cast<std::size_t>(quad[k % 4])]; };
    // The quad's normal, from its diagonals (twice its vector area): also defined for a bent quad, whose
    // corners are convex when they turn the same way about it as the quad's corners go round.
    const Vec3 normal = vec3::cross(vec3::sub(at(2), at(0)), vec3::sub(at(3), at(1)));
    for (int k = 0; k < 4; ++k) {
      const int a = quad[(k + 3) % 4], b = quad[k], c = quad[(k + 1) % 4];
      const Vec3 u = vec3::sub(at(k + 3), at(k));
      const Vec3 w = vec3::sub(at(k + 1), at(k));
      const Vec3 turn = vec3::cross(w, u);
      if (vec3::norm(turn) <= 1e-12 * vec3::norm(u) * vec3::norm(w)) {
        if (collinear++ == 0)
          first_collinear = quad_at(surface, q) + " has three collinear corners " + std::to_string(a) + ", " +
                            std::to_string(b) + ", " + std::to_string(c) +
                            ": every hex on it has a corner Jacobian of 0 at " + vertex_at(surface, b) +
                            " whatever the interior, so no valid hex mesh has this boundary; move that "
                            "vertex off the line (make the quad convex)";
        continue;
      }
      if (vec3::dot(turn, normal) > 0) continue;
      // Only a nearly planar quad's corner is sure to be reflex: its halves split along the diagonal through
      // the corner bend by less than 60 degrees. The real jaw's template surface has quads bent by 70 to 170
      // degrees whose diagonal normal makes a corner look reflex although it is convex on the bone; such a
      // quad is left to the embedding (which may call it too bent).
      const Vec3 opposite = at(k + 2);
      const Vec3 half_c = vec3::cross(w, vec3::sub(opposite, at(k)));
      const Vec3 half_a = vec3::cross(vec3::sub(opposite, at(k)), u);
      if (vec3::dot(half_c, half_a) < 0.5 * vec3::norm(half_c) * vec3::norm(half_a)) continue;
      if (reflex++ > 0) continue;
      // The interior angle at b, seen along the normal; a quad without area (a bow tie) has none.
      const double length = vec3::norm(normal);
      char angle[64] = "no area";
      if (length > 0) {
        double degrees = std::atan2(vec3::dot(turn, vec3::scale(normal, 1 / length)), vec3::dot(u, w));
        degrees *= 180 / M_PI;
        std::snprintf(angle, sizeof angle, "%.0f degrees inside", degrees < 0 ? degrees + 360 : degrees);
      }
      first_reflex = quad_at(surface, q) + " is not convex: its corner at " + vertex_at(surface, b) +
                     " between corners " + std::to_string(a) + " and " + std::to_string(c) + " is reflex (" +
                     angle +
                     "): every hex on it has a negative corner Jacobian there whatever the interior, so no "
                     "valid hex mesh has this boundary; move that vertex out (make the quad convex)";
    }
  }
  const auto in_all = [](int n, const std::string& what) {
    return n > 1 ? " (" + std::to_string(n) + " " + what + " quad corners in all)" : std::string();
  };
  std::string text;
  if (collinear > 0) text = first_collinear + in_all(collinear, "such");
  if (reflex > 0) text += (text.empty() ? "" : "; ") + first_reflex + in_all(reflex, "reflex");
  return text;
}

QuadEdges build_quad_edges(const std::vector<std::array<int, 4>>& quads) {
  struct Side {
    int a, b, quad, local;
  };
  std::vector<Side> sides;
  sides.reserve(quads.size() * 4);
  for (int q = 0; q < static_cast<int>(quads.size()); ++q)
    for (int k = 0; k < 4; ++k) {
      const int u = quads[q][k], v = quads[q][(k + 1) % 4];
      sides.push_back({std::min(u, v), std::max(u, v), q, k});
    }
  std::sort(sides.begin(), sides.end(), [](const Side& x, const Side& y) {
    return std::tie(x.a, x.b, x.quad, x.local) < std::tie(y.a, y.b, y.quad, y.local);
  });
  QuadEdges r;
  r.quad_edges.assign(quads.size(), {-1, -1, -1, -1});
  for (std::size_t i = 0; i < sides.size(); ++i) {
    if (i == 0 || sides[i].a != sides[i - 1].a || sides[i].b != sides[i - 1].b) {
      r.edges.push_back({sides[i].a, sides[i].b});
      r.edge_quads.emplace_back();
    }
    const int e = static_cast<int>(r.edges.size()) - 1;
    r.edge_quads[e].push_back({sides[i].quad, sides[i].local});
    r.quad_edges[sides[i].quad][sides[i].local] = e;
  }
  return r;
}

std::vector<Chord> find_chords(const std::vector<std::array<int, 4>>& quads, const QuadEdges& qe) {
  const int ne = static_cast<int>(qe.edges.size());
  for (int e = 0; e < ne; ++e)
    if (qe.edge_quads[e].size() != 2 || qe.edge_quads[e][0][0] == qe.edge_quads[e][1][0])
      throw std::invalid_argument("find_chords: every edge must lie in exactly two different quads");
  std::vector<char> seen(static_cast<std::size_t>(ne), 0);
  std::vector<int> crossings(quads.size(), 0);
  std::vector<Chord> chords;
  for (int start = 0; start < ne; ++start) {
    if (seen[start]) continue;
    Chord c;
    int e = start;
    int q = qe.edge_quads[e][0][0];
    int local = qe.edge_quads[e][0][1];
    do {
      seen[e] = 1;
      c.quads.push_back(q);
      c.edges.push_back(e);
      const int out = qe.quad_edges[q][(local + 2) % 4];
      const auto& pair = qe.edge_quads[out];
      // Leave through the opposite side into the other quad of that edge.
      const int slot = pair[0][0] == q && pair[0][1] == (local + 2) % 4 ? 1 : 0;
      e = out;
      q = pair[slot][0];
      local = pair[slot][1];
    } while (e != start);
    for (int x : c.quads)
      if (++crossings[x] == 2) c.repeated_quads.push_back(x);
    for (int x : c.quads) crossings[x] = 0;
    std::sort(c.repeated_quads.begin(), c.repeated_quads.end());
    chords.push_back(std::move(c));
  }
  return chords;
}

bool is_planar_graph(int n, const std::vector<std::array<int, 2>>& edges) {
  boost::adjacency_list<boost::vecS, boost::vecS, boost::undirectedS> g(static_cast<std::size_t>(n));
  for (const auto& e : edges) boost::add_edge(e[0], e[1], g);
  return boost::boyer_myrvold_planarity_test(g);
}

bool is_three_connected(int n, const std::vector<std::array<int, 2>>& edges, std::vector<int>* separator) {
  const Csr g = make_csr(n, edges);
  if (g.active.size() < 4) return false;
  std::vector<int> disc(static_cast<std::size_t>(n)), low(static_cast<std::size_t>(n));
  std::vector<std::array<int, 2>> stack;
  for (int v : g.active)
    if (g.start[v + 1] - g.start[v] < 3) {  // its neighbours separate it
      if (separator) {
        separator->assign(g.adj.begin() + g.start[v], g.adj.begin() + g.start[v + 1]);
        std::sort(separator->begin(), separator->end());
      }
      return false;
    }
  for (int removed : g.active)
    if (const int cut = articulation_without(g, removed, disc, low, stack); cut != -1) {
      if (separator && cut >= 0) *separator = {std::min(removed, cut), std::max(removed, cut)};
      if (separator && cut == -2) *separator = {removed};
      return false;
    }
  return true;
}

QuadSurfaceReport check_quad_surface(const QuadSurface& surface, const std::string& file) {
  QuadSurfaceReport r;
  r.file = file;
  const auto& quads = surface.quads;
  const int nq = static_cast<int>(quads.size());
  const int nv = static_cast<int>(surface.vertices.size());
  r.quads = nq;
  for (const auto& q : quads)
    for (int v : q)
      if (v < 0 || v >= nv) throw std::invalid_argument("check_quad_surface: vertex index out of range");

  std::vector<char> used(static_cast<std::size_t>(nv), 0);
  for (const auto& q : quads)
    for (int v : q) used[v] = 1;
  r.vertices = static_cast<int>(std::count(used.begin(), used.end(), 1));
  r.unused_vertices = nv - r.vertices;

  // The first place of each problem, for its message (0-based).
  std::string first_degenerate, first_duplicate, first_open, first_non_manifold_edge, first_inconsistent,
      first_non_manifold_vertex, first_unused;
  for (int v = 0; v < nv && first_unused.empty(); ++v)
    if (!used[v]) first_unused = vertex_at(surface, v);
  for (int q = 0; q < nq; ++q) {
    std::array<int, 4> s = quads[q];
    std::sort(s.begin(), s.end());
    if (std::adjacent_find(s.begin(), s.end()) == s.end()) continue;
    if (r.degenerate_quads++ == 0) first_degenerate = quad_at(surface, static_cast<std::size_t>(q));
  }
  {
    std::vector<std::pair<std::array<int, 4>, int>> sorted;
    for (int q = 0; q < nq; ++q) {
      std::array<int, 4> s = quads[q];
      std::sort(s.begin(), s.end());
      sorted.push_back({s, q});
    }
    std::sort(sorted.begin(), sorted.end());
    // Equal vertex sets sort by quad, so the earlier quad comes first.
    for (std::size_t i = 1; i < sorted.size(); ++i)
      if (sorted[i].first == sorted[i - 1].first && r.duplicate_quads++ == 0)
        first_duplicate = quad_at(surface, static_cast<std::size_t>(sorted[i].second)) +
                          ", the same as quad " + std::to_string(sorted[i - 1].second);
  }

  const QuadEdges qe = build_quad_edges(quads);
  r.edges = static_cast<int>(qe.edges.size());
  DisjointSets components(nq);
  // One slot per quad corner; corners of the same vertex in quads joined across an edge at that vertex
  // belong to the same fan, so a vertex with corners in several fans is non-manifold.
  DisjointSets fans(4 * nq);
  std::vector<std::array<int, 3>> sharing;  // quad pairs across manifold edges, with the edge
  for (std::size_t e = 0; e < qe.edges.size(); ++e) {
    const auto& list = qe.edge_quads[e];
    if (list.size() == 1 && r.open_edges++ == 0) first_open = edge_at(surface, qe.edges[e], list[0][0]);
    if (list.size() > 2 && r.non_manifold_edges++ == 0)
      first_non_manifold_edge =
          edge_at(surface, qe.edges[e], list[0][0]) + ", in " + std::to_string(list.size()) + " quads";
    for (std::size_t i = 1; i < list.size(); ++i) components.unite(list[0][0], list[i][0]);
    if (list.size() != 2) continue;
    const auto [q1, k1] = list[0];
    const auto [q2, k2] = list[1];
    sharing.push_back({std::min(q1, q2), std::max(q1, q2), static_cast<int>(e)});
    // Quads are oriented consistently when they traverse their shared edge in opposite directions.
    const bool same_direction = quads[q1][k1] == quads[q2][k2];
    if (same_direction && r.inconsistent_edges++ == 0)
      first_inconsistent = edge_at(surface, qe.edges[e], q1) + " and quad " + std::to_string(q2);
    for (int v : qe.edges[e]) {
      int c1 = -1, c2 = -1;
      for (int k = 0; k < 4; ++k) {
        if (quads[q1][k] == v) c1 = k;
        if (quads[q2][k] == v) c2 = k;
      }
      fans.unite(4 * q1 + c1, 4 * q2 + c2);
    }
  }
  {
    std::vector<int> first_fan(static_cast<std::size_t>(nv), -1);
    std::vector<bool> bad(static_cast<std::size_t>(nv), false);
    for (int q = 0; q < nq; ++q)
      for (int k = 0; k < 4; ++k) {
        const int v = quads[q][k];
        const int f = fans.find(4 * q + k);
        if (first_fan[v] < 0)
          first_fan[v] = f;
        else if (first_fan[v] != f)
          bad[v] = true;
      }
    r.non_manifold_vertices = static_cast<int>(std::count(bad.begin(), bad.end(), true));
    const auto pinched = std::find(bad.begin(), bad.end(), true);
    if (pinched != bad.end())
      first_non_manifold_vertex = vertex_at(surface, static_cast<int>(pinched - bad.begin()));
  }
  for (int q = 0; q < nq; ++q)
    if (components.find(q) == q) ++r.components;
  std::sort(sharing.begin(), sharing.end());
  std::string first_sharing;
  const auto same_pair = [&](std::size_t i, std::size_t j) {
    return sharing[i][0] == sharing[j][0] && sharing[i][1] == sharing[j][1];
  };
  for (std::size_t i = 1; i < sharing.size(); ++i) {
    if (!same_pair(i, i - 1) || (i >= 2 && same_pair(i, i - 2))) continue;
    if (r.quad_pairs_sharing_edges++ > 0) continue;
    std::string shared;
    for (std::size_t j = i - 1; j < sharing.size() && same_pair(j, i); ++j) {
      const std::array<int, 2>& e = qe.edges[static_cast<std::size_t>(sharing[j][2])];
      shared += (shared.empty() ? "" : ", ") + std::to_string(e[0]) + "-" + std::to_string(e[1]);
    }
    first_sharing = quad_at(surface, static_cast<std::size_t>(sharing[i][0])) + " and " +
                    quad_at(surface, static_cast<std::size_t>(sharing[i][1])) + " share edges " + shared;
  }

  r.closed = r.open_edges == 0;
  r.manifold = r.non_manifold_edges == 0 && r.non_manifold_vertices == 0;
  r.consistently_oriented = r.inconsistent_edges == 0;
  r.euler_characteristic = r.vertices - r.edges + nq;
  if (r.closed && r.manifold && r.consistently_oriented && r.components == 1 && r.degenerate_quads == 0)
    r.genus = (2 - r.euler_characteristic) / 2;
  r.ball = r.genus == 0;
  r.even = nq % 2 == 0;
  r.simple = r.degenerate_quads == 0 && r.quad_pairs_sharing_edges == 0 && r.duplicate_quads == 0 &&
             r.non_manifold_edges == 0;
  r.planar = is_planar_graph(nv, qe.edges);
  r.three_connected = is_three_connected(nv, qe.edges, &r.separator);
  if (r.closed && r.non_manifold_edges == 0 && r.degenerate_quads == 0) {
    r.chords_computed = true;
    r.chords = find_chords(quads, qe);
    for (int c = 0; c < static_cast<int>(r.chords.size()); ++c)
      if (!r.chords[c].simple()) r.self_intersecting_chords.push_back(c);
  }

  auto count = [](int n, const char* one, const char* many) {
    return std::to_string(n) + " " + (n == 1 ? one : many);
  };
  if (!r.even)
    r.problems.push_back(
        "odd number of quads (" + std::to_string(nq) +
        "): a hex mesh of a ball needs an even number of boundary quads (Thurston, Mitchell); "
        "refine or remesh the quad surface");
  if (!r.closed) {
    // Quads exported each with its own corners (unwelded) leave every edge open without a visible hole.
    std::vector<Vec3> positions;
    for (int v = 0; v < nv; ++v)
      if (used[v]) positions.push_back(surface.vertices[v]);
    std::sort(positions.begin(), positions.end());
    int coincident = 0;
    for (std::size_t i = 1; i < positions.size(); ++i)
      if (positions[i] == positions[i - 1]) ++coincident;
    r.problems.push_back(
        "not closed: " + count(r.open_edges, "open edge", "open edges") +
        " (edges in only one quad; the first: " + first_open + "); " +
        (coincident > 0 ? count(coincident, "vertex lies", "vertices lie") +
                              " exactly on another one: the quads are not welded, merge coincident vertices "
                              "where the surface was made"
                        : std::string("close the holes")));
  }
  if (!r.manifold)
    r.problems.push_back(
        "not manifold: " + count(r.non_manifold_edges, "edge", "edges") + " in more than two quads" +
        (first_non_manifold_edge.empty() ? "" : " (the first: " + first_non_manifold_edge + ")") + ", " +
        count(r.non_manifold_vertices, "non-manifold vertex", "non-manifold vertices") +
        (first_non_manifold_vertex.empty() ? "" : " (the first: " + first_non_manifold_vertex + ")"));
  if (r.degenerate_quads > 0)
    r.problems.push_back(count(r.degenerate_quads, "degenerate quad", "degenerate quads") +
                         " (a repeated vertex; the first: " + first_degenerate + ")");
  if (r.closed && r.manifold && !r.consistently_oriented)
    r.problems.push_back("inconsistent orientation: " + count(r.inconsistent_edges, "edge", "edges") +
                         " traversed in the same direction by both quads (the first: " + first_inconsistent +
                         "); turn the quads of one side around");
  if (r.components > 1)
    r.problems.push_back("not a ball: " + std::to_string(r.components) + " separate components");
  else if (r.genus > 0)
    r.problems.push_back("not a ball: genus " + std::to_string(r.genus) + " (Euler characteristic " +
                         std::to_string(r.euler_characteristic) +
                         "); the sheet mesher needs a topological "
                         "ball (genus 0); use the grid method");
  if (r.unused_vertices > 0)
    r.problems.push_back(count(r.unused_vertices, "vertex", "vertices") +
                         " in no quad (the first: " + first_unused + "); remove them");
  // A duplicate quad also puts its edges in four quads (not manifold); this names the cause.
  if (r.duplicate_quads > 0)
    r.problems.push_back(
        "graph not simple: " + count(r.duplicate_quads, "duplicate quad", "duplicate quads") +
        " (the same vertices as an earlier quad; the first: " + first_duplicate +
        "); remove the repeated quads");
  if (r.quad_pairs_sharing_edges > 0 && r.degenerate_quads == 0)  // a degenerate quad may pair with itself
    r.problems.push_back("graph not simple: " +
                         count(r.quad_pairs_sharing_edges, "pair of quads shares", "pairs of quads share") +
                         " two or more edges (the first: " + first_sharing +
                         "); quads of a hex mesh's boundary meet in one edge at most: remesh there");
  if (r.ball && !r.three_connected) {
    std::string which = "two vertices";
    if (!r.separator.empty()) {
      which = vertex_at(surface, r.separator[0]);
      for (std::size_t i = 1; i < r.separator.size(); ++i)
        which += " and " + vertex_at(surface, r.separator[i]);
    }
    r.problems.push_back("graph not 3-connected: removing " + which +
                         " disconnects it (a vertex of degree 2 or a pinch); the elimination needs a "
                         "3-connected graph");
  }
  for (int c : r.self_intersecting_chords) {
    const Chord& ch = r.chords[c];
    std::string quads_text;
    for (std::size_t i = 0; i < ch.repeated_quads.size() && i < 10; ++i)
      quads_text += (i ? ", " : "") + std::to_string(ch.repeated_quads[i]);
    if (ch.repeated_quads.size() > 10) quads_text += ", ...";
    r.problems.push_back("chord " + std::to_string(c) + " (length " + std::to_string(ch.length()) +
                         ") self-intersects: it crosses quads " + quads_text +
                         " twice; only simple chords can be eliminated: remesh there or use the grid method");
  }
  return r;
}

}  // namespace hexbite
