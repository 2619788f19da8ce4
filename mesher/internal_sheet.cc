#include "mesher/internal_sheet.h"

#include <algorithm>
#include <numeric>
#include <tuple>

#include "mesher/hex_boundary.h"

namespace hexbite {

namespace {

using Quad = std::array<int, 4>;
using Edge = std::array<int, 2>;

Quad sorted(Quad q) {
  std::sort(q.begin(), q.end());
  return q;
}

Edge edge(int a, int b) {
  return {std::min(a, b), std::max(a, b)};
}

}  // namespace

bool insert_internal_sheet(HexMesh& mesh, const std::vector<std::array<std::array<int, 4>, 2>>& side,
                           int first_created, int created) {
  const int nh = static_cast<int>(mesh.hexes.size());
  auto is_created = [&](int v) { return v >= first_created && v < first_created + created; };
  std::vector<Quad> inner;
  for (const auto& pair : side) inner.push_back(sorted(pair[1]));
  std::sort(inner.begin(), inner.end());
  // Faces: sorted corner ids -> (hex, local face).
  struct Face {
    Quad key;
    int hex, local;
  };
  std::vector<Face> faces;
  faces.reserve(6 * static_cast<std::size_t>(nh));
  // H: the hexes holding a created vertex or a face on an inner quad.
  std::vector<char> in_h(static_cast<std::size_t>(nh), 0);
  for (int h = 0; h < nh; ++h)
    for (int f = 0; f < 6; ++f) {
      Quad q;
      for (int k = 0; k < 4; ++k) {
        q[k] = mesh.hexes[h][kHexFaces[f][k]];
        if (is_created(q[k])) in_h[h] = 1;
      }
      faces.push_back({sorted(q), h, f});
      if (std::binary_search(inner.begin(), inner.end(), faces.back().key)) in_h[h] = 1;
    }
  std::sort(faces.begin(), faces.end(), [](const Face& a, const Face& b) {
    return std::tie(a.key, a.hex, a.local) < std::tie(b.key, b.hex, b.local);
  });
  std::vector<std::array<int, 2>> interface;  // (hex of H, local face) facing a hex outside H
  std::size_t h_boundary = 0;
  for (std::size_t i = 0; i < faces.size();) {
    std::size_t j = i;
    while (j < faces.size() && faces[j].key == faces[i].key) ++j;
    if (j - i > 2) return false;  // not conforming
    if (j - i == 1) {
      if (in_h[faces[i].hex]) {
        if (!std::binary_search(inner.begin(), inner.end(), faces[i].key)) return false;
        ++h_boundary;
      }
    } else if (in_h[faces[i].hex] != in_h[faces[i + 1].hex]) {
      const Face& f = in_h[faces[i].hex] ? faces[i] : faces[i + 1];
      interface.push_back({f.hex, f.local});
    }
    i = j;
  }
  if (h_boundary != inner.size() || interface.empty()) return false;

  // The interface must be a disk bounded by the rail.
  std::vector<Edge> rail;  // edges in exactly one inner quad
  for (const auto& pair : side)
    for (int k = 0; k < 4; ++k) rail.push_back(edge(pair[1][k], pair[1][(k + 1) % 4]));
  std::sort(rail.begin(), rail.end());
  {
    std::vector<Edge> once;
    for (std::size_t i = 0; i < rail.size();) {
      std::size_t j = i;
      while (j < rail.size() && rail[j] == rail[i]) ++j;
      if (j - i == 1) once.push_back(rail[i]);
      i = j;
    }
    rail = std::move(once);
  }
  std::vector<std::pair<Edge, int>> face_edges;  // (edge, interface face)
  std::vector<int> vertices;
  for (int f = 0; f < static_cast<int>(interface.size()); ++f) {
    const auto& hex = mesh.hexes[interface[f][0]];
    const int* local = kHexFaces[interface[f][1]];
    for (int k = 0; k < 4; ++k) {
      face_edges.push_back({edge(hex[local[k]], hex[local[(k + 1) % 4]]), f});
      vertices.push_back(hex[local[k]]);
    }
  }
  std::sort(face_edges.begin(), face_edges.end());
  std::sort(vertices.begin(), vertices.end());
  vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
  std::vector<int> component(interface.size());
  std::iota(component.begin(), component.end(), 0);
  auto find = [&](int x) {
    while (component[x] != x) x = component[x] = component[component[x]];
    return x;
  };
  std::vector<Edge> boundary;
  int edges = 0;
  for (std::size_t i = 0; i < face_edges.size();) {
    std::size_t j = i;
    while (j < face_edges.size() && face_edges[j].first == face_edges[i].first) ++j;
    if (j - i > 2) return false;
    if (j - i == 1) boundary.push_back(face_edges[i].first);
    if (j - i == 2) component[find(face_edges[i].second)] = find(face_edges[i + 1].second);
    ++edges;
    i = j;
  }
  if (boundary != rail) return false;
  if (static_cast<int>(vertices.size()) - edges + static_cast<int>(interface.size()) != 1) return false;
  for (std::size_t f = 1; f < interface.size(); ++f)
    if (find(static_cast<int>(f)) != find(0)) return false;

  // Names on H's side: the inner quads' vertices become the outer quads' (the rail moves onto the outer
  // rail, the created vertices back to the vertices they were split from); the other interface vertices
  // are duplicated.
  std::vector<std::pair<int, int>> rename;
  for (const auto& [outer, in] : side)
    for (int k = 0; k < 4; ++k) rename.push_back({in[k], outer[k]});
  std::sort(rename.begin(), rename.end());
  rename.erase(std::unique(rename.begin(), rename.end()), rename.end());
  for (std::size_t i = 1; i < rename.size(); ++i)
    if (rename[i].first == rename[i - 1].first) return false;  // inconsistent side
  for (int v : vertices) {
    const auto it = std::lower_bound(rename.begin(), rename.end(), std::make_pair(v, -1));
    if (it != rename.end() && it->first == v) continue;
    rename.push_back({v, static_cast<int>(mesh.vertices.size())});
    mesh.vertices.push_back(mesh.vertices[v]);
  }
  std::sort(rename.begin(), rename.end());
  auto on_h_side = [&](int v) {
    const auto it = std::lower_bound(rename.begin(), rename.end(), std::make_pair(v, -1));
    return it != rename.end() && it->first == v ? it->second : v;
  };
  // One hex per interface face: the face seen from H (reversed) at the bottom, named as outside H, and its
  // copy named as on H's side on top, so that the new hex lies between the others and H.
  for (const auto& [h, f] : interface) {
    const std::array<int, 8> hex = mesh.hexes[h];  // a copy: the loop appends to mesh.hexes
    std::array<int, 8> sheet_hex{};
    for (int k = 0; k < 4; ++k) {
      sheet_hex[k] = hex[kHexFaces[f][3 - k]];
      sheet_hex[k + 4] = on_h_side(sheet_hex[k]);
    }
    mesh.hexes.push_back(sheet_hex);
  }
  for (int h = 0; h < nh; ++h)
    if (in_h[h])
      for (int& v : mesh.hexes[h]) v = on_h_side(v);
  return true;
}

}  // namespace hexbite
