#include "mesher/hex_boundary.h"

#include <algorithm>
#include <sstream>

#include "common/error.h"

namespace hexbite {

namespace {

// One face of one hex, keyed by its sorted vertex ids so that the two copies of an interior face meet
// when the list is sorted.
struct FaceRecord {
  std::array<int, 4> key;
  int hex;
  int face;
  bool operator<(const FaceRecord& o) const {
    if (key != o.key) return key < o.key;
    if (hex != o.hex) return hex < o.hex;
    return face < o.face;
  }
};

std::vector<FaceRecord> sorted_faces(const HexMesh& mesh) {
  std::vector<FaceRecord> faces;
  faces.reserve(mesh.hexes.size() * 6);
  for (int h = 0; h < static_cast<int>(mesh.hexes.size()); ++h) {
    for (int f = 0; f < 6; ++f) {
      FaceRecord r;
      for (int k = 0; k < 4; ++k) r.key[k] = mesh.hexes[h][kHexFaces[f][k]];
      std::sort(r.key.begin(), r.key.end());
      r.hex = h;
      r.face = f;
      faces.push_back(r);
    }
  }
  std::sort(faces.begin(), faces.end());
  return faces;
}

// Calls visit(first, count) for each run of equal keys in the sorted face list.
template <typename Visit>
void for_each_face_group(const std::vector<FaceRecord>& faces, Visit visit) {
  std::size_t i = 0;
  while (i < faces.size()) {
    std::size_t j = i + 1;
    while (j < faces.size() && faces[j].key == faces[i].key) ++j;
    visit(i, j - i);
    i = j;
  }
}

}  // namespace

HexBoundary extract_boundary(const HexMesh& mesh) {
  const std::vector<FaceRecord> faces = sorted_faces(mesh);
  HexBoundary b;
  std::vector<int> surface_index(mesh.vertices.size(), -1);
  // Boundary faces are collected in sorted-key order first; quads are emitted in (hex, face) order below so
  // that the surface follows the mesh's element order, which keeps it stable under unrelated edits.
  std::vector<std::array<int, 2>> boundary_faces;
  for_each_face_group(faces, [&](std::size_t first, std::size_t count) {
    if (count == 1) {
      boundary_faces.push_back({faces[first].hex, faces[first].face});
      for (int v : faces[first].key) surface_index[v] = 0;
    } else if (count > 2) {
      std::ostringstream msg;
      msg << "the hex mesh is not a manifold: the face with vertices " << faces[first].key[0] << ", "
          << faces[first].key[1] << ", " << faces[first].key[2] << ", " << faces[first].key[3]
          << " is shared by " << count << " hexes (";
      for (std::size_t k = 0; k < count; ++k) msg << (k ? ", " : "") << faces[first + k].hex;
      msg << "); a face may belong to at most two hexes";
      throw InputError(msg.str());
    }
  });
  std::sort(boundary_faces.begin(), boundary_faces.end());

  for (int v = 0; v < static_cast<int>(mesh.vertices.size()); ++v) {
    if (surface_index[v] < 0) continue;
    surface_index[v] = static_cast<int>(b.boundary_vertices.size());
    b.boundary_vertices.push_back(v);
    b.surface.vertices.push_back(mesh.vertices[v]);
  }
  b.surface.quads.reserve(boundary_faces.size());
  b.quad_face = boundary_faces;
  for (const auto& [h, f] : boundary_faces) {
    std::array<int, 4> quad;
    for (int k = 0; k < 4; ++k) quad[k] = surface_index[mesh.hexes[h][kHexFaces[f][k]]];
    b.surface.quads.push_back(quad);
  }
  return b;
}

std::vector<char> boundary_vertex_mask(const HexMesh& mesh) {
  const std::vector<FaceRecord> faces = sorted_faces(mesh);
  std::vector<char> mask(mesh.vertices.size(), 0);
  for_each_face_group(faces, [&](std::size_t first, std::size_t count) {
    if (count == 1)
      for (int v : faces[first].key) mask[v] = 1;
  });
  return mask;
}

TriSurface fan_triangles(const QuadSurface& quads) {
  TriSurface t;
  t.vertices = quads.vertices;
  for (const auto& quad : quads.quads) {
    const int centre = static_cast<int>(t.vertices.size());
    Vec3 c{0, 0, 0};
    for (int v : quad)
      for (int a = 0; a < 3; ++a) c[a] += 0.25 * quads.vertices[v][a];
    t.vertices.push_back(c);
    for (int k = 0; k < 4; ++k) t.triangles.push_back({quad[k], quad[(k + 1) % 4], centre});
  }
  return t;
}

}  // namespace hexbite
