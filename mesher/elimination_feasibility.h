// The graph test of a cycle elimination step (mesher/cycle_elimination.h), in near-linear time.
//
// Input: a list of quads (vertex ids, any range; quads counter-clockwise seen from outside).
// Output: whether the quads form the surface of a "polyhedral ball": a closed, edge-manifold, consistently
// oriented, connected surface of Euler characteristic 2 whose graph is simple, planar and 3-connected. This
// is exactly what check_quad_surface() (mesher/quad_check.h) calls ball && simple && planar &&
// three_connected, which the elimination asks of every surface it produces. Algorithm: the graph of a sphere
// map is planar, and a 2-connected plane graph is 3-connected if and only if any two of its facial cycles
// meet in nothing, one vertex or one edge (the planar case of the polyhedral-map characterization: a 2-cut
// {u, v} of a plane graph is a closed curve through u, v and two faces that both contain u and v; if the
// faces meet only in the edge uv, the curve encloses nothing but that edge). So:
//   1. every quad has four distinct vertices (every face is a 4-cycle), every vertex pair edge lies in
//      exactly two quads that traverse it in opposite directions (closed, oriented; a third quad would be a
//      parallel edge), the quads are edge-connected and V - E + F = 2. A pinched (non-manifold) vertex
//      would need V - E + F < 2, since splitting it keeps the surface connected, closed and oriented and so
//      its Euler characteristic at most 2; hence the surface is a sphere and the graph is 2-connected;
//   2. every two quads sharing a vertex share at most that vertex or exactly the two ends of a common edge
//      (this also rules out two quads with two common edges and duplicate quads: a non-simple graph).
// The old test (remove each vertex, search articulation points) cost O(V (V + E)); the tests of
// test_cycle_elimination.cc compare both on every candidate collapse of several surfaces.
// Why hand-written: Boost.Graph and LEMON test planarity or biconnectivity, but have no triconnectivity
// test (that would be an SPQR tree); on a sphere map the face criterion is simpler and local.
// Cost: O(F log F) for the edge table plus O(sum over vertices of degree^2); no hashing, deterministic.
#pragma once

#include <array>
#include <vector>

namespace hexbite {

bool is_polyhedral_ball(const std::vector<std::array<int, 4>>& quads);

}  // namespace hexbite
