// Combinatorial checks of a quad surface for the sheet mesher (definitions: ../shared/DESIGN.md section 3).
//
// Input: a QuadSurface (vertex ids in range; unused vertices are allowed and ignored by the graph measures).
// Output: a QuadSurfaceReport (closed, manifold, genus, even count, simple, planar, 3-connected, chords) and
// the reusable pieces: the edge table of a quad list, its chords, and graph tests.
// Definitions used here:
//   - An edge is an unordered vertex pair that is a side of some quad. The surface is closed when every edge
//     lies in at least two quads and manifold when no edge lies in more than two and the quads around every
//     vertex form a single fan.
//   - A chord (canonical dual cycle) is the cyclic sequence of quads obtained by entering a quad through one
//     edge and leaving it through the opposite edge. Every edge of a closed manifold surface lies on exactly
//     one chord; the chord's length is its number of quad crossings, which equals its number of edges. A
//     chord self-intersects when it crosses some quad twice (through both pairs of opposite edges).
//   - The surface's graph is simple when no quad repeats a vertex, no two quads share two or more edges and
//   no
//     two quads have the same vertices (a pair of vertices joined by two edges shows up as an edge in more
//     than two quads, which is reported as non-manifold). 3-connected means vertex connectivity >= 3.
// Cost: the edge table sorts 4 F entries, O(F log F); chords are linear; planarity is linear (Boyer-Myrvold);
// 3-connectivity removes each vertex in turn and looks for articulation points, O(V (V + E)).
// Deterministic: no hashing, fixed orders.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "mesher/hex_mesh.h"

namespace hexbite {

// The edges of a list of quads. quad_edges[q][k] is the edge of local side k, from corner k to corner
// (k + 1) % 4. edge_quads[e] lists (quad, local side) pairs, ascending by quad.
struct QuadEdges {
  std::vector<std::array<int, 2>> edges;  // (smaller vertex, larger vertex), ascending
  std::vector<std::array<int, 4>> quad_edges;
  std::vector<std::vector<std::array<int, 2>>> edge_quads;
};

QuadEdges build_quad_edges(const std::vector<std::array<int, 4>>& quads);

// Edge-connected components of the quads q for which in_set(q) holds, joined only across the edges e for
// which crossable(e) holds: component[q] = its number (numbered in the order of their lowest quad), -1 for
// quads outside the set. Returns the number of components. O(F).
template <class InSet, class Crossable>
int quad_components(const QuadEdges& qe, InSet in_set, Crossable crossable, std::vector<int>& component) {
  const int nq = static_cast<int>(qe.quad_edges.size());
  component.assign(static_cast<std::size_t>(nq), -1);
  int count = 0;
  std::vector<int> stack;
  for (int s = 0; s < nq; ++s) {
    if (component[s] >= 0 || !in_set(s)) continue;
    component[s] = count;
    stack.assign(1, s);
    while (!stack.empty()) {
      const int q = stack.back();
      stack.pop_back();
      for (int e : qe.quad_edges[q])
        if (crossable(e))
          for (const auto& [r, local] : qe.edge_quads[e])
            if (component[r] < 0 && in_set(r)) {
              component[r] = count;
              stack.push_back(r);
            }
    }
    ++count;
  }
  return count;
}

struct Chord {
  std::vector<int> quads;           // crossed quads in order (a quad crossed twice appears twice)
  std::vector<int> edges;           // edges[i] is where the chord enters quads[i]
  std::vector<int> repeated_quads;  // quads crossed twice, ascending; empty for a simple chord
  int length() const { return static_cast<int>(quads.size()); }
  bool simple() const { return repeated_quads.empty(); }
};

// The chords of a closed manifold quad list without degenerate quads (every edge in exactly two quads);
// numbered by their smallest edge, each starting there and entering the lower-numbered quad of that edge.
// Throws std::invalid_argument when an edge does not lie in exactly two quads.
std::vector<Chord> find_chords(const std::vector<std::array<int, 4>>& quads, const QuadEdges& edges);

// Graph tests on vertices 0..n-1 with the given undirected edges (no duplicates). Isolated vertices are
// ignored. The 3-connectivity test needs at least 4 non-isolated vertices; when it fails and `separator` is
// given, that gets the vertices (one or two) whose removal disconnects the graph (a vertex of degree below
// 3: its neighbours), or stays empty when the graph is too small or not connected at all.
bool is_planar_graph(int n, const std::vector<std::array<int, 2>>& edges);
bool is_three_connected(int n, const std::vector<std::array<int, 2>>& edges,
                        std::vector<int>* separator = nullptr);

struct QuadSurfaceReport {
  std::string file;
  int quads = 0;
  int vertices = 0;         // vertices used by quads
  int unused_vertices = 0;  // listed in the file but in no quad
  int edges = 0;
  int components = 0;  // edge-connected components of quads
  bool closed = false;
  int open_edges = 0;
  bool manifold = false;
  int non_manifold_edges = 0;
  int non_manifold_vertices = 0;
  bool consistently_oriented = false;
  int inconsistent_edges = 0;
  int euler_characteristic = 0;
  int genus = -1;     // -1 when undefined (open, non-manifold, non-orientable or several components)
  bool ball = false;  // closed, manifold, oriented, one component, genus 0
  bool even = false;
  bool simple = false;
  int degenerate_quads = 0;          // a quad with a repeated vertex
  int quad_pairs_sharing_edges = 0;  // pairs of quads sharing two or more edges
  int duplicate_quads = 0;           // quads with the same vertices as an earlier quad
  bool planar = false;
  bool three_connected = false;
  std::vector<int> separator;    // when not 3-connected: one or two vertices whose removal disconnects it
  bool chords_computed = false;  // only for closed manifold surfaces without degenerate quads
  std::vector<Chord> chords;
  std::vector<int> self_intersecting_chords;  // indices into chords
  std::vector<std::string> problems;          // everything that keeps the surface from bounding a sheet mesh
  bool usable() const { return problems.empty(); }
};

// Indices in the report's problems are 0-based (the OBJ's vertex k is vertex k - 1 here, its face k is quad
// k - 1), and each problem names its first place with coordinates. The problems are combinatorial (the
// elimination's conditions); non_convex_corners_problem() is the geometric one of an embedding that keeps
// the boundary.
QuadSurfaceReport check_quad_surface(const QuadSurface& surface, const std::string& file);

// The centre of quad q: the mean of its four corners.
Vec3 quad_centre(const QuadSurface& surface, int q);

// The quad corners that are not convex: collinear ones (the two neighbours on one line with the corner) and
// reflex ones (turning against the quad's normal, the cross product of its diagonals, which a bent quad has
// too, on a quad whose halves split along the diagonal through the corner bend by less than 60 degrees;
// a more bent quad is left to the embedding). A hex on such a quad has a corner Jacobian of
// 0 (collinear) or below 0 (reflex) there whatever the interior, so no valid hex mesh has this boundary.
// Empty when there is none, else a message naming the first corner of each kind (0-based, with
// coordinates) and how many there are.
std::string non_convex_corners_problem(const QuadSurface& surface);

}  // namespace hexbite
