#include "mesher/cycle_elimination.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iterator>

#include "common/error.h"
#include "mesher/elimination_feasibility.h"
#include "mesher/hex_pillow.h"
#include "mesher/internal_sheet.h"
#include "mesher/quad_check.h"
#include "mesher/vec3.h"

namespace hexbite {

namespace {

using Quad = std::array<int, 4>;

// A simple chord whose strip leaves exactly two sides, every rung joining them: the basis of both single
// and k-step eliminations.
struct ChordSides {
  int chord = -1;
  std::vector<int> side;                 // per quad of the current surface: -1 in the strip, else side 0 or 1
  std::array<int, 2> size{0, 0};         // quads per side
  std::array<std::vector<int>, 2> rail;  // rail[s][i]: the endpoint of rung i on side s
  std::vector<int> endpoints;            // all rung endpoints, ascending
};

// An elimination step: its chords, the elimination side Q (the quads that receive hexes) and the collapse
// map from the Q-side rails onto the other rails.
struct Step {
  std::vector<int> chords;     // indices into the current chords, ascending
  std::vector<char> on_side;   // per quad: 1 in Q
  std::vector<int> rung_from;  // Q-side endpoint of every rung
  std::vector<int> rung_to;    // its partner
  int strip_quads = 0;
  int side_quads = 0;
  int other_quads = 0;
  double sharpness = 0.0;  // geometric order only
  bool flat = false;       // geometric order only: a pillow on a flat patch (flat_step())
};

// Edge-connected components of the quads outside the strip; comp[q] = -1 for strip quads.
int components(const QuadEdges& qe, const std::vector<char>& strip, std::vector<int>& comp) {
  return quad_components(
      qe, [&strip](int q) { return !strip[q]; }, [](int) { return true; }, comp);
}

// The linear part of the feasibility test of one chord: distinct rung endpoints (both rails are disjoint
// simple cycles), exactly two sides, no vertex on both sides, every rung joining the two sides.
bool chord_sides(const std::vector<Quad>& quads, const QuadEdges& qe, const Chord& chord, int index,
                 int max_id, ChordSides& out) {
  out = ChordSides{};
  out.chord = index;
  for (int e : chord.edges) {
    out.endpoints.push_back(qe.edges[e][0]);
    out.endpoints.push_back(qe.edges[e][1]);
  }
  std::sort(out.endpoints.begin(), out.endpoints.end());
  if (std::adjacent_find(out.endpoints.begin(), out.endpoints.end()) != out.endpoints.end()) return false;
  std::vector<char> strip(quads.size(), 0);
  for (int q : chord.quads) strip[q] = 1;
  if (components(qe, strip, out.side) != 2) return false;
  std::vector<int> vertex_side(static_cast<std::size_t>(max_id) + 1, -1);
  for (int q = 0; q < static_cast<int>(quads.size()); ++q) {
    if (strip[q]) continue;
    ++out.size[out.side[q]];
    for (int v : quads[q]) {
      if (vertex_side[v] >= 0 && vertex_side[v] != out.side[q]) return false;  // pinches the collapse
      vertex_side[v] = out.side[q];
    }
  }
  for (int e : chord.edges) {
    const int a = qe.edges[e][0], b = qe.edges[e][1];
    if (vertex_side[a] < 0 || vertex_side[b] < 0 || vertex_side[a] == vertex_side[b]) return false;
    out.rail[vertex_side[a]].push_back(a);
    out.rail[vertex_side[b]].push_back(b);
  }
  return true;
}

// A single elimination: Q is the smaller side; on a tie the side holding the lowest-numbered non-strip
// quad, which components() numbered 0.
Step single_step(const ChordSides& c, int strip_quads) {
  const int s = c.size[0] <= c.size[1] ? 0 : 1;
  Step step;
  step.chords = {c.chord};
  step.on_side.resize(c.side.size());
  for (std::size_t q = 0; q < c.side.size(); ++q) step.on_side[q] = c.side[q] == s;
  step.rung_from = c.rail[s];
  step.rung_to = c.rail[1 - s];
  step.strip_quads = strip_quads;
  step.side_quads = c.size[s];
  step.other_quads = c.size[1 - s];
  return step;
}

bool disjoint(const std::vector<int>& a, const std::vector<int>& b) {
  for (std::size_t i = 0, j = 0; i < a.size() && j < b.size();) {
    if (a[i] == b[j]) return false;
    a[i] < b[j] ? ++i : ++j;
  }
  return true;
}

// A k-step elimination of the chords `parts` (k >= 2, pairwise vertex-disjoint strips), with the seed's
// conditions: Q_i is the side of chord i that holds the other chords (if they lie on both sides no Q_i can
// make every chord bound Q), Q is the intersection of the Q_i, (2) Q is edge-connected and (3) Q union Q_i
// has more quads than Q for every i. Beyond the paper's wording, every Q-side rail must bound Q and no
// vertex may touch both Q and the quads outside it, so that the one sheet of hexes under Q meets the
// surface exactly in the k chords. Condition (1), the collapsed graph, is tested afterwards.
bool k_step(const std::vector<Quad>& quads, const QuadEdges& qe, const std::vector<Chord>& chords,
            const std::vector<const ChordSides*>& parts, int max_id, Step& out) {
  const int nq = static_cast<int>(quads.size());
  const std::size_t k = parts.size();
  std::vector<int> s(k, -1);
  for (std::size_t i = 0; i < k; ++i) {
    for (std::size_t j = 0; j < k; ++j) {
      if (i == j) continue;
      if (!disjoint(parts[i]->endpoints, parts[j]->endpoints)) return false;
      const int side = parts[i]->side[chords[parts[j]->chord].quads[0]];
      if (s[i] >= 0 && s[i] != side) return false;
      s[i] = side;
    }
  }
  out = Step{};
  out.on_side.assign(static_cast<std::size_t>(nq), 0);
  std::vector<char> strip(static_cast<std::size_t>(nq), 0);
  for (const ChordSides* p : parts) {
    out.chords.push_back(p->chord);
    for (int q : chords[p->chord].quads) strip[q] = 1;
    out.strip_quads += chords[p->chord].length();
  }
  std::sort(out.chords.begin(), out.chords.end());
  for (int q = 0; q < nq; ++q) {
    bool in = true;
    for (std::size_t i = 0; i < k && in; ++i) in = parts[i]->side[q] == s[i];
    if (!in) continue;
    out.on_side[q] = 1;
    ++out.side_quads;
  }
  // (2) Q non-empty and edge-connected.
  std::vector<int> component;
  if (quad_components(
          qe, [&out](int q) { return out.on_side[q] != 0; }, [](int) { return true; }, component) != 1)
    return false;
  // (3) Q union Q_i larger than Q.
  for (std::size_t i = 0; i < k; ++i)
    if (parts[i]->size[s[i]] <= out.side_quads) return false;
  // The sheet under Q is bounded by exactly the k chords.
  std::vector<char> in_q(static_cast<std::size_t>(max_id) + 1, 0), in_rest(in_q.size(), 0);
  for (int q = 0; q < nq; ++q)
    if (!strip[q])
      for (int v : quads[q]) (out.on_side[q] ? in_q : in_rest)[v] = 1;
  for (int v = 0; v <= max_id; ++v)
    if (in_q[v] && in_rest[v]) return false;
  for (std::size_t i = 0; i < k; ++i) {
    for (int v : parts[i]->rail[s[i]])
      if (!in_q[v]) return false;
    out.rung_from.insert(out.rung_from.end(), parts[i]->rail[s[i]].begin(), parts[i]->rail[s[i]].end());
    out.rung_to.insert(out.rung_to.end(), parts[i]->rail[1 - s[i]].begin(), parts[i]->rail[1 - s[i]].end());
  }
  out.other_quads = nq - out.side_quads - out.strip_quads;
  return true;
}

// The non-strip quads after the collapse, in their current order, with Q-side rail vertices replaced by
// their partners (interior vertices of Q keep their ids until the step is accepted).
std::vector<Quad> collapse(const std::vector<Quad>& quads, const std::vector<Chord>& chords,
                           const Step& step) {
  std::vector<std::pair<int, int>> map;
  for (std::size_t i = 0; i < step.rung_from.size(); ++i) map.push_back({step.rung_from[i], step.rung_to[i]});
  std::sort(map.begin(), map.end());
  std::vector<char> strip(quads.size(), 0);
  for (int c : step.chords)
    for (int q : chords[c].quads) strip[q] = 1;
  std::vector<Quad> out;
  for (int q = 0; q < static_cast<int>(quads.size()); ++q) {
    if (strip[q]) continue;
    Quad m = quads[q];
    if (step.on_side[q])
      for (int& v : m) {
        const auto it = std::lower_bound(map.begin(), map.end(), std::make_pair(v, -1));
        if (it != map.end() && it->first == v) v = it->second;
      }
    out.push_back(m);
  }
  return out;
}

Vec3 quad_normal(const Quad& q, const std::vector<Vec3>& positions) {
  Vec3 n{0.0, 0.0, 0.0};
  for (int k = 0; k < 4; ++k) n = vec3::add(n, vec3::cross(positions[q[k]], positions[q[(k + 1) % 4]]));
  return n;
}

// The mean angle (radians) between the normals of the chord's strip quads and the quads across its rail on
// the side where in_q(quad) holds: 0 where the rail runs through a flat region, pi / 2 along a right-angled
// primal cycle.
template <class InQ>
double rail_angle(const std::vector<Quad>& quads, const QuadEdges& qe, const Chord& chord, InQ in_q,
                  const std::vector<Vec3>& positions) {
  double sum = 0.0;
  int count = 0;
  for (int q : chord.quads) {
    const Vec3 nq = quad_normal(quads[q], positions);
    for (int e : qe.quad_edges[q])
      for (const auto& [r, local] : qe.edge_quads[e]) {
        if (!in_q(r)) continue;
        const Vec3 nr = quad_normal(quads[r], positions);
        const double len = vec3::norm(nq) * vec3::norm(nr);
        const double cosine = len > 0.0 ? vec3::dot(nq, nr) / len : 1.0;
        sum += std::acos(std::clamp(cosine, -1.0, 1.0));
        ++count;
      }
  }
  return count ? sum / count : 0.0;
}

// A step's sharpness: the smallest rail angle over its chords, on the Q side.
double rail_sharpness(const std::vector<Quad>& quads, const QuadEdges& qe, const std::vector<Chord>& chords,
                      const Step& step, const std::vector<Vec3>& positions) {
  double sharpness = M_PI;
  for (int c : step.chords)
    sharpness = std::min(sharpness,
                         rail_angle(
                             quads, qe, chords[c], [&](int q) { return step.on_side[q] != 0; }, positions));
  return sharpness;
}

// Positions for the interior vertices of Q on the collapsed surface (appended to `positions` in the order
// of `interior`, the vertices' new ids), for the geometric order: every Q-side rail vertex moves onto its
// partner, and the interior vertices follow by the harmonic extension of those displacements over Q (Jacobi
// sweeps), so that a peeled end face lands flat one layer in rather than leaving a tent behind.
void place_inner_vertices(const std::vector<Quad>& quads, const Step& step, const std::vector<int>& interior,
                          std::vector<Vec3>& positions) {
  std::vector<std::pair<int, Vec3>> shift;  // (vertex, displacement), sorted by vertex
  for (std::size_t i = 0; i < step.rung_from.size(); ++i)
    shift.push_back({step.rung_from[i], vec3::sub(positions[step.rung_to[i]], positions[step.rung_from[i]])});
  for (int v : interior) shift.push_back({v, Vec3{0.0, 0.0, 0.0}});
  std::sort(shift.begin(), shift.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  auto slot = [&](int v) {
    return static_cast<std::size_t>(
        std::lower_bound(shift.begin(), shift.end(), v, [](const auto& a, int x) { return a.first < x; }) -
        shift.begin());
  };
  std::vector<std::array<std::size_t, 2>> edges;  // Q's edges between interior vertices and anything in Q
  for (std::size_t q = 0; q < quads.size(); ++q)
    if (step.on_side[q])
      for (int k = 0; k < 4; ++k) edges.push_back({slot(quads[q][k]), slot(quads[q][(k + 1) % 4])});
  std::vector<char> free_vertex(shift.size(), 0);
  for (int v : interior) free_vertex[slot(v)] = 1;
  for (int sweep = 0; sweep < 50; ++sweep) {
    std::vector<Vec3> sum(shift.size(), Vec3{0.0, 0.0, 0.0});
    std::vector<int> count(shift.size(), 0);
    for (const auto& [a, b] : edges) {
      sum[a] = vec3::add(sum[a], shift[b].second);
      sum[b] = vec3::add(sum[b], shift[a].second);
      ++count[a];
      ++count[b];
    }
    for (std::size_t i = 0; i < shift.size(); ++i)
      if (free_vertex[i] && count[i] > 0) shift[i].second = vec3::scale(sum[i], 1.0 / count[i]);
  }
  for (int v : interior) positions.push_back(vec3::add(positions[v], shift[slot(v)].second));
}

// Whether the step removes a pillow from a flat patch of the surface (a patch refined or pillowed within a
// face): the normals of Q, of the strips and of the quads across both rails agree within 15 degrees. Its
// sheet belongs under the patch (an internal sheet, mesher/internal_sheet.h), which fits only while the
// hexes below the patch are not yet corner hexes, so the geometric order takes such steps first. A strip
// with one sharp rail (the O-grid disk's cap ring, along the rim) is no pillow.
bool flat_step(const std::vector<Quad>& quads, const QuadEdges& qe, const std::vector<Chord>& chords,
               const Step& step, const std::vector<Vec3>& positions) {
  std::vector<char> strip(quads.size(), 0);
  for (int c : step.chords)
    for (int q : chords[c].quads) strip[q] = 1;
  const double min_cosine = std::cos(15.0 * M_PI / 180.0);
  for (std::size_t e = 0; e < qe.edges.size(); ++e) {
    const int a = qe.edge_quads[e][0][0], b = qe.edge_quads[e][1][0];
    const bool involved = strip[a] || strip[b] || (step.on_side[a] && step.on_side[b]);
    if (!involved) continue;
    const Vec3 na = quad_normal(quads[a], positions), nb = quad_normal(quads[b], positions);
    if (vec3::dot(na, nb) < min_cosine * vec3::norm(na) * vec3::norm(nb)) return false;
  }
  return true;
}

// A rail is sharp from a mean angle of 45 degrees between the normals across it.
constexpr double kSharpRail = M_PI / 4;

// Rank of a sharpness: 1 for a sharp rail, else 0. Two classes only: 5-degree ranks let the faceting of
// smooth regions and folds of a mandible quad surface outweigh the side size (59 instead of 18 inverted
// hexes on the jaw, docs/sheets.md).
int sharpness_rank(double angle) {
  return angle >= kSharpRail ? 1 : 0;
}

struct Candidates {
  std::vector<ChordSides> chords;  // every simple chord that passes chord_sides()
  std::vector<Step> steps;         // in the order of the elimination order
};

Candidates ordered_candidates(const std::vector<Quad>& quads, const QuadEdges& qe,
                              const std::vector<Chord>& chords, EliminationOrder order,
                              const std::vector<Vec3>* positions) {
  int max_id = 0;
  for (const Quad& q : quads) max_id = std::max(max_id, *std::max_element(q.begin(), q.end()));
  Candidates out;
  for (int c = 0; c < static_cast<int>(chords.size()); ++c) {
    if (!chords[c].simple()) continue;
    ChordSides sides;
    if (!chord_sides(quads, qe, chords[c], c, max_id, sides)) continue;
    out.steps.push_back(single_step(sides, chords[c].length()));
    out.chords.push_back(std::move(sides));
  }
  if (order != EliminationOrder::kGeometric) {
    std::stable_sort(out.steps.begin(), out.steps.end(),
                     [](const Step& a, const Step& b) { return a.side_quads < b.side_quads; });
    return out;
  }
  for (Step& s : out.steps) {
    s.sharpness = rail_sharpness(quads, qe, chords, s, *positions);
    s.flat = flat_step(quads, qe, chords, s, *positions);
  }
  // The geometric order also weighs 2-step eliminations: one annular sheet under the region between two
  // chords, which is what a boundary layer between two sharp primal cycles wants; so only when both Q-side
  // rails are sharp (a mean dihedral angle of 45 degrees or more), never in smooth or flat regions. The
  // rail angles of every chord side come first, so that only pairs of sharp sides facing each other are
  // prepared (O(F) each).
  std::vector<std::array<char, 2>> sharp(out.chords.size());
  for (std::size_t i = 0; i < out.chords.size(); ++i)
    for (int side = 0; side < 2; ++side)
      sharp[i][side] = rail_angle(
                           quads, qe, chords[out.chords[i].chord],
                           [&](int q) { return out.chords[i].side[q] == side; }, *positions) >= kSharpRail;
  auto faces_sharp = [&](std::size_t i, std::size_t j) {  // chord i's rail towards chord j is sharp
    return sharp[i][out.chords[i].side[chords[out.chords[j].chord].quads[0]]] != 0;
  };
  for (std::size_t i = 0; i < out.chords.size(); ++i)
    for (std::size_t j = i + 1; j < out.chords.size(); ++j) {
      if (!faces_sharp(i, j) || !faces_sharp(j, i)) continue;
      if (!disjoint(out.chords[i].endpoints, out.chords[j].endpoints)) continue;
      Step step;
      if (!k_step(quads, qe, chords, {&out.chords[i], &out.chords[j]}, max_id, step)) continue;
      step.sharpness = rail_sharpness(quads, qe, chords, step, *positions);
      if (step.sharpness >= kSharpRail) out.steps.push_back(std::move(step));
    }
  std::stable_sort(out.steps.begin(), out.steps.end(), [](const Step& a, const Step& b) {
    const int ra = a.flat ? 2 : sharpness_rank(a.sharpness), rb = b.flat ? 2 : sharpness_rank(b.sharpness);
    return ra != rb ? ra > rb : a.side_quads < b.side_quads;
  });
  return out;
}

// Whether the surface is a cube or has a feasible single elimination. k-steps need not be tried: for
// vertex-disjoint chords the collapse of all of them is the collapse of one followed by the others, and a
// defect of the first collapse (two quads meeting in two vertices but no edge, a vertex of degree 2, a
// parallel edge) involves only its merged rail vertices, which the later collapses neither separate nor
// remove; so a feasible k-step implies feasible single eliminations of each of its chords.
bool has_feasible_chord(const std::vector<Quad>& quads) {
  if (quads.size() == 6) return true;
  const QuadEdges qe = build_quad_edges(quads);
  const std::vector<Chord> chords = find_chords(quads, qe);
  for (const Step& s : ordered_candidates(quads, qe, chords, EliminationOrder::kFewestHexes, nullptr).steps)
    if (is_polyhedral_ball(collapse(quads, chords, s))) return true;
  return false;
}

std::string quad_text(const Quad& q, int input_vertices) {
  std::string s = "[";
  for (int k = 0; k < 4; ++k) s += (k ? " " : "") + (q[k] < input_vertices ? std::to_string(q[k]) : "new");
  return s + "]";
}

// The last sentence of the RunError when no elimination is feasible.
constexpr const char* kStuckAdvice = ". Refine the quad surface there or mesh the solid with --method grid";

// The RunError text when no elimination is feasible: the remaining chords with their lengths and quads
// (input vertex ids; "new" for interior vertices created by earlier eliminations).
std::string stuck_message(const std::vector<Quad>& quads, const std::vector<Chord>& chords, int done,
                          int input_vertices) {
  std::string s = "cycle elimination is stuck after " + std::to_string(done) +
                  " eliminations: no chord of the remaining surface (" + std::to_string(quads.size()) +
                  " quads, " + std::to_string(chords.size()) +
                  " chords) can be eliminated with a simple, planar, 3-connected result (and no 2-step "
                  "elimination can, see docs/sheets.md). Remaining chords: ";
  for (std::size_t i = 0; i < chords.size() && i < 12; ++i) {
    s += (i ? "; " : "") + std::string("chord ") + std::to_string(i) + " (length " +
         std::to_string(chords[i].length()) + (chords[i].simple() ? "" : ", self-intersecting") + ", quads";
    for (std::size_t k = 0; k < chords[i].quads.size() && k < 4; ++k)
      s += " " + quad_text(quads[chords[i].quads[k]], input_vertices);
    s += chords[i].quads.size() > 4 ? " ...)" : ")";
  }
  if (chords.size() > 12) s += "; ...";
  return s + kStuckAdvice;
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

// The chord through the edge {rung[0], rung[1]} of the current surface, or -1 when there is no such edge.
int chord_of_rung(const QuadEdges& qe, const std::vector<Chord>& chords, const std::array<int, 2>& rung) {
  const std::array<int, 2> key{std::min(rung[0], rung[1]), std::max(rung[0], rung[1])};
  const auto it = std::lower_bound(qe.edges.begin(), qe.edges.end(), key);
  if (key[0] == key[1] || it == qe.edges.end() || *it != key) return -1;
  const int e = static_cast<int>(it - qe.edges.begin());
  for (int c = 0; c < static_cast<int>(chords.size()); ++c)
    if (std::find(chords[c].edges.begin(), chords[c].edges.end(), e) != chords[c].edges.end()) return c;
  return -1;
}

// Vertex v's id after `step`: a Q-side rail vertex becomes its rung partner, an interior vertex of Q its
// fresh id (`fresh`: sorted (old, new) pairs); others keep theirs.
int renamed(int v, const Step& step, const std::vector<std::pair<int, int>>& fresh) {
  for (std::size_t i = 0; i < step.rung_from.size(); ++i)
    if (step.rung_from[i] == v) return step.rung_to[i];
  const auto it = std::lower_bound(fresh.begin(), fresh.end(), std::make_pair(v, -1));
  return it != fresh.end() && it->first == v ? it->second : v;
}

}  // namespace

EliminationOrder parse_elimination_order(const std::string& name) {
  if (name == "fewest-hexes") return EliminationOrder::kFewestHexes;
  if (name == "look-ahead") return EliminationOrder::kLookAhead;
  if (name == "geometric") return EliminationOrder::kGeometric;
  throw InputError("unknown elimination order '" + name + "': use fewest-hexes, look-ahead or geometric");
}

const char* elimination_order_name(EliminationOrder order) {
  switch (order) {
    case EliminationOrder::kLookAhead:
      return "look-ahead";
    case EliminationOrder::kGeometric:
      return "geometric";
    default:
      return "fewest-hexes";
  }
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
  std::vector<Vec3> positions = surface.vertices;  // of the current surface, for the geometric order
  std::vector<Quad> quads = surface.quads;
  std::vector<std::array<int, 2>> first_rungs = options.first_rungs;  // ids followed through collapses
  std::size_t first = 0;                                              // the next of them
  while (quads.size() > 6) {
    const QuadEdges qe = build_quad_edges(quads);
    const std::vector<Chord> chords = find_chords(quads, qe);
    const Candidates candidates = ordered_candidates(quads, qe, chords, options.order, &positions);
    const Step* chosen = nullptr;
    std::vector<Quad> next;
    auto feasible = [&](const Step& s) {
      std::vector<Quad> collapsed = collapse(quads, chords, s);
      if (!is_polyhedral_ball(collapsed)) return false;
      if (options.order != EliminationOrder::kFewestHexes && !has_feasible_chord(collapsed)) return false;
      chosen = &s;
      next = std::move(collapsed);
      return true;
    };
    while (!chosen && first < first_rungs.size()) {
      const int c = chord_of_rung(qe, chords, first_rungs[first++]);
      for (const Step& s : candidates.steps)
        if (c >= 0 && s.chords.size() == 1 && s.chords[0] == c && feasible(s)) break;
    }
    for (const Step& s : candidates.steps)
      if (chosen || feasible(s)) break;
    if (!chosen)
      throw RunError(
          stuck_message(quads, chords, static_cast<int>(scheme.eliminations.size()), scheme.input_vertices));
    // Fresh interior ids for the vertices of Q that are not rail vertices; the rail vertices were mapped
    // onto their partners by collapse().
    std::vector<int> rails = chosen->rung_from;
    std::sort(rails.begin(), rails.end());
    std::vector<int> interior;
    for (int q = 0; q < static_cast<int>(quads.size()); ++q)
      if (chosen->on_side[q])
        for (int v : quads[q])
          if (!std::binary_search(rails.begin(), rails.end(), v)) interior.push_back(v);
    std::sort(interior.begin(), interior.end());
    interior.erase(std::unique(interior.begin(), interior.end()), interior.end());
    Elimination step;
    step.first_new_vertex = next_id;
    step.new_vertices = static_cast<int>(interior.size());
    std::vector<std::pair<int, int>> fresh;  // (old id, new id), sorted by old id
    if (options.order == EliminationOrder::kGeometric)
      place_inner_vertices(quads, *chosen, interior, positions);
    for (int v : interior) {
      fresh.push_back({v, next_id++});
      scheme.split_from.push_back(v);
    }
    step.chords = static_cast<int>(chosen->chords.size());
    step.chord_length = chosen->strip_quads;
    step.quads_before = static_cast<int>(quads.size());
    step.other_side_quads = chosen->other_quads;
    // `next` lists the non-strip quads in order, so the side quads are found again by walking both lists.
    std::vector<char> strip(quads.size(), 0);
    for (int c : chosen->chords)
      for (int q : chords[c].quads) strip[q] = 1;
    std::size_t k = 0;
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
    for (std::size_t i = first; i < first_rungs.size(); ++i)
      for (int& v : first_rungs[i]) v = renamed(v, *chosen, fresh);
  }
  std::copy(quads.begin(), quads.end(), scheme.cube.begin());
  scheme.total_vertices = next_id;
  return scheme;
}

HexMesh build_hex_complex(const QuadSurface& surface, const EliminationScheme& scheme) {
  return build_hex_complex(surface, scheme, false, nullptr);
}

HexMesh build_hex_complex(const QuadSurface& surface, const EliminationScheme& scheme, bool internal_sheets,
                          std::vector<SheetKind>* kinds) {
  HexMesh mesh;
  mesh.vertices = surface.vertices;
  // Interior vertices are created in id order, and each copies a vertex with a smaller id.
  for (int v : scheme.split_from) mesh.vertices.push_back(mesh.vertices[v]);
  mesh.hexes.push_back(cube_hex(scheme.cube));
  std::vector<SheetKind> kind(scheme.eliminations.size(), SheetKind::kExternal);
  for (std::size_t i = scheme.eliminations.size(); i-- > 0;) {
    const Elimination& e = scheme.eliminations[i];
    if (internal_sheets && insert_internal_sheet(mesh, e.hexes, e.first_new_vertex, e.new_vertices)) {
      kind[i] = SheetKind::kInternal;
      continue;
    }
    for (const auto& [outer, inner] : e.hexes)
      mesh.hexes.push_back({inner[0], inner[1], inner[2], inner[3], outer[0], outer[1], outer[2], outer[3]});
  }
  if (std::count(kind.begin(), kind.end(), SheetKind::kInternal) > 0) {
    std::vector<char> used(mesh.vertices.size(), 0);
    for (const auto& hex : mesh.hexes)
      for (int v : hex) used[v] = 1;
    std::vector<int> id(mesh.vertices.size(), -1);
    std::vector<Vec3> kept;
    for (std::size_t v = 0; v < mesh.vertices.size(); ++v)
      if (used[v] || static_cast<int>(v) < scheme.input_vertices) {
        id[v] = static_cast<int>(kept.size());
        kept.push_back(mesh.vertices[v]);
      }
    for (auto& hex : mesh.hexes)
      for (int& v : hex) v = id[v];
    mesh.vertices = std::move(kept);
  }
  if (kinds) *kinds = std::move(kind);
  return mesh;
}

namespace {

// Step 3: barycentric smoothing and the optimizer, with the first n vertices (the boundary) fixed.
OptimizeReport embed(HexMesh& mesh, int n, const SheetMeshOptions& options) {
  std::vector<char> interior(mesh.vertices.size(), 0), fixed(mesh.vertices.size(), 0);
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) (static_cast<int>(v) < n ? fixed : interior)[v] = 1;
  barycentric_smoothing(mesh, interior, options.smoothing_iterations);
  return options.optimize ? optimize_hex_mesh(mesh, nullptr, fixed, options.optimizer) : OptimizeReport{};
}

using Edge = std::array<int, 2>;

Edge edge_of(int a, int b) {
  return {std::min(a, b), std::max(a, b)};
}

// Whether the edges that both part complexes have between the disk's vertices are exactly the disk's
// edges (part vertex ids as in PrimalCycleSplit::ids; n: the vertices of the split surface).
bool meet_in_disk(const std::array<HexMesh, 2>& parts, const PrimalCycleSplit& split, int n) {
  auto on_disk = [&](int v) {
    return v >= n ? v < n + split.disk_vertices : std::count(split.cycle.begin(), split.cycle.end(), v) > 0;
  };
  static constexpr int kHexEdges[12][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6},
                                           {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
  std::array<std::vector<Edge>, 2> edges;
  for (int s = 0; s < 2; ++s) {
    const std::vector<int>& id = split.ids[s];
    for (const auto& hex : parts[s].hexes)
      for (const auto& e : kHexEdges) {
        const int a = hex[e[0]], b = hex[e[1]];
        if (a < static_cast<int>(id.size()) && b < static_cast<int>(id.size()) && on_disk(id[a]) &&
            on_disk(id[b]))
          edges[s].push_back(edge_of(id[a], id[b]));
      }
    std::sort(edges[s].begin(), edges[s].end());
    edges[s].erase(std::unique(edges[s].begin(), edges[s].end()), edges[s].end());
  }
  std::vector<Edge> common, disk;
  std::set_intersection(edges[0].begin(), edges[0].end(), edges[1].begin(), edges[1].end(),
                        std::back_inserter(common));
  for (const auto& q : split.disk)
    for (int k = 0; k < 4; ++k) disk.push_back(edge_of(q[k], q[(k + 1) % 4]));
  std::sort(disk.begin(), disk.end());
  disk.erase(std::unique(disk.begin(), disk.end()), disk.end());
  return common == disk;
}

// Where the inner copies of a pillow layer start (hex_pillow.h): a start for the embedding only.
constexpr double kPillowInset = 0.4;

// Steps 1 and 2 for `surface`, decomposing it along a primal cycle when the elimination is stuck (depth:
// the nesting of the decomposition that made it; parts are decomposed again while it is below max_depth).
// Splits whose parts mesh with less nesting come first: the search runs with the parts' nesting limited to
// depth + 1, then depth + 2, ... max_depth. Adds the counts of eliminations, sheets and decompositions to
// `counts`. The result's vertices 0..n-1 are the surface's.
// The chosen order, and where it runs into a dead end the look-ahead order (which avoids dead ends) before a
// decomposition: on the edentulous built-in mandible the geometric order got stuck after 89 eliminations and
// the decomposition gave 4,157 hexes of SJ 0.247 / 0.805, where the look-ahead order completes with 2,477
// hexes of 0.543 / 0.881 (docs/sheets.md). Throws the chosen order's RunError when both are stuck.
EliminationScheme eliminate_or_look_ahead(const QuadSurface& surface, const EliminationOptions& options,
                                          SheetMeshReport& counts) {
  try {
    return eliminate_chords(surface, options);
  } catch (const RunError&) {
    if (options.order == EliminationOrder::kLookAhead || !options.look_ahead_after_dead_end) throw;
    EliminationOptions look_ahead = options;
    look_ahead.order = EliminationOrder::kLookAhead;
    try {
      EliminationScheme scheme = eliminate_chords(surface, look_ahead);
      ++counts.look_ahead_fallbacks;
      return scheme;
    } catch (const RunError&) {
    }
    throw;
  }
}

HexMesh sheet_complex(const QuadSurface& surface, const SheetMeshOptions& options, int depth, int max_depth,
                      SheetMeshReport& counts) {
  EliminationScheme scheme;
  try {
    scheme = eliminate_or_look_ahead(surface, options.elimination, counts);
  } catch (const RunError& stuck) {
    if (depth >= max_depth) throw;
    const int n = static_cast<int>(surface.vertices.size());
    HexMesh glued;
    DecompositionSearch search;
    for (int limit = depth + 1; limit <= max_depth && !search.accepted; ++limit)
      search = search_primal_cycle_splits(surface, options.decomposition, [&](const PrimalCycleSplit& split) {
        std::array<HexMesh, 2> parts;
        SheetMeshReport part_counts;
        try {
          for (int s = 0; s < 2; ++s)
            parts[s] = sheet_complex(split.parts[s], options, depth + 1, limit, part_counts);
        } catch (const RunError&) {
          return false;
        }
        // A pillow layer under each part (its side's quads and the disk): no hex of the parts' complexes
        // keeps a face on the boundary or on the disk, and the parts meet in the disk's quads only. Without
        // it they may meet only in the disk: an edge of both between two disk vertices that is no disk edge
        // (possible where the parts' elimination connected cycle vertices) would not be conforming.
        if (options.decomposition.pillow_parts) {
          for (int s = 0; s < 2; ++s) pillow_quad_boundary(parts[s], split.parts[s], kPillowInset);
        } else if (!meet_in_disk(parts, split, n)) {
          return false;
        }
        // The surface's vertices, the disk's, then the parts' interior vertices part by part.
        glued.vertices = surface.vertices;
        glued.vertices.insert(glued.vertices.end(), split.disk_positions.begin(), split.disk_positions.end());
        for (int s = 0; s < 2; ++s) {
          std::vector<int> id = split.ids[s];
          const int k = static_cast<int>(id.size());
          for (int v = k; v < static_cast<int>(parts[s].vertices.size()); ++v) {
            id.push_back(static_cast<int>(glued.vertices.size()));
            glued.vertices.push_back(parts[s].vertices[v]);
          }
          for (auto hex : parts[s].hexes) {
            for (int& v : hex) v = id[v];
            glued.hexes.push_back(hex);
          }
        }
        counts.eliminations_single += part_counts.eliminations_single;
        counts.eliminations_k_step += part_counts.eliminations_k_step;
        counts.chords_eliminated += part_counts.chords_eliminated;
        counts.external_sheets += part_counts.external_sheets;
        counts.internal_sheets += part_counts.internal_sheets;
        counts.decompositions += part_counts.decompositions + 1;
        counts.look_ahead_fallbacks += part_counts.look_ahead_fallbacks;
        return true;
      });
    if (search.accepted) return glued;
    std::string message = stuck.what();
    const std::string advice = kStuckAdvice;
    if (message.size() >= advice.size() &&
        message.compare(message.size() - advice.size(), advice.size(), advice) == 0)
      message.resize(message.size() - advice.size());
    throw RunError(message + ". Decomposition along a primal cycle did not help either: " +
                   std::to_string(search.cycles) + " primal cycles of even length up to " +
                   std::to_string(options.decomposition.max_cycle_length) + " gave " +
                   std::to_string(search.splits) +
                   " splits into two usable balls (a side plus an internal quad disk)" +
                   (search.splits ? ", none with two parts that could be meshed (nesting depth " +
                                        std::to_string(options.decomposition.max_depth) + ")"
                                  : "") +
                   advice);
  }
  std::vector<SheetKind> kinds;
  HexMesh mesh = build_hex_complex(surface, scheme, options.internal_sheets, &kinds);
  for (std::size_t i = 0; i < kinds.size(); ++i) {
    const Elimination& e = scheme.eliminations[i];
    (e.chords > 1 ? counts.eliminations_k_step : counts.eliminations_single) += 1;
    (kinds[i] == SheetKind::kInternal ? counts.internal_sheets : counts.external_sheets) += 1;
    counts.chords_eliminated += e.chords;
  }
  return mesh;
}

// The surface with every quad's corners reversed when the quads face inward (the volume they enclose, each
// split along its 0-2 diagonal, is negative): the same solid, whose hexes would otherwise all be inverted.
QuadSurface facing_outward(const QuadSurface& surface) {
  QuadSurface out = surface;
  if (surface.vertices.empty()) return out;
  const Vec3& o = surface.vertices[0];
  double volume6 = 0;
  for (const Quad& q : surface.quads)
    for (int k : {1, 2})
      volume6 += vec3::dot(
          vec3::sub(surface.vertices[q[0]], o),
          vec3::cross(vec3::sub(surface.vertices[q[k]], o), vec3::sub(surface.vertices[q[k + 1]], o)));
  if (volume6 < 0)
    for (Quad& q : out.quads) std::reverse(q.begin(), q.end());
  return out;
}

}  // namespace

HexMesh mesh_by_cycle_elimination(const QuadSurface& input, const SheetMeshOptions& options,
                                  SheetMeshReport* report) {
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  const QuadSurface surface = facing_outward(input);
  // The embedding keeps the boundary where it is: a quad corner on one line with its neighbours, or a
  // reflex one, leaves every hex there with a corner Jacobian of 0 or below, so the elimination (up to
  // minutes) is not started.
  if (options.optimize)
    if (const std::string corner = non_convex_corners_problem(surface); !corner.empty())
      throw InputError(corner);
  SheetMeshReport counts;
  HexMesh mesh = sheet_complex(surface, options, 0, options.decomposition.max_depth, counts);
  const auto t1 = Clock::now();
  const int n = static_cast<int>(surface.vertices.size());
  OptimizeReport opt = embed(mesh, n, options);
  QualitySummary quality = summarize_quality(mesh);
  const int inverted_without_pillow = quality.inverted;
  int pillow_hexes = 0;
  if (options.optimize && options.pillow_if_inverted && quality.inverted > 0) {
    HexMesh pillowed = mesh;
    const int added = pillow_quad_boundary(pillowed, surface, kPillowInset);
    OptimizeReport pillowed_opt = embed(pillowed, n, options);
    QualitySummary pillowed_quality = summarize_quality(pillowed);
    if (pillowed_quality.inverted < quality.inverted) {
      mesh = std::move(pillowed);
      opt = std::move(pillowed_opt);
      quality = std::move(pillowed_quality);
      pillow_hexes = added;
    }
  }
  const auto t2 = Clock::now();
  if (report) {
    SheetMeshReport& r = *report;
    r = counts;
    r.quads = static_cast<int>(surface.quads.size());
    r.chords = static_cast<int>(find_chords(surface.quads, build_quad_edges(surface.quads)).size());
    r.eliminations = r.eliminations_single + r.eliminations_k_step;
    r.hexes = static_cast<int>(mesh.hexes.size());
    r.interior_vertices = static_cast<int>(mesh.vertices.size()) - n;
    r.order = options.elimination.order;
    r.seconds_elimination = std::chrono::duration<double>(t1 - t0).count();
    r.seconds_embedding = std::chrono::duration<double>(t2 - t1).count();
    r.optimize = std::move(opt);
    r.quality = std::move(quality);
    r.pillow_hexes = pillow_hexes;
    r.inverted_without_pillow = inverted_without_pillow;
  }
  return mesh;
}

}  // namespace hexbite
