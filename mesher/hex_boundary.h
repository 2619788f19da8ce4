// The boundary of a hex mesh: the quads used by exactly one hex, oriented outward.
//
// Input: a HexMesh (positively oriented hexes in VTK order, valid vertex indices).
// Output: the boundary quad surface (counter-clockwise seen from outside) on its own compacted vertices, the
// mesh vertex id of each surface vertex, and for each quad the hex and local face it comes from.
// Cost: sorts the 6 m hex faces, O(m log m) for m hexes; deterministic (no hashing).
#pragma once

#include <array>
#include <vector>

#include "mesher/hex_mesh.h"
#include "mesher/tri_surface.h"

namespace hexbite {

// Local faces of a VTK hexahedron, each counter-clockwise seen from outside a positively oriented hex:
// x = 0, x = 1, y = 0, y = 1, z = 0, z = 1 of the reference cube.
inline constexpr int kHexFaces[6][4] = {{0, 4, 7, 3}, {1, 2, 6, 5}, {0, 1, 5, 4},
                                        {3, 7, 6, 2}, {0, 3, 2, 1}, {4, 5, 6, 7}};

struct HexBoundary {
  QuadSurface surface;                        // vertices compacted to the boundary vertices
  std::vector<int> boundary_vertices;         // mesh vertex id of surface vertex i, ascending
  std::vector<std::array<int, 2>> quad_face;  // quad -> (hex index, local face 0..5 of kHexFaces)
};

// Throws InputError when a face is shared by more than two hexes (a non-manifold or non-conforming mesh),
// naming the face's vertices and the hexes that share it.
HexBoundary extract_boundary(const HexMesh& mesh);

// mask[v] != 0 when vertex v lies on a face used by exactly one hex. Never throws: faces used by more than
// two hexes are simply not boundary faces. Used by the quality summary to find the interior nodes.
std::vector<char> boundary_vertex_mask(const HexMesh& mesh);

// The quads as triangles for distance and inside queries: four per quad, fanned around its bilinear centre
// (the mean of its corners, vertex quads.vertices.size() + q for quad q); triangles 4q..4q+3 come from quad
// q.
TriSurface fan_triangles(const QuadSurface& quads);

}  // namespace hexbite
