#include "mesher/hex_refine.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "common/progress.h"
#include "mesher/hex_boundary.h"
#include "mesher/hex_quality_kernel.h"
#include "mesher/surface_projector.h"

namespace hexbite {

namespace {

// Reference-cube coordinates (0 or 1 per axis) of the VTK corners.
constexpr int kCorner[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                               {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};

// The 27 points of a hex's 3 x 3 x 3 refinement lattice, index a + 3 b + 9 c for a, b, c in {0, 1, 2}
// (twice the reference coordinate). A lattice coordinate of 1 is free (the point is a midpoint along that
// axis); 0 or 2 pins the axis. `corners` lists the hex corners whose average is the point: 1 for a corner,
// 2 for an edge midpoint, 4 for a face centre and 8 for the centre.
struct LatticePoint {
  int count = 0;
  int corners[8] = {};
};

struct Lattice {
  LatticePoint points[27];
  Lattice() {
    for (int i = 0; i < 27; ++i) {
      const int l[3] = {i % 3, (i / 3) % 3, i / 9};
      for (int k = 0; k < 8; ++k) {
        bool match = true;
        for (int a = 0; a < 3; ++a)
          if (l[a] != 1 && 2 * kCorner[k][a] != l[a]) match = false;
        if (match) points[i].corners[points[i].count++] = k;
      }
    }
  }
};

const Lattice& lattice() {
  static const Lattice l;
  return l;
}

template <std::size_t N>
std::array<int, N> lattice_key(const std::array<int, 8>& hex, const LatticePoint& p) {
  std::array<int, N> key;
  for (std::size_t k = 0; k < N; ++k) key[k] = hex[p.corners[k]];
  std::sort(key.begin(), key.end());
  return key;
}

template <typename Key>
int find_key(const std::vector<Key>& keys, const Key& key) {
  return static_cast<int>(std::lower_bound(keys.begin(), keys.end(), key) - keys.begin());
}

bool hex_inverted(const HexMesh& mesh, int h) {
  Vec3 x[8];
  for (int k = 0; k < 8; ++k) x[k] = mesh.vertices[mesh.hexes[h][k]];
  for (int k = 0; k < 8; ++k) {
    Vec3 a, b, c;
    hex_corner_columns(x, k, a, b, c);
    if (!(corner_jacobian(a, b, c) > 0.0)) return true;
  }
  return false;
}

double distance(const Vec3& a, const Vec3& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                   (a[2] - b[2]) * (a[2] - b[2]));
}

// Moves the new boundary nodes (ids >= first_new) onto the surface. A node of a hex that the projection
// inverted goes back halfway toward its parametric position, repeatedly; after kMaxHalvings halvings it
// sits at the parametric position, where the split hexes were valid (if their parent was), so the loop
// ends.
void project_new_boundary(HexMesh& mesh, int first_new, const SurfaceProjector& surface,
                          RefineLevelReport& report) {
  constexpr int kMaxHalvings = 6;
  const int nv = static_cast<int>(mesh.vertices.size());
  const std::vector<char> boundary = boundary_vertex_mask(mesh);
  std::vector<char> projected(nv, 0);
  std::vector<Vec3> parametric(nv), target(nv);
  std::vector<int> halvings(nv, 0);
  for (int v = first_new; v < nv; ++v) {
    if (!boundary[v]) continue;
    projected[v] = 1;
    parametric[v] = mesh.vertices[v];
    target[v] = surface.closest(mesh.vertices[v]).point;
    report.max_projection = std::max(report.max_projection, distance(parametric[v], target[v]));
    mesh.vertices[v] = target[v];
    ++report.projected_nodes;
  }

  // Only hexes with a projected node can have changed.
  std::vector<int> check;
  for (int h = 0; h < static_cast<int>(mesh.hexes.size()); ++h)
    for (int v : mesh.hexes[h])
      if (projected[v]) {
        check.push_back(h);
        break;
      }
  while (!check.empty()) {
    std::vector<char> back_off(nv, 0);
    std::vector<int> still;
    for (int h : check) {
      if (!hex_inverted(mesh, h)) continue;
      bool can_move = false;
      for (int v : mesh.hexes[h])
        if (projected[v] && halvings[v] <= kMaxHalvings) {
          back_off[v] = 1;
          can_move = true;
        }
      if (can_move) still.push_back(h);
    }
    if (still.empty()) break;
    for (int v = first_new; v < nv; ++v) {
      if (!back_off[v]) continue;
      ++halvings[v];
      const double t = halvings[v] > kMaxHalvings ? 0.0 : std::ldexp(1.0, -halvings[v]);
      for (int a = 0; a < 3; ++a)
        mesh.vertices[v][a] = parametric[v][a] + t * (target[v][a] - parametric[v][a]);
    }
    // Backing a node off changes every hex around it, not only the inverted one that asked for it.
    check.clear();
    for (int h = 0; h < static_cast<int>(mesh.hexes.size()); ++h)
      for (int v : mesh.hexes[h])
        if (back_off[v]) {
          check.push_back(h);
          break;
        }
  }
  for (int v = first_new; v < nv; ++v)
    if (projected[v] && halvings[v] > 0) ++report.backed_off_nodes;
}

// Hexes that the projection inverted or whose scaled Jacobian fell by more than the fraction `damage` of its
// value after the split, and hexes holding a node that had to back off.
std::vector<char> damaged_hexes(const HexMesh& mesh, const HexQualityField& split, double damage,
                                int* count) {
  const HexQualityField now = compute_hex_quality(mesh);
  std::vector<char> damaged(mesh.hexes.size(), 0);
  *count = 0;
  for (std::size_t h = 0; h < mesh.hexes.size(); ++h) {
    const double before = split.scaled_jacobian[h], after = now.scaled_jacobian[h];
    if (!(now.jacobian[h] > 0.0) || after < before - damage * std::fabs(before)) {
      damaged[h] = 1;
      ++*count;
    }
  }
  return damaged;
}

// Runs the optimizer on the damaged hexes grown by `rings` layers of hexes (sharing a node), as a submesh of
// its own: nodes that the region shares with the hexes outside it stay fixed, so the rest of the mesh is
// untouched and each objective evaluation costs the region's size, not the mesh's. Returns the region size.
int optimize_region(HexMesh& mesh, std::vector<char> region, int rings, const std::vector<char>& fixed,
                    const SurfaceProjector& surface, const OptimizeOptions& options, OptimizeReport* report) {
  const std::size_t nv = mesh.vertices.size(), nh = mesh.hexes.size();
  for (int ring = 0; ring < rings; ++ring) {
    std::vector<char> touched(nv, 0);
    for (std::size_t h = 0; h < nh; ++h)
      if (region[h])
        for (int v : mesh.hexes[h]) touched[v] = 1;
    for (std::size_t h = 0; h < nh; ++h)
      for (int v : mesh.hexes[h])
        if (touched[v]) region[h] = 1;
  }
  std::vector<char> inside(nv, 0), outside(nv, 0);
  for (std::size_t h = 0; h < nh; ++h)
    for (int v : mesh.hexes[h]) (region[h] ? inside : outside)[v] = 1;

  HexMesh sub;
  std::vector<int> local(nv, -1), global;
  std::vector<char> sub_fixed;
  for (std::size_t v = 0; v < nv; ++v)
    if (inside[v]) {
      local[v] = static_cast<int>(global.size());
      global.push_back(static_cast<int>(v));
      sub.vertices.push_back(mesh.vertices[v]);
      sub_fixed.push_back(fixed[v] || outside[v]);
    }
  for (std::size_t h = 0; h < nh; ++h)
    if (region[h]) {
      std::array<int, 8> hex;
      for (int k = 0; k < 8; ++k) hex[k] = local[mesh.hexes[h][k]];
      sub.hexes.push_back(hex);
    }
  *report = optimize_hex_mesh(sub, &surface, sub_fixed, options);
  for (std::size_t i = 0; i < global.size(); ++i) mesh.vertices[global[i]] = sub.vertices[i];
  return static_cast<int>(sub.hexes.size());
}

}  // namespace

RefinementMap refinement_map(const HexMesh& coarse) {
  RefinementMap map;
  map.coarse_vertices = static_cast<int>(coarse.vertices.size());
  map.coarse_hexes = static_cast<int>(coarse.hexes.size());
  map.edges.reserve(12 * coarse.hexes.size());
  map.faces.reserve(6 * coarse.hexes.size());
  for (const auto& hex : coarse.hexes)
    for (const LatticePoint& p : lattice().points) {
      if (p.count == 2) map.edges.push_back(lattice_key<2>(hex, p));
      if (p.count == 4) map.faces.push_back(lattice_key<4>(hex, p));
    }
  std::sort(map.edges.begin(), map.edges.end());
  map.edges.erase(std::unique(map.edges.begin(), map.edges.end()), map.edges.end());
  std::sort(map.faces.begin(), map.faces.end());
  map.faces.erase(std::unique(map.faces.begin(), map.faces.end()), map.faces.end());
  return map;
}

std::array<std::array<int, 4>, 4> child_quads(const RefinementMap& map, const std::array<int, 4>& quad) {
  std::array<int, 4> key = quad;
  std::sort(key.begin(), key.end());
  const auto face = std::lower_bound(map.faces.begin(), map.faces.end(), key);
  if (face == map.faces.end() || *face != key)
    throw std::invalid_argument("child_quads: the quad is no face of the coarse mesh");
  const int centre =
      map.coarse_vertices + static_cast<int>(map.edges.size()) + static_cast<int>(face - map.faces.begin());
  std::array<int, 4> mid;  // mid[k]: the midpoint of the edge from corner k to corner k + 1
  for (int k = 0; k < 4; ++k) {
    const int a = quad[k], b = quad[(k + 1) % 4];
    const std::array<int, 2> edge{std::min(a, b), std::max(a, b)};
    mid[k] = map.coarse_vertices + find_key(map.edges, edge);
  }
  std::array<std::array<int, 4>, 4> children;
  for (int k = 0; k < 4; ++k) children[k] = {quad[k], mid[k], centre, mid[(k + 3) % 4]};
  return children;
}

HexMesh refine_uniform(const HexMesh& coarse, RefinementMap* map_out) {
  const Lattice& L = lattice();
  const int nv = static_cast<int>(coarse.vertices.size());
  const int nh = static_cast<int>(coarse.hexes.size());

  RefinementMap map = refinement_map(coarse);
  const int first_face = nv + static_cast<int>(map.edges.size());
  const int first_cell = first_face + static_cast<int>(map.faces.size());

  // New points are averages of coarse corners: the trilinear map of each hex evaluated at the lattice points,
  // so the children exactly tile their parent and neighbours agree on shared edges and faces.
  HexMesh fine;
  fine.vertices.resize(static_cast<std::size_t>(first_cell) + nh);
  std::copy(coarse.vertices.begin(), coarse.vertices.end(), fine.vertices.begin());
  auto average = [&](const int* ids, int count) {
    Vec3 s{0.0, 0.0, 0.0};
    for (int k = 0; k < count; ++k)
      for (int a = 0; a < 3; ++a) s[a] += coarse.vertices[ids[k]][a];
    for (int a = 0; a < 3; ++a) s[a] /= count;
    return s;
  };
  for (std::size_t i = 0; i < map.edges.size(); ++i) fine.vertices[nv + i] = average(map.edges[i].data(), 2);
  for (std::size_t j = 0; j < map.faces.size(); ++j)
    fine.vertices[first_face + j] = average(map.faces[j].data(), 4);

  fine.hexes.resize(8 * static_cast<std::size_t>(nh));
  for (int h = 0; h < nh; ++h) {
    const std::array<int, 8>& hex = coarse.hexes[h];
    fine.vertices[first_cell + h] = average(hex.data(), 8);
    int node[27];
    for (int i = 0; i < 27; ++i) {
      const LatticePoint& p = L.points[i];
      switch (p.count) {
        case 1:
          node[i] = hex[p.corners[0]];
          break;
        case 2:
          node[i] = nv + find_key(map.edges, lattice_key<2>(hex, p));
          break;
        case 4:
          node[i] = first_face + find_key(map.faces, lattice_key<4>(hex, p));
          break;
        default:
          node[i] = first_cell + h;
      }
    }
    // Child c spans lattice cells from corner c toward the centre, with its corners in the parent's VTK
    // order, so it has the parent's orientation.
    for (int c = 0; c < 8; ++c) {
      std::array<int, 8>& child = fine.hexes[8 * static_cast<std::size_t>(h) + c];
      for (int k = 0; k < 8; ++k) {
        const int a = kCorner[c][0] + kCorner[k][0], b = kCorner[c][1] + kCorner[k][1],
                  d = kCorner[c][2] + kCorner[k][2];
        child[k] = node[a + 3 * b + 9 * d];
      }
    }
  }
  if (map_out) *map_out = std::move(map);
  return fine;
}

HexMesh refine_to_surface(const HexMesh& coarse, const SurfaceProjector* surface,
                          const RefineOptions& options, RefineReport* report_out) {
  const auto t_start = std::chrono::steady_clock::now();
  RefineReport report;
  report.before = summarize_quality(coarse);
  const int original_vertices = static_cast<int>(coarse.vertices.size());

  HexMesh mesh = coarse;
  for (int level = 0; level < options.levels; ++level) {
    RefineLevelReport lr;
    auto t0 = std::chrono::steady_clock::now();
    RefinementMap map;
    mesh = refine_uniform(mesh, &map);
    lr.seconds_split = seconds_since(t0);
    lr.hexes = static_cast<int>(mesh.hexes.size());
    lr.nodes = static_cast<int>(mesh.vertices.size());
    lr.parametric = summarize_quality(mesh);
    if (surface == nullptr) {
      lr.projected = lr.parametric;
      lr.final_quality = lr.parametric;
      report.levels.push_back(std::move(lr));
      continue;
    }

    t0 = std::chrono::steady_clock::now();
    const HexQualityField split_quality = compute_hex_quality(mesh);
    project_new_boundary(mesh, map.coarse_vertices, *surface, lr);
    lr.projected = summarize_quality(mesh);
    lr.seconds_project = seconds_since(t0);

    const std::vector<char> damaged = damaged_hexes(mesh, split_quality, options.damage, &lr.damaged_hexes);
    if (options.optimize && (lr.damaged_hexes > 0 || lr.backed_off_nodes > 0)) {
      t0 = std::chrono::steady_clock::now();
      std::vector<char> fixed(mesh.vertices.size(), 0);
      if (options.keep_coarse_vertices) std::fill(fixed.begin(), fixed.begin() + original_vertices, 1);
      lr.optimized_hexes = optimize_region(mesh, damaged, options.optimize_rings, fixed, *surface,
                                           options.optimizer, &lr.optimize);
      lr.optimized = true;
      lr.seconds_optimize = seconds_since(t0);
    }

    // Refinement-created boundary nodes of every level so far: all of them should be on the surface.
    const std::vector<char> boundary = boundary_vertex_mask(mesh);
    for (int v = original_vertices; v < static_cast<int>(mesh.vertices.size()); ++v)
      if (boundary[v]) {
        const double d = surface->distance(mesh.vertices[v]);
        lr.max_surface_distance = std::max(lr.max_surface_distance, d);
        if (d > 1e-6) ++lr.off_surface_nodes;
      }
    lr.final_quality = summarize_quality(mesh);
    report.levels.push_back(std::move(lr));
  }
  report.after = report.levels.empty() ? report.before : report.levels.back().final_quality;
  if (options.fit_volume && surface != nullptr && report.after.inverted == 0) {
    std::vector<char> fixed(mesh.vertices.size(), 0);
    std::fill(fixed.begin(), fixed.begin() + original_vertices, 1);
    report.volume_fit = fit_boundary_to_volume(mesh, *surface, fixed);
    report.after = summarize_quality(mesh);
  }
  report.seconds_total = seconds_since(t_start);
  if (report_out) *report_out = std::move(report);
  return mesh;
}

}  // namespace hexbite
