#include "mesher/hex_reorder.h"

#include <algorithm>
#include <boost/graph/adjacency_list.hpp>
#include <boost/graph/cuthill_mckee_ordering.hpp>
#include <limits>
#include <stdexcept>
#include <string>

#include "mesher/hex_boundary.h"

namespace hexbite {

namespace {

// Ascending old indices of the hexes that have a boundary face.
std::vector<int> boundary_hexes(const HexMesh& mesh) {
  std::vector<int> hexes;
  for (const auto& qf : extract_boundary(mesh).quad_face) hexes.push_back(qf[0]);
  std::sort(hexes.begin(), hexes.end());
  hexes.erase(std::unique(hexes.begin(), hexes.end()), hexes.end());
  return hexes;
}

// Face neighbours of every hex: neighbour[6 h + f] is the hex across local face f, or -1. Faces shared by
// more than two hexes (a non-manifold mesh) link the first two only; extract_boundary reports such meshes.
std::vector<int> face_neighbours(const HexMesh& mesh) {
  struct Face {
    std::array<int, 4> key;
    int slot;  // 6 h + f
    bool operator<(const Face& o) const { return key != o.key ? key < o.key : slot < o.slot; }
  };
  std::vector<Face> faces;
  faces.reserve(6 * mesh.hexes.size());
  for (int h = 0; h < static_cast<int>(mesh.hexes.size()); ++h)
    for (int f = 0; f < 6; ++f) {
      Face face;
      for (int k = 0; k < 4; ++k) face.key[k] = mesh.hexes[h][kHexFaces[f][k]];
      std::sort(face.key.begin(), face.key.end());
      face.slot = 6 * h + f;
      faces.push_back(face);
    }
  std::sort(faces.begin(), faces.end());
  std::vector<int> neighbour(faces.size(), -1);
  for (std::size_t i = 0; i + 1 < faces.size(); ++i)
    if (faces[i].key == faces[i + 1].key && neighbour[faces[i].slot] < 0 &&
        neighbour[faces[i + 1].slot] < 0) {
      neighbour[faces[i].slot] = faces[i + 1].slot / 6;
      neighbour[faces[i + 1].slot] = faces[i].slot / 6;
    }
  return neighbour;
}

// Applies the permutations: new hex i is old hex hex_order[i] with its corners renumbered.
HexMesh permuted(const HexMesh& mesh, const std::vector<int>& hex_order, const std::vector<int>& node_order) {
  std::vector<int> new_id(mesh.vertices.size());
  for (std::size_t i = 0; i < node_order.size(); ++i) new_id[node_order[i]] = static_cast<int>(i);
  HexMesh out;
  out.vertices.reserve(mesh.vertices.size());
  for (int v : node_order) out.vertices.push_back(mesh.vertices[v]);
  out.hexes.reserve(mesh.hexes.size());
  for (int h : hex_order) {
    std::array<int, 8> hex;
    for (int k = 0; k < 8; ++k) hex[k] = new_id[mesh.hexes[h][k]];
    out.hexes.push_back(hex);
  }
  return out;
}

// Nodes that no hex uses, ascending: they go last in every order.
std::vector<int> unused_nodes(const HexMesh& mesh) {
  std::vector<char> used(mesh.vertices.size(), 0);
  for (const auto& hex : mesh.hexes)
    for (int v : hex) used[v] = 1;
  std::vector<int> unused;
  for (int v = 0; v < static_cast<int>(mesh.vertices.size()); ++v)
    if (!used[v]) unused.push_back(v);
  return unused;
}

}  // namespace

AdjacencyProfile nodal_adjacency_profile(const HexMesh& mesh) {
  // Nodes are adjacent exactly when some hex holds both, so per node the farthest neighbour below it is the
  // smallest corner of one of its hexes, and the bandwidth is the largest id spread within one hex.
  std::vector<int> lowest(mesh.vertices.size());
  for (std::size_t v = 0; v < lowest.size(); ++v) lowest[v] = static_cast<int>(v);
  AdjacencyProfile p;
  for (const auto& hex : mesh.hexes) {
    const auto [lo, hi] = std::minmax_element(hex.begin(), hex.end());
    p.bandwidth = std::max<long long>(p.bandwidth, *hi - *lo);
    for (int v : hex) lowest[v] = std::min(lowest[v], *lo);
  }
  for (std::size_t v = 0; v < lowest.size(); ++v) p.profile += static_cast<long long>(v) - lowest[v];
  return p;
}

int nearest_boundary_hex(const HexMesh& mesh, const Vec3& point) {
  int best = -1;
  double best_d2 = std::numeric_limits<double>::infinity();
  for (int h : boundary_hexes(mesh)) {
    const Vec3 c = hex_centroid(mesh, h);
    const double d2 = (c[0] - point[0]) * (c[0] - point[0]) + (c[1] - point[1]) * (c[1] - point[1]) +
                      (c[2] - point[2]) * (c[2] - point[2]);
    if (d2 < best_d2) {
      best_d2 = d2;
      best = h;
    }
  }
  return best;
}

int smallest_x_boundary_hex(const HexMesh& mesh) {
  int best = -1;
  double best_x = std::numeric_limits<double>::infinity();
  for (int h : boundary_hexes(mesh)) {
    const double x = hex_centroid(mesh, h)[0];
    if (x < best_x) {
      best_x = x;
      best = h;
    }
  }
  return best;
}

ReorderResult reorder_breadth_first(const HexMesh& mesh, int start_hex) {
  const int nh = static_cast<int>(mesh.hexes.size());
  if (nh > 0 && (start_hex < 0 || start_hex >= nh))
    throw std::invalid_argument("reorder_breadth_first: start hex " + std::to_string(start_hex) +
                                " is not one of the " + std::to_string(nh) + " hexes");
  ReorderResult r;
  r.start_hex = nh > 0 ? start_hex : -1;
  r.before = nodal_adjacency_profile(mesh);

  const std::vector<int> neighbour = face_neighbours(mesh);
  std::vector<char> seen(nh, 0);
  r.hex_order.reserve(nh);
  // A plain queue over hex_order itself: hexes enter in the order they are first reached.
  auto visit_from = [&](int root) {
    std::size_t head = r.hex_order.size();
    seen[root] = 1;
    r.hex_order.push_back(root);
    while (head < r.hex_order.size()) {
      const int h = r.hex_order[head++];
      for (int f = 0; f < 6; ++f) {
        const int n = neighbour[6 * h + f];
        if (n >= 0 && !seen[n]) {
          seen[n] = 1;
          r.hex_order.push_back(n);
        }
      }
    }
  };
  if (nh > 0) visit_from(start_hex);
  for (int h = 0; h < nh; ++h)
    if (!seen[h]) visit_from(h);

  std::vector<char> numbered(mesh.vertices.size(), 0);
  r.node_order.reserve(mesh.vertices.size());
  for (int h : r.hex_order)
    for (int v : mesh.hexes[h])
      if (!numbered[v]) {
        numbered[v] = 1;
        r.node_order.push_back(v);
      }
  for (int v : unused_nodes(mesh)) r.node_order.push_back(v);

  r.mesh = permuted(mesh, r.hex_order, r.node_order);
  r.after = nodal_adjacency_profile(r.mesh);
  return r;
}

ReorderResult reorder_reverse_cuthill_mckee(const HexMesh& mesh) {
  ReorderResult r;
  r.before = nodal_adjacency_profile(mesh);
  const int nv = static_cast<int>(mesh.vertices.size());
  const int nh = static_cast<int>(mesh.hexes.size());

  // Node -> incident hexes (compressed rows), then each node's neighbours as the sorted union of the corners
  // of its hexes; every edge is added once, from its lower end.
  std::vector<int> start(nv + 1, 0);
  for (const auto& hex : mesh.hexes)
    for (int v : hex) ++start[v + 1];
  for (int v = 0; v < nv; ++v) start[v + 1] += start[v];
  std::vector<int> incident(start[nv]);
  std::vector<int> fill(start.begin(), start.end() - 1);
  for (int h = 0; h < nh; ++h)
    for (int v : mesh.hexes[h]) incident[fill[v]++] = h;

  using Graph = boost::adjacency_list<boost::vecS, boost::vecS, boost::undirectedS,
                                      boost::property<boost::vertex_color_t, boost::default_color_type,
                                                      boost::property<boost::vertex_degree_t, int>>>;
  Graph graph(nv);
  std::vector<int> around;
  for (int v = 0; v < nv; ++v) {
    around.clear();
    for (int i = start[v]; i < start[v + 1]; ++i)
      for (int u : mesh.hexes[incident[i]])
        if (u > v) around.push_back(u);
    std::sort(around.begin(), around.end());
    around.erase(std::unique(around.begin(), around.end()), around.end());
    for (int u : around) boost::add_edge(v, u, graph);
  }

  // Writing Cuthill-McKee's order backwards gives the reverse order. Nodes without hexes are isolated
  // components of their own; they are taken out here and appended at the end.
  std::vector<Graph::vertex_descriptor> order(nv);
  boost::cuthill_mckee_ordering(graph, order.rbegin(), boost::get(boost::vertex_color, graph),
                                boost::make_degree_map(graph));
  r.node_order.reserve(nv);
  for (auto v : order)
    if (start[v + 1] > start[v]) r.node_order.push_back(static_cast<int>(v));
  for (int v : unused_nodes(mesh)) r.node_order.push_back(v);

  std::vector<int> new_id(nv);
  for (int i = 0; i < nv; ++i) new_id[r.node_order[i]] = i;
  std::vector<int> key(nh);
  for (int h = 0; h < nh; ++h) {
    key[h] = nv;
    for (int v : mesh.hexes[h]) key[h] = std::min(key[h], new_id[v]);
  }
  r.hex_order.resize(nh);
  for (int h = 0; h < nh; ++h) r.hex_order[h] = h;
  std::stable_sort(r.hex_order.begin(), r.hex_order.end(), [&](int a, int b) { return key[a] < key[b]; });

  r.mesh = permuted(mesh, r.hex_order, r.node_order);
  r.after = nodal_adjacency_profile(r.mesh);
  return r;
}

}  // namespace hexbite
