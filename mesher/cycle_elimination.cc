#include "mesher/cycle_elimination.h"

#include <algorithm>
#include <chrono>
#include <numeric>

#include "common/error.h"
#include "mesher/quad_check.h"

namespace hexbite {

namespace {

using Quad = std::array<int, 4>;

// A simple chord whose strip splits the other quads into two sides, with the collapse map of its
// elimination side; the expensive part of the feasibility test (the collapsed graph) comes later.
struct Candidate {
  int chord = -1;
  std::vector<char> on_side;  // per quad of the current surface: 1 on the elimination side
  std::vector<int> rung_a;    // elimination-side endpoint of every rung
  std::vector<int> rung_b;    // its partner on the other side
  int side_quads = 0;
  int other_quads = 0;
};

// Steps 1 to 6 of the feasibility test described in the header, all linear: distinct rung endpoints,
// exactly two sides, every rung joining the two sides. Returns false when any of them fails.
bool prepare_candidate(const std::vector<Quad>& quads, const QuadEdges& qe, const Chord& chord, int index,
                       Candidate& out) {
  const int nq = static_cast<int>(quads.size());
  std::vector<int> endpoints;
  for (int e : chord.edges) {
    endpoints.push_back(qe.edges[e][0]);
    endpoints.push_back(qe.edges[e][1]);
  }
  std::sort(endpoints.begin(), endpoints.end());
  if (std::adjacent_find(endpoints.begin(), endpoints.end()) != endpoints.end()) return false;

  std::vector<char> strip(static_cast<std::size_t>(nq), 0);
  for (int q : chord.quads) strip[q] = 1;
  // Sides: components of the non-strip quads across edges whose two quads are both outside the strip.
  std::vector<int> comp(static_cast<std::size_t>(nq), -1);
  std::vector<int> size;
  std::vector<int> queue;
  for (int s = 0; s < nq; ++s) {
    if (strip[s] || comp[s] >= 0) continue;
    const int id = static_cast<int>(size.size());
    size.push_back(0);
    queue.assign(1, s);
    comp[s] = id;
    while (!queue.empty()) {
      const int q = queue.back();
      queue.pop_back();
      ++size[id];
      for (int e : qe.quad_edges[q])
        for (const auto& [r, local] : qe.edge_quads[e])
          if (!strip[r] && comp[r] < 0) {
            comp[r] = id;
            queue.push_back(r);
          }
    }
  }
  if (size.size() != 2) return false;
  // Side of each vertex of a non-strip quad; a vertex touching both sides would pinch the collapsed
  // surface, so it makes the chord infeasible right away.
  std::vector<int> vertex_side;
  for (const Quad& q : quads)
    for (int v : q) vertex_side.resize(std::max<std::size_t>(vertex_side.size(), std::size_t(v) + 1), -1);
  for (int q = 0; q < nq; ++q) {
    if (strip[q]) continue;
    for (int v : quads[q]) {
      if (vertex_side[v] >= 0 && vertex_side[v] != comp[q]) return false;
      vertex_side[v] = comp[q];
    }
  }
  // The smaller side receives the hexes; on a tie the side holding the lowest-numbered non-strip quad,
  // which the search above numbered 0.
  const int side = size[0] <= size[1] ? 0 : 1;
  out = Candidate{};
  out.chord = index;
  out.side_quads = size[side];
  out.other_quads = size[1 - side];
  out.on_side.assign(static_cast<std::size_t>(nq), 0);
  for (int q = 0; q < nq; ++q) out.on_side[q] = !strip[q] && comp[q] == side;
  for (int e : chord.edges) {
    const int a = qe.edges[e][0], b = qe.edges[e][1];
    if (vertex_side[a] < 0 || vertex_side[b] < 0 || vertex_side[a] == vertex_side[b]) return false;
    out.rung_a.push_back(vertex_side[a] == side ? a : b);
    out.rung_b.push_back(vertex_side[a] == side ? b : a);
  }
  return true;
}

// The non-strip quads after the collapse, in their current order, with elimination-side rail vertices
// replaced by their partners (interior vertices of the side keep their ids until the step is accepted).
std::vector<Quad> collapse(const std::vector<Quad>& quads, const Chord& chord, const Candidate& c,
                           std::vector<int>* side_quads) {
  std::vector<std::pair<int, int>> map;
  for (std::size_t i = 0; i < c.rung_a.size(); ++i) map.push_back({c.rung_a[i], c.rung_b[i]});
  std::sort(map.begin(), map.end());
  std::vector<char> strip(quads.size(), 0);
  for (int q : chord.quads) strip[q] = 1;
  std::vector<Quad> out;
  for (int q = 0; q < static_cast<int>(quads.size()); ++q) {
    if (strip[q]) continue;
    Quad m = quads[q];
    if (c.on_side[q]) {
      for (int& v : m) {
        const auto it = std::lower_bound(map.begin(), map.end(), std::make_pair(v, -1));
        if (it != map.end() && it->first == v) v = it->second;
      }
      if (side_quads) side_quads->push_back(q);
    }
    out.push_back(m);
  }
  return out;
}

// The collapsed surface must again be a closed, manifold, oriented ball with a simple, planar, 3-connected
// graph. Its chords may self-intersect: that only rules them out as later candidates.
bool valid_surface(const std::vector<Quad>& quads) {
  std::vector<int> ids;
  for (const Quad& q : quads) ids.insert(ids.end(), q.begin(), q.end());
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  QuadSurface s;
  s.vertices.assign(ids.size(), Vec3{0.0, 0.0, 0.0});
  for (Quad q : quads) {
    for (int& v : q) v = static_cast<int>(std::lower_bound(ids.begin(), ids.end(), v) - ids.begin());
    s.quads.push_back(q);
  }
  const QuadSurfaceReport r = check_quad_surface(s, "");
  return r.ball && r.simple && r.planar && r.three_connected;
}

// Candidates of the current surface in the order of the fewest-hexes rule.
std::vector<Candidate> ordered_candidates(const std::vector<Quad>& quads, const QuadEdges& qe,
                                          const std::vector<Chord>& chords) {
  std::vector<Candidate> list;
  for (int c = 0; c < static_cast<int>(chords.size()); ++c) {
    if (!chords[c].simple()) continue;
    Candidate cand;
    if (prepare_candidate(quads, qe, chords[c], c, cand)) list.push_back(std::move(cand));
  }
  std::stable_sort(list.begin(), list.end(),
                   [](const Candidate& a, const Candidate& b) { return a.side_quads < b.side_quads; });
  return list;
}

bool has_feasible_chord(const std::vector<Quad>& quads) {
  if (quads.size() == 6) return true;
  const QuadEdges qe = build_quad_edges(quads);
  const std::vector<Chord> chords = find_chords(quads, qe);
  for (const Candidate& c : ordered_candidates(quads, qe, chords))
    if (valid_surface(collapse(quads, chords[c.chord], c, nullptr))) return true;
  return false;
}

std::string describe_chords(const std::vector<Chord>& chords) {
  std::string s;
  for (std::size_t i = 0; i < chords.size() && i < 20; ++i) {
    s += (i ? ", " : "") + std::string("chord ") + std::to_string(i) + " (length " +
         std::to_string(chords[i].length()) + (chords[i].simple() ? "" : ", self-intersecting") + ")";
  }
  if (chords.size() > 20) s += ", ...";
  return s;
}

// The single hex of a cube surface: the first quad is its bottom, the top corners are the bottom corners'
// third neighbours.
std::array<int, 8> cube_hex(const std::array<Quad, 6>& cube) {
  std::array<int, 8> h{};
  const Quad& b = cube[0];
  h[0] = b[0];
  h[3] = b[1];
  h[2] = b[2];
  h[1] = b[3];
  for (int i = 0; i < 4; ++i) {
    for (const Quad& q : cube)
      for (int k = 0; k < 4; ++k) {
        const int u = q[k], v = q[(k + 1) % 4];
        const int other = u == h[i] ? v : v == h[i] ? u : -1;
        if (other >= 0 && std::find(b.begin(), b.end(), other) == b.end()) h[i + 4] = other;
      }
  }
  return h;
}

}  // namespace

EliminationOrder parse_elimination_order(const std::string& name) {
  if (name == "fewest-hexes") return EliminationOrder::kFewestHexes;
  if (name == "look-ahead") return EliminationOrder::kLookAhead;
  throw InputError("unknown elimination order '" + name + "': use fewest-hexes or look-ahead");
}

const char* elimination_order_name(EliminationOrder order) {
  return order == EliminationOrder::kLookAhead ? "look-ahead" : "fewest-hexes";
}

EliminationScheme eliminate_chords(const QuadSurface& surface, const EliminationOptions& options) {
  const QuadSurfaceReport check = check_quad_surface(surface, "the quad surface");
  if (!check.usable()) {
    std::string problems;
    for (const std::string& p : check.problems) problems += (problems.empty() ? "" : "; ") + p;
    throw InputError("the quad surface cannot be meshed by cycle elimination: " + problems);
  }
  EliminationScheme scheme;
  scheme.input_vertices = static_cast<int>(surface.vertices.size());
  int next_id = scheme.input_vertices;
  std::vector<Quad> quads = surface.quads;
  while (quads.size() > 6) {
    const QuadEdges qe = build_quad_edges(quads);
    const std::vector<Chord> chords = find_chords(quads, qe);
    const Candidate* chosen = nullptr;
    std::vector<Quad> next;
    std::vector<int> side;
    const std::vector<Candidate> candidates = ordered_candidates(quads, qe, chords);
    for (const Candidate& c : candidates) {
      std::vector<int> side_quads;
      std::vector<Quad> collapsed = collapse(quads, chords[c.chord], c, &side_quads);
      if (!valid_surface(collapsed)) continue;
      if (options.order == EliminationOrder::kLookAhead && !has_feasible_chord(collapsed)) continue;
      chosen = &c;
      next = std::move(collapsed);
      side = std::move(side_quads);
      break;
    }
    if (!chosen)
      throw RunError("cycle elimination is stuck: no chord of the remaining surface (" +
                     std::to_string(quads.size()) + " quads, " + std::to_string(chords.size()) +
                     " chords: " + describe_chords(chords) +
                     ") can be eliminated with a simple, planar, 3-connected result; k-step eliminations and "
                     "decomposition are not implemented yet: use --method grid");
    // Fresh interior ids for the side's vertices that are not rail vertices; the rail vertices were mapped
    // onto their partners by collapse().
    std::vector<int> rails = chosen->rung_a;
    std::sort(rails.begin(), rails.end());
    std::vector<std::pair<int, int>> fresh;  // (old id, new id), sorted by old id
    std::vector<int> interior;
    for (int q : side)
      for (int v : quads[q])
        if (!std::binary_search(rails.begin(), rails.end(), v)) interior.push_back(v);
    std::sort(interior.begin(), interior.end());
    interior.erase(std::unique(interior.begin(), interior.end()), interior.end());
    for (int v : interior) {
      fresh.push_back({v, next_id++});
      scheme.split_from.push_back(v);
    }
    Elimination step;
    step.chord_length = chords[chosen->chord].length();
    step.quads_before = static_cast<int>(quads.size());
    step.other_side_quads = chosen->other_quads;
    // `next` lists the non-strip quads in order, so the side quads are found again by walking both lists.
    std::size_t k = 0;
    std::vector<char> strip(quads.size(), 0);
    for (int q : chords[chosen->chord].quads) strip[q] = 1;
    for (int q = 0; q < static_cast<int>(quads.size()); ++q) {
      if (strip[q]) continue;
      Quad& inner = next[k++];
      if (!chosen->on_side[q]) continue;
      for (int& v : inner) {
        const auto it = std::lower_bound(fresh.begin(), fresh.end(), std::make_pair(v, -1));
        if (it != fresh.end() && it->first == v) v = it->second;
      }
      step.hexes.push_back({quads[q], inner});
    }
    scheme.eliminations.push_back(std::move(step));
    quads = std::move(next);
  }
  std::copy(quads.begin(), quads.end(), scheme.cube.begin());
  scheme.total_vertices = next_id;
  return scheme;
}

HexMesh build_hex_complex(const QuadSurface& surface, const EliminationScheme& scheme) {
  HexMesh mesh;
  mesh.vertices = surface.vertices;
  // Interior vertices are created in id order, and each copies a vertex with a smaller id.
  for (int v : scheme.split_from) mesh.vertices.push_back(mesh.vertices[v]);
  mesh.hexes.push_back(cube_hex(scheme.cube));
  for (auto it = scheme.eliminations.rbegin(); it != scheme.eliminations.rend(); ++it)
    for (const auto& [outer, inner] : it->hexes)
      mesh.hexes.push_back({inner[0], inner[1], inner[2], inner[3], outer[0], outer[1], outer[2], outer[3]});
  return mesh;
}

HexMesh mesh_by_cycle_elimination(const QuadSurface& surface, const SheetMeshOptions& options,
                                  SheetMeshReport* report) {
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  const EliminationScheme scheme = eliminate_chords(surface, options.elimination);
  HexMesh mesh = build_hex_complex(surface, scheme);
  const auto t1 = Clock::now();
  const int n = scheme.input_vertices;
  std::vector<char> interior(mesh.vertices.size(), 0), fixed(mesh.vertices.size(), 0);
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) (static_cast<int>(v) < n ? fixed : interior)[v] = 1;
  barycentric_smoothing(mesh, interior, options.smoothing_iterations);
  OptimizeReport opt;
  if (options.optimize) opt = optimize_hex_mesh(mesh, nullptr, fixed, options.optimizer);
  const auto t2 = Clock::now();
  if (report) {
    SheetMeshReport& r = *report;
    r = SheetMeshReport{};
    r.quads = static_cast<int>(surface.quads.size());
    r.chords = static_cast<int>(find_chords(surface.quads, build_quad_edges(surface.quads)).size());
    r.eliminations = static_cast<int>(scheme.eliminations.size());
    r.external_sheets = r.eliminations;
    r.hexes = static_cast<int>(mesh.hexes.size());
    r.interior_vertices = scheme.total_vertices - n;
    r.order = options.elimination.order;
    r.seconds_elimination = std::chrono::duration<double>(t1 - t0).count();
    r.seconds_embedding = std::chrono::duration<double>(t2 - t1).count();
    r.optimize = std::move(opt);
    r.quality = summarize_quality(mesh);
  }
  return mesh;
}

}  // namespace hexbite
