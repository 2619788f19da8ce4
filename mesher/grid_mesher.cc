#include "mesher/grid_mesher.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <future>
#include <limits>
#include <memory>
#include <numeric>
#include <optional>
#include <queue>
#include <sstream>
#include <thread>
#include <tuple>
#include <utility>

#include "common/error.h"
#include "common/helper_threads.h"
#include "common/progress.h"
#include "mesher/arch_frame.h"
#include "mesher/cell_size_search.h"
#include "mesher/hex_boundary.h"
#include "mesher/hex_quality_kernel.h"
#include "mesher/principal_frame.h"
#include "mesher/surface_projector.h"
#include "mesher/swept_core.h"
#include "mesher/union_find.h"
#include "mesher/units.h"

namespace hexbite {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

using detail::cross;
using detail::dot;
using detail::sub;

using vec3::add;
using vec3::norm;
using vec3::scale;

// A body (an outer shell with its voids) that no grid component represents: no cell centre lies inside it
// at this cell size.
struct MissedBody {
  int body = -1;
  int cells = 0;  // cells of dropped components nearest to it
};

// Bodies that one core component holds: the gap between them is narrower than a cell, the mesh joins them.
struct JoinedBodies {
  std::vector<int> bodies;
  Vec3 contact{};  // centroid of the cells inside one body with a face neighbour inside another
};

// A regular grid of n[0] x n[1] x n[2] cubic cells of size h; cell (i, j, k) spans
// origin + h * [i, i+1] x [j, j+1] x [k, k+1]. The outermost layer of cells lies outside the surface's
// bounding box, so the unselected cells always surround the selected ones.
struct Grid {
  Vec3 origin{};
  double h = 1;
  std::array<int, 3> n{};

  long cells() const { return long(n[0]) * n[1] * n[2]; }
  long cell(int i, int j, int k) const { return (long(k) * n[1] + j) * n[0] + i; }
  void ijk(long c, int& i, int& j, int& k) const {
    i = int(c % n[0]);
    j = int((c / n[0]) % n[1]);
    k = int(c / (long(n[0]) * n[1]));
  }
  Vec3 centre(int i, int j, int k) const {
    return {origin[0] + (i + 0.5) * h, origin[1] + (j + 0.5) * h, origin[2] + (k + 0.5) * h};
  }
  long vertex(int i, int j, int k) const { return (long(k) * (n[1] + 1) + j) * (n[0] + 1) + i; }
};

// The surface's closed shells (triangles connected through shared vertices) grouped into bodies: each
// outer shell (positive enclosed volume) is a body, each inner shell (negative volume: a void) belongs to
// the body of the smallest outer shell around it. A fractured mandible has two bodies; a hollow solid one
// body with a void.
struct Shells {
  std::vector<int> shell_of_triangle;
  std::vector<int> body_of_shell;
  std::vector<char> inner;             // per shell: a void
  std::vector<Vec3> body_lo, body_hi;  // bounding box of each body's outer shell
  std::vector<long> body_triangles;    // triangles of each body's outer shell
  std::vector<long> shell_triangles;   // triangles of each shell
  int bodies = 0;
  bool any_inner = false;
  // Cells are labelled (body, void) only for several bodies or voids; a single shell meshes as before.
  bool labelled() const { return bodies > 1 || any_inner; }
};

// The winding number of a closed shell's triangles around p: 1 inside an outward oriented shell, 0 outside
// (the solid angles of its triangles over 4 pi).
double winding_number(const TriSurface& surface, const std::vector<int>& triangles, const Vec3& p) {
  double sum = 0;
  for (int t : triangles) {
    const Vec3 a = sub(surface.vertices[surface.triangles[t][0]], p);
    const Vec3 b = sub(surface.vertices[surface.triangles[t][1]], p);
    const Vec3 c = sub(surface.vertices[surface.triangles[t][2]], p);
    const double la = norm(a), lb = norm(b), lc = norm(c);
    sum += 2.0 *
           std::atan2(dot(a, cross(b, c)), la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la);
  }
  return sum / (4.0 * M_PI);
}

Shells find_shells(const TriSurface& surface) {
  Shells sh;
  const std::size_t nt = surface.triangles.size();
  UnionFind pieces(surface.vertices.size());
  for (const auto& tri : surface.triangles) pieces.unite(tri[0], tri[1]), pieces.unite(tri[0], tri[2]);
  std::vector<int> shell_of_root(surface.vertices.size(), -1);
  std::vector<std::vector<int>> members;
  sh.shell_of_triangle.resize(nt);
  for (std::size_t t = 0; t < nt; ++t) {
    int& shell = shell_of_root[pieces.find(surface.triangles[t][0])];
    if (shell < 0) shell = int(members.size()), members.emplace_back();
    members[shell].push_back(int(t));
    sh.shell_of_triangle[t] = shell;
  }
  const int n = int(members.size());
  // Six times each shell's enclosed volume (divergence theorem, as enclosed_volume).
  std::vector<double> volume(n, 0.0);
  for (int q = 0; q < n; ++q) {
    for (int t : members[q]) {
      const Vec3& a = surface.vertices[surface.triangles[t][0]];
      volume[q] +=
          dot(a, cross(surface.vertices[surface.triangles[t][1]], surface.vertices[surface.triangles[t][2]]));
    }
    sh.shell_triangles.push_back(long(members[q].size()));
  }
  sh.inner.assign(n, 0);
  sh.body_of_shell.assign(n, -1);
  std::vector<int> outer;
  for (int q = 0; q < n; ++q) {
    if (volume[q] < 0) {
      sh.inner[q] = 1, sh.any_inner = true;
      continue;
    }
    sh.body_of_shell[q] = sh.bodies++;
    outer.push_back(q);
    Vec3 lo{kInf, kInf, kInf}, hi{-kInf, -kInf, -kInf};
    for (int t : members[q])
      for (int v : surface.triangles[t])
        for (int a = 0; a < 3; ++a)
          lo[a] = std::min(lo[a], surface.vertices[v][a]), hi[a] = std::max(hi[a], surface.vertices[v][a]);
    sh.body_lo.push_back(lo);
    sh.body_hi.push_back(hi);
    sh.body_triangles.push_back(long(members[q].size()));
  }
  for (int q = 0; q < n; ++q) {
    if (!sh.inner[q]) continue;
    const Vec3& p = surface.vertices[surface.triangles[members[q][0]][0]];
    int around = -1;
    for (int o : outer)
      if (winding_number(surface, members[o], p) > 0.5 && (around < 0 || volume[o] < volume[around]))
        around = o;
    sh.body_of_shell[q] = around >= 0 ? sh.body_of_shell[around] : 0;
  }
  return sh;
}

// The selected cells for one cell size, with the data needed to repair and score them.
struct Selection {
  Grid grid;
  std::vector<char> inside;   // cell centre inside the surface
  std::vector<double> score;  // signed distance of the cell centre (positive inside); NaN = not computed
  std::vector<char> selected;
  // With several bodies or with voids (Shells::labelled): the body of each cell whose centre lies inside
  // the solid (-1 for the others), and whether a cell's centre lies in a void (inside an inner shell).
  std::vector<int> body;
  std::vector<char> in_void;
  int added_for_manifold = 0;
  int dropped = 0;  // cells of dropped fragments of a body that has its main component (narrow necks)
  Vec3 dropped_centroid{};
  std::vector<MissedBody> missed;    // bodies without a main component
  std::vector<JoinedBodies> joined;  // kept components that hold several bodies
  long core_cells = 0;
  long boundary_quads = 0;
};

double cell_score(Selection& s, const SurfaceProjector& surface, long c) {
  if (std::isnan(s.score[c])) {
    int i, j, k;
    s.grid.ijk(c, i, j, k);
    const double d = surface.distance(s.grid.centre(i, j, k));
    s.score[c] = s.inside[c] ? d : -d;
  }
  return s.score[c];
}

// True when the solid is thinner than `diameter` at the closest surface point of p: a ball of that diameter
// touching the surface there from inside does not fit (one closest-point and one distance query).
bool thinner_than(const SurfaceProjector& surface, const Vec3& p, double diameter) {
  const SurfacePoint foot = surface.closest(p);
  const double r = 0.5 * diameter;
  return surface.distance(sub(foot.point, scale(foot.normal, r))) < 0.99 * r;
}

// Face neighbours of a cell inside the grid, as cell indices (fewer at the grid's border).
int face_neighbours(const Grid& g, long c, long out[6]) {
  int i, j, k, m = 0;
  g.ijk(c, i, j, k);
  if (i > 0) out[m++] = c - 1;
  if (i + 1 < g.n[0]) out[m++] = c + 1;
  if (j > 0) out[m++] = c - g.n[0];
  if (j + 1 < g.n[1]) out[m++] = c + g.n[0];
  if (k > 0) out[m++] = c - long(g.n[0]) * g.n[1];
  if (k + 1 < g.n[2]) out[m++] = c + long(g.n[0]) * g.n[1];
  return m;
}

// Inside flags of all cell centres: crossing parity along each grid column, with a per-cell inside test
// where the column grazes an edge or a vertex of the surface.
// With several bodies or voids (Shells::labelled) also the body of each inside cell (the body of the
// last shell crossed below it: entering its outer shell or leaving one of its voids) and the void cells
// (outside the solid, inside an odd number of crossings of an inner shell below it); where the column
// grazes, the shell of the closest surface point decides.
void classify(Selection& s, const SurfaceProjector& surface, const Shells& shells) {
  const Grid& g = s.grid;
  s.inside.assign(g.cells(), 0);
  const bool labelled = shells.labelled();
  if (labelled) s.body.assign(g.cells(), -1), s.in_void.assign(g.cells(), 0);
  std::vector<int> parity(shells.inner.size(), 0);
  std::vector<double> t;
  std::vector<int> crossed;
  for (int j = 0; j < g.n[1]; ++j)
    for (int i = 0; i < g.n[0]; ++i) {
      const Vec3 c0 = g.centre(i, j, 0);
      const Vec3 a{c0[0], c0[1], g.origin[2] - g.h};
      const Vec3 b{c0[0], c0[1], g.origin[2] + (g.n[2] + 1) * g.h};
      const bool ok = surface.segment_crossings(a, b, &t, labelled ? &crossed : nullptr);
      std::size_t below = 0;  // labelled: crossings below the current cell centre, counted in `parity`
      int open_voids = 0;     // inner shells crossed an odd number of times below the centre
      for (int k = 0; k < g.n[2]; ++k) {
        const Vec3 c = g.centre(i, j, k);
        const long cell = g.cell(i, j, k);
        bool in;
        if (ok) {
          const double tc = (c[2] - a[2]) / (b[2] - a[2]);
          const std::size_t m = std::lower_bound(t.begin(), t.end(), tc) - t.begin();
          in = m % 2 == 1;
          if (labelled) {
            for (; below < m; ++below) {
              const int shell = shells.shell_of_triangle[crossed[below]];
              if (shells.inner[shell]) open_voids += (parity[shell] ^= 1) ? 1 : -1;
            }
            if (in && m > 0) s.body[cell] = shells.body_of_shell[shells.shell_of_triangle[crossed[m - 1]]];
            if (!in) s.in_void[cell] = open_voids > 0;
          }
        } else {
          in = surface.inside(c);
          if (labelled) {
            const int shell = shells.shell_of_triangle[surface.closest(c).triangle];
            if (in) s.body[cell] = shells.body_of_shell[shell];
            if (!in) s.in_void[cell] = shells.inner[shell];
          }
        }
        s.inside[cell] = in;
      }
      if (labelled)
        for (std::size_t q = 0; q < below; ++q) parity[shells.shell_of_triangle[crossed[q]]] = 0;
    }
}

// Selects the core cells: the cells whose centre lies at least margin * h inside the surface. A negative
// margin also takes cells whose centre lies outside but within -margin * h of the surface, that is cells
// that reach well into the solid: then a plate or a neck thinner than a cell keeps a sheet of cells (which
// the pillow layer pulls below the surface) instead of vanishing from the core. Distances are computed for
// the inside cells within a few cells of an outside cell when the margin is positive (deeper cells are far
// enough by construction), and, when it is negative, for the outside cells whose centre lies within
// -margin * h of a triangle's bounding box (the others cannot qualify). An outside cell whose centre lies
// farther out (or less deep inside) than thick_margin * h (when thick_margin > margin) is kept only where
// the solid is thinner than thin_cells cells: where a ball of diameter thin_cells * h touching the surface
// at the centre's closest point from inside does not fit in the solid.
void select_core(Selection& s, const SurfaceProjector& surface, double margin, double thick_margin,
                 double thin_cells) {
  const Grid& g = s.grid;
  const long nc = g.cells();
  s.score.assign(nc, std::numeric_limits<double>::quiet_NaN());
  const int reach = int(std::ceil(std::max({margin, thick_margin, 0.0}))) + 1;
  std::vector<char> near(nc, 0);
  for (long c = 0; c < nc; ++c) {
    if (s.inside[c]) continue;
    int i, j, k;
    g.ijk(c, i, j, k);
    for (int dk = -reach; dk <= reach; ++dk)
      for (int dj = -reach; dj <= reach; ++dj)
        for (int di = -reach; di <= reach; ++di) {
          const int a = i + di, b = j + dj, e = k + dk;
          if (a < 0 || b < 0 || e < 0 || a >= g.n[0] || b >= g.n[1] || e >= g.n[2]) continue;
          near[g.cell(a, b, e)] = 1;
        }
  }
  // For a negative margin, only the outside cells whose centre lies in the bounding box of a triangle
  // widened by -margin * h can be close enough: the others are skipped without a distance query.
  std::vector<char> candidate;
  if (margin < 0.0) {
    candidate.assign(nc, 0);
    const double r = -margin * g.h * (1.0 + 1e-9) + 1e-12 * g.h;
    const TriSurface& t = surface.surface();
    for (const auto& tri : t.triangles) {
      int from[3], to[3];
      for (int a = 0; a < 3; ++a) {
        double lo = kInf, hi = -kInf;
        for (int v : tri) lo = std::min(lo, t.vertices[v][a]), hi = std::max(hi, t.vertices[v][a]);
        from[a] = std::max(0, int(std::ceil((lo - r - g.origin[a]) / g.h - 0.5)));
        to[a] = std::min(g.n[a] - 1, int(std::floor((hi + r - g.origin[a]) / g.h - 0.5)));
      }
      for (int k = from[2]; k <= to[2]; ++k)
        for (int j = from[1]; j <= to[1]; ++j)
          for (int i = from[0]; i <= to[0]; ++i) candidate[g.cell(i, j, k)] = 1;
    }
  }
  s.selected.assign(nc, 0);
  for (long c = 0; c < nc; ++c) {
    if (!s.inside[c] && (margin >= 0.0 || !candidate[c])) continue;
    // Every inside cell qualifies for margins <= 0 (its distance is positive), without a distance query.
    if (s.inside[c] && margin <= 0.0 && thick_margin <= 0.0) {
      s.selected[c] = 1;
    } else if (!near[c]) {
      s.score[c] = kInf;
      s.selected[c] = 1;
    } else {
      const double score = cell_score(s, surface, c);
      s.selected[c] = score >= margin * g.h;
      if (s.selected[c] && score < thick_margin * g.h) {
        int i, j, k;
        g.ijk(c, i, j, k);
        s.selected[c] = thinner_than(surface, g.centre(i, j, k), thin_cells * g.h);
      }
    }
  }
}

// Keeps the largest face-connected component of the selected cells (the first one on a tie).
void keep_largest_component(Selection& s) {
  const Grid& g = s.grid;
  const long nc = g.cells();
  std::vector<int> label(nc, -1);
  std::vector<long> sizes;
  for (long c = 0; c < nc; ++c) {
    if (!s.selected[c] || label[c] >= 0) continue;
    const int id = int(sizes.size());
    long size = 0;
    std::vector<long> stack{c};
    label[c] = id;
    while (!stack.empty()) {
      const long x = stack.back();
      stack.pop_back();
      ++size;
      long nb[6];
      const int m = face_neighbours(g, x, nb);
      for (int q = 0; q < m; ++q)
        if (s.selected[nb[q]] && label[nb[q]] < 0) label[nb[q]] = id, stack.push_back(nb[q]);
    }
    sizes.push_back(size);
  }
  if (sizes.empty()) return;
  const int keep = int(std::max_element(sizes.begin(), sizes.end()) - sizes.begin());
  Vec3 sum{0, 0, 0};
  for (long c = 0; c < nc; ++c)
    if (s.selected[c] && label[c] != keep) {
      s.selected[c] = 0;
      ++s.dropped;
      int i, j, k;
      g.ijk(c, i, j, k);
      sum = add(sum, g.centre(i, j, k));
    }
  if (s.dropped > 0) s.dropped_centroid = scale(sum, 1.0 / s.dropped);
}

// Several bodies: keeps each body's main component, the face-connected component with the most cells
// whose centre lies inside that body (the first one on a tie). Dropped components with cells inside a
// body, or without inside cells and nearest to a represented body, are its fragments (narrow necks:
// dropped, dropped_centroid); a body without inside cells is missed (missed, with the cells of the
// components nearest to it); a kept component with cells inside several bodies joins them (joined).
void keep_main_components(Selection& s, const SurfaceProjector& surface, const Shells& shells) {
  const Grid& g = s.grid;
  const long nc = g.cells();
  std::vector<int> label(nc, -1);
  std::vector<long> first;                 // a cell of each component
  std::vector<std::vector<long>> in_body;  // per component: cells inside each body
  for (long c = 0; c < nc; ++c) {
    if (!s.selected[c] || label[c] >= 0) continue;
    const int id = int(first.size());
    first.push_back(c);
    in_body.emplace_back(shells.bodies, 0);
    std::vector<long> stack{c};
    label[c] = id;
    while (!stack.empty()) {
      const long x = stack.back();
      stack.pop_back();
      if (s.body[x] >= 0) ++in_body[id][s.body[x]];
      long nb[6];
      const int m = face_neighbours(g, x, nb);
      for (int q = 0; q < m; ++q)
        if (s.selected[nb[q]] && label[nb[q]] < 0) label[nb[q]] = id, stack.push_back(nb[q]);
    }
  }
  const int components = int(first.size());
  std::vector<char> keep(components, 0);
  std::vector<int> main_of(shells.bodies, -1);
  for (int b = 0; b < shells.bodies; ++b) {
    for (int id = 0; id < components; ++id)
      if (in_body[id][b] > 0 && (main_of[b] < 0 || in_body[id][b] > in_body[main_of[b]][b])) main_of[b] = id;
    if (main_of[b] >= 0) keep[main_of[b]] = 1;
  }
  // The body each dropped component belongs to: a body it has cells inside, else the body of the surface
  // point closest to one of its cells.
  std::vector<int> owner(components, -1);
  for (int id = 0; id < components; ++id) {
    if (keep[id]) continue;
    for (int b = 0; b < shells.bodies && owner[id] < 0; ++b)
      if (in_body[id][b] > 0) owner[id] = b;
    if (owner[id] < 0) {
      int i, j, k;
      g.ijk(first[id], i, j, k);
      owner[id] = shells.body_of_shell[shells.shell_of_triangle[surface.closest(g.centre(i, j, k)).triangle]];
    }
  }
  std::vector<int> missed_index(shells.bodies, -1);
  for (int b = 0; b < shells.bodies; ++b)
    if (main_of[b] < 0) {
      missed_index[b] = int(s.missed.size());
      s.missed.push_back({b, 0});
    }
  Vec3 sum{0, 0, 0};
  for (long c = 0; c < nc; ++c) {
    if (!s.selected[c] || keep[label[c]]) continue;
    s.selected[c] = 0;
    const int b = owner[label[c]];
    if (missed_index[b] >= 0) {
      ++s.missed[missed_index[b]].cells;
      continue;
    }
    ++s.dropped;
    int i, j, k;
    g.ijk(c, i, j, k);
    sum = add(sum, g.centre(i, j, k));
  }
  if (s.dropped > 0) s.dropped_centroid = scale(sum, 1.0 / s.dropped);
  for (int id = 0; id < components; ++id) {
    if (!keep[id]) continue;
    JoinedBodies joined;
    for (int b = 0; b < shells.bodies; ++b)
      if (in_body[id][b] > 0) joined.bodies.push_back(b);
    if (joined.bodies.size() < 2) continue;
    Vec3 contact{0, 0, 0};
    long count = 0;
    for (long c = 0; c < nc; ++c) {
      if (label[c] != id || s.body[c] < 0) continue;
      long nb[6];
      const int m = face_neighbours(g, c, nb);
      bool touches = false;
      for (int q = 0; q < m; ++q) touches = touches || (s.body[nb[q]] >= 0 && s.body[nb[q]] != s.body[c]);
      if (!touches) continue;
      int i, j, k;
      g.ijk(c, i, j, k);
      contact = add(contact, g.centre(i, j, k));
      ++count;
    }
    if (count == 0) {  // joined through cells outside both: between the first two bodies' boxes
      for (int b : {joined.bodies[0], joined.bodies[1]})
        contact = add(contact, scale(add(shells.body_lo[b], shells.body_hi[b]), 0.25));
      count = 1;
    }
    joined.contact = scale(contact, 1.0 / count);
    s.joined.push_back(joined);
  }
}

// Selects every unselected cell that the outside cannot reach through faces (an enclosed cavity). With
// voids (Selection::in_void), an enclosed cavity that holds a void cell is a void of the solid and stays
// open; the others (cells inside the solid that the margins left out) are filled.
int fill_cavities(Selection& s) {
  const Grid& g = s.grid;
  const long nc = g.cells();
  std::vector<char> reached(nc, 0);
  std::vector<long> stack{0};  // cell 0 is in the outer layer, never selected
  reached[0] = 1;
  while (!stack.empty()) {
    const long x = stack.back();
    stack.pop_back();
    long nb[6];
    const int m = face_neighbours(g, x, nb);
    for (int q = 0; q < m; ++q)
      if (!s.selected[nb[q]] && !reached[nb[q]]) reached[nb[q]] = 1, stack.push_back(nb[q]);
  }
  int filled = 0;
  if (s.in_void.empty()) {
    for (long c = 0; c < nc; ++c)
      if (!s.selected[c] && !reached[c]) s.selected[c] = 1, ++filled;
    return filled;
  }
  for (long c = 0; c < nc; ++c) {
    if (s.selected[c] || reached[c]) continue;
    // One enclosed cavity, marked reached as it is collected.
    std::vector<long> cavity{c};
    bool is_void = s.in_void[c];
    reached[c] = 1;
    for (std::size_t q = 0; q < cavity.size(); ++q) {
      long nb[6];
      const int m = face_neighbours(g, cavity[q], nb);
      for (int r = 0; r < m; ++r)
        if (!s.selected[nb[r]] && !reached[nb[r]]) {
          reached[nb[r]] = 1;
          cavity.push_back(nb[r]);
          is_void = is_void || s.in_void[nb[r]];
        }
    }
    if (is_void) continue;
    for (long x : cavity) s.selected[x] = 1, ++filled;
  }
  return filled;
}

// True when the cells of a 2 x 2 x 2 block flagged in `mask` (bit b = di + 2 dj + 4 dk) are face-connected
// within the block.
bool block_connected(int mask) {
  if (mask == 0) return true;
  int first = 0;
  while (!(mask >> first & 1)) ++first;
  int seen = 1 << first, frontier = seen;
  while (frontier) {
    int next = 0;
    for (int b = 0; b < 8; ++b)
      if (frontier >> b & 1)
        for (int axis = 0; axis < 3; ++axis) {
          const int nb = b ^ (1 << axis);
          if ((mask >> nb & 1) && !(seen >> nb & 1)) next |= 1 << nb;
        }
    seen |= next;
    frontier = next;
  }
  return seen == mask;
}

// A 2 x 2 x 2 block is manifold at its centre vertex when the selected cells and the unselected cells are
// each face-connected within the block, and no face of the block holds exactly a diagonal pair (two cells
// that share only the edge through the centre).
bool block_manifold(int mask) {
  static const int faces[6][4] = {{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                  {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}};
  for (const auto& f : faces) {
    const int a = mask >> f[0] & 1, b = mask >> f[1] & 1, c = mask >> f[2] & 1, d = mask >> f[3] & 1;
    if (a == c && b == d && a != b) return false;
  }
  return block_connected(mask) && block_connected(~mask & 0xff);
}

// block_manifold of every mask.
const std::array<bool, 256>& manifold_table() {
  static const std::array<bool, 256> table = [] {
    std::array<bool, 256> t{};
    for (int m = 0; m < 256; ++m) t[m] = block_manifold(m);
    return t;
  }();
  return table;
}

// The mask of the 2 x 2 x 2 block of cells around grid vertex (i, j, k) (bit b = di + 2 dj + 4 dk for the
// cell (i - 1 + di, j - 1 + dj, k - 1 + dk)); the vertex must not lie on the grid's border.
int block_mask(const Selection& s, int i, int j, int k) {
  int mask = 0;
  for (int b = 0; b < 8; ++b)
    if (s.selected[s.grid.cell(i - 1 + (b & 1), j - 1 + (b >> 1 & 1), k - 1 + (b >> 2 & 1))]) mask |= 1 << b;
  return mask;
}

// Adds cells until every grid vertex is manifold: in each offending block the unselected cell whose centre
// lies deepest inside the surface is added. Only adds, so it terminates.
void make_manifold(Selection& s, const SurfaceProjector& surface) {
  const Grid& g = s.grid;
  const std::array<bool, 256>& manifold = manifold_table();
  bool changed = true;
  while (changed) {
    changed = false;
    for (int k = 1; k < g.n[2]; ++k)
      for (int j = 1; j < g.n[1]; ++j)
        for (int i = 1; i < g.n[0]; ++i) {
          long cells[8];
          int mask = 0;
          for (int b = 0; b < 8; ++b) {
            cells[b] = g.cell(i - 1 + (b & 1), j - 1 + (b >> 1 & 1), k - 1 + (b >> 2 & 1));
            if (s.selected[cells[b]]) mask |= 1 << b;
          }
          if (manifold[mask]) continue;
          int best = -1;
          double best_score = -kInf;
          for (int b = 0; b < 8; ++b)
            if (!(mask >> b & 1)) {
              const double sc = cell_score(s, surface, cells[b]);
              if (best < 0 || sc > best_score) best = b, best_score = sc;
            }
          s.selected[cells[best]] = 1;
          ++s.added_for_manifold;
          changed = true;
        }
    if (fill_cavities(s) > 0) changed = true;
  }
}

// The valence of a 2 x 2 x 2 block's centre vertex on the core's boundary surface: the number of the
// block's 12 inner faces that lie between a selected and an unselected cell (0 off the boundary).
int block_valence(int mask) {
  int v = 0;
  for (int b = 0; b < 8; ++b)
    for (int axis = 0; axis < 3; ++axis)
      if (!(b >> axis & 1) && ((mask >> b ^ mask >> (b | 1 << axis)) & 1)) ++v;
  return v;
}

// The irregularity of a block's centre vertex on the core boundary, |valence - 4| (0 off the boundary), or
// -1 when the vertex is not manifold.
const std::array<int, 256>& irregularity_table() {
  static const std::array<int, 256> table = [] {
    std::array<int, 256> t{};
    for (int m = 0; m < 256; ++m) {
      const int v = block_valence(m);
      t[m] = !block_manifold(m) ? -1 : v == 0 ? 0 : std::abs(v - 4);
    }
    return t;
  }();
  return table;
}

// True when switching cell (i, j, k) keeps the core's local topology: within the cell's 26 neighbours the
// face neighbours of either state (selected, unselected) stay face-connected through cells of that state
// without the cell, so no component splits off, no cavity appears and no tunnel opens or closes.
bool switch_keeps_topology(const Selection& s, int i, int j, int k) {
  static const int kFaces[6] = {4, 10, 12, 14, 16, 22};  // the face neighbours in the 3 x 3 x 3 block
  char state[27];
  for (int q = 0; q < 27; ++q)
    state[q] = s.selected[s.grid.cell(i - 1 + q % 3, j - 1 + q / 3 % 3, k - 1 + q / 9)];
  for (const char colour : {char(0), char(1)}) {
    int start = -1, faces = 0;
    for (int q : kFaces)
      if (state[q] == colour) ++faces, start = start < 0 ? q : start;
    if (start < 0) continue;
    bool seen[27] = {};
    int stack[27], top = 0, reached = 0;
    seen[start] = true;
    stack[top++] = start;
    while (top > 0) {
      const int q = stack[--top];
      reached += std::find(std::begin(kFaces), std::end(kFaces), q) != std::end(kFaces);
      const int x = q % 3, y = q / 3 % 3, z = q / 9;
      for (int axis = 0; axis < 3; ++axis)
        for (int d : {-1, 1}) {
          const int p[3] = {x + (axis == 0) * d, y + (axis == 1) * d, z + (axis == 2) * d};
          if (std::min({p[0], p[1], p[2]}) < 0 || std::max({p[0], p[1], p[2]}) > 2) continue;
          const int r = p[0] + 3 * p[1] + 9 * p[2];
          if (r != 13 && !seen[r] && state[r] == colour) seen[r] = true, stack[top++] = r;
        }
    }
    if (reached != faces) return false;
  }
  return true;
}

// The regular core (fine cells): a staircase core boundary has irregular vertices (valence 3, 5 or 6 on the
// boundary quad surface), whose pillow hexes average SJ 0.66-0.79 against 0.90 on regular ones. Sweeps in
// grid order switch single boundary cells (remove a selected cell whose centre lies at most inside * h
// inside the surface, add an unselected one whose centre lies at most outside * h outside) when that lowers
// the summed |valence - 4| of its eight corners, keeps every corner manifold and the local topology
// (switch_keeps_topology), and only where the solid is at least two cells thick (thin plates keep their
// cells). Strict decreases only, so it terminates.
void regularize_core(Selection& s, const SurfaceProjector& surface, double inside, double outside) {
  const Grid& g = s.grid;
  const std::array<int, 256>& irregularity = irregularity_table();
  for (bool changed = true; changed;) {
    changed = false;
    for (int k = 1; k + 1 < g.n[2]; ++k)
      for (int j = 1; j + 1 < g.n[1]; ++j)
        for (int i = 1; i + 1 < g.n[0]; ++i) {
          const long c = g.cell(i, j, k);
          const char selected = s.selected[c];
          long nb[6];
          const int m = face_neighbours(g, c, nb);
          bool boundary = false;
          for (int q = 0; q < m; ++q) boundary = boundary || s.selected[nb[q]] != selected;
          if (!boundary) continue;
          int gain = 0;
          bool manifold = true;
          for (int b = 0; b < 8 && manifold; ++b) {
            // Corner b of the cell is the centre vertex of the block whose cell 7 - b is this one.
            const int mask = block_mask(s, i + (b & 1), j + (b >> 1 & 1), k + (b >> 2 & 1));
            const int next = irregularity[mask ^ 1 << (7 - b)];
            manifold = next >= 0;
            gain += irregularity[mask] - next;
          }
          if (!manifold || gain <= 0) continue;
          const double score = cell_score(s, surface, c);
          if (selected ? score > inside * g.h : score < -outside * g.h) continue;
          if (!switch_keeps_topology(s, i, j, k) || thinner_than(surface, g.centre(i, j, k), 2.0 * g.h))
            continue;
          s.selected[c] = !selected;
          changed = true;
        }
  }
}

// The number of core boundary vertices and of the irregular ones among them (valence other than 4).
std::pair<int, int> boundary_valences(const Selection& s) {
  const Grid& g = s.grid;
  const std::array<int, 256>& irregularity = irregularity_table();
  int vertices = 0, irregular = 0;
  for (int k = 1; k < g.n[2]; ++k)
    for (int j = 1; j < g.n[1]; ++j)
      for (int i = 1; i < g.n[0]; ++i) {
        const int mask = block_mask(s, i, j, k);
        if (mask == 0 || mask == 0xff) continue;
        ++vertices;
        irregular += irregularity[mask] != 0;
      }
  return {vertices, irregular};
}

void count_cells(Selection& s) {
  const Grid& g = s.grid;
  s.core_cells = 0;
  s.boundary_quads = 0;
  for (long c = 0; c < g.cells(); ++c) {
    if (!s.selected[c]) continue;
    ++s.core_cells;
    long nb[6];
    const int m = face_neighbours(g, c, nb);
    for (int q = 0; q < m; ++q) s.boundary_quads += !s.selected[nb[q]];
  }
}

// How an attempt's core is selected at one cell size (select_core's margins; regularize_core's band when
// regularize).
struct CoreSelection {
  double margin = 0, thick_margin = 0, thin_cells = 1;
  bool regularize = false;
  double inside = 0, outside = 0;
};

// The selection for cell size h, the grid shifted by `shift` cells along every axis.
Selection build_selection(const SurfaceProjector& surface, const Shells& shells, const Vec3& lo,
                          const Vec3& hi, double h, double shift, const CoreSelection& how) {
  Selection s;
  s.grid.h = h;
  for (int a = 0; a < 3; ++a) {
    // Two more cells when shifted, so that the outer layer stays outside the bounding box.
    s.grid.n[a] = int(std::ceil((hi[a] - lo[a]) / h)) + (shift != 0.0 ? 4 : 2);
    // Centre the grid on the bounding box, so that the result does not depend on which corner is lower.
    s.grid.origin[a] = 0.5 * (lo[a] + hi[a]) - (0.5 * s.grid.n[a] - shift) * h;
  }
  classify(s, surface, shells);
  select_core(s, surface, how.margin, how.thick_margin, how.thin_cells);
  // Manifold repair first: a part that touches the rest only along an edge or at a vertex (a thin process
  // at this cell size) is then joined by a cell instead of being dropped as a separate component.
  make_manifold(s, surface);
  if (shells.bodies > 1)
    keep_main_components(s, surface, shells);
  else
    keep_largest_component(s);
  fill_cavities(s);
  make_manifold(s, surface);
  if (how.regularize) regularize_core(s, surface, how.inside, how.outside);
  count_cells(s);
  return s;
}

// The core hex mesh of the selected cells, vertices numbered in grid order.
HexMesh core_mesh(const Selection& s) {
  const Grid& g = s.grid;
  std::vector<int> id(std::size_t(g.n[0] + 1) * (g.n[1] + 1) * (g.n[2] + 1), -1);
  for (long c = 0; c < g.cells(); ++c) {
    if (!s.selected[c]) continue;
    int i, j, k;
    g.ijk(c, i, j, k);
    for (int b = 0; b < 8; ++b) id[g.vertex(i + (b & 1), j + (b >> 1 & 1), k + (b >> 2 & 1))] = 0;
  }
  HexMesh mesh;
  for (int k = 0; k <= g.n[2]; ++k)
    for (int j = 0; j <= g.n[1]; ++j)
      for (int i = 0; i <= g.n[0]; ++i) {
        int& v = id[g.vertex(i, j, k)];
        if (v < 0) continue;
        v = int(mesh.vertices.size());
        mesh.vertices.push_back({g.origin[0] + i * g.h, g.origin[1] + j * g.h, g.origin[2] + k * g.h});
      }
  for (long c = 0; c < g.cells(); ++c) {
    if (!s.selected[c]) continue;
    int i, j, k;
    g.ijk(c, i, j, k);
    mesh.hexes.push_back({id[g.vertex(i, j, k)], id[g.vertex(i + 1, j, k)], id[g.vertex(i + 1, j + 1, k)],
                          id[g.vertex(i, j + 1, k)], id[g.vertex(i, j, k + 1)], id[g.vertex(i + 1, j, k + 1)],
                          id[g.vertex(i + 1, j + 1, k + 1)], id[g.vertex(i, j + 1, k + 1)]});
  }
  return mesh;
}

// Adds the pillow layer: a copy of every core boundary vertex on the surface and one hex per boundary quad.
int add_pillow_layer(HexMesh& mesh, const SurfaceProjector& surface, double h) {
  const HexBoundary boundary = extract_boundary(mesh);
  const QuadSurface& q = boundary.surface;
  // Area-weighted vertex normals of the core boundary (the cross product of a quad's diagonals).
  std::vector<Vec3> normal(q.vertices.size(), Vec3{0, 0, 0});
  for (const auto& quad : q.quads) {
    const Vec3 n =
        cross(sub(q.vertices[quad[2]], q.vertices[quad[0]]), sub(q.vertices[quad[3]], q.vertices[quad[1]]));
    for (int v : quad) normal[v] = add(normal[v], n);
  }
  std::vector<int> copy(q.vertices.size());
  for (std::size_t i = 0; i < q.vertices.size(); ++i) {
    Vec3 p = q.vertices[i];
    const double len = norm(normal[i]);
    const Vec3 n = len > 0 ? scale(normal[i], 1.0 / len) : Vec3{0, 0, 1};
    // A core vertex that pokes out of the surface or lies almost on it would give a flat or inverted pillow
    // hex: pull it below the surface first, by a third of a cell, or less where the solid is thin (a third
    // of the thickness measured along the inward normal), so that vertices from opposite sides of a thin
    // part do not cross.
    const SurfacePoint near = surface.closest(p);
    if (!surface.inside(p) || near.distance < 0.25 * h) {
      double depth = h / 3.0;
      SurfacePoint opposite;
      const Vec3 inward = scale(near.normal, -1.0);
      const Vec3 start = add(near.point, scale(inward, 1e-6 * h));
      if (surface.first_hit(start, inward, 3.0 * h, &opposite))
        depth = std::min(depth, opposite.distance / 3.0);
      p = add(near.point, scale(inward, depth));
      mesh.vertices[boundary.boundary_vertices[i]] = p;
    }
    // The copy goes where the vertex normal meets the surface, which spreads the copies evenly on concave
    // and convex parts alike; when the ray misses or travels much farther than the closest point, the
    // closest point is used instead.
    SurfacePoint hit;
    const SurfacePoint closest = surface.closest(p);
    Vec3 target = closest.point;
    if (surface.first_hit(p, n, 3.0 * h, &hit) && hit.distance <= 2.0 * closest.distance + 0.25 * h)
      target = hit.point;
    copy[i] = int(mesh.vertices.size());
    mesh.vertices.push_back(target);
  }
  for (const auto& quad : q.quads) {
    const int a = boundary.boundary_vertices[quad[0]], b = boundary.boundary_vertices[quad[1]],
              c = boundary.boundary_vertices[quad[2]], d = boundary.boundary_vertices[quad[3]];
    // The quad is counter-clockwise seen from outside, so it is the bottom face of a hex whose top face
    // (the copies) lies outside it.
    mesh.hexes.push_back({a, b, c, d, copy[quad[0]], copy[quad[1]], copy[quad[2]], copy[quad[3]]});
  }
  return int(q.quads.size());
}

// The solid's thickness under a region of its surface: the median, over the region's triangles weighted by
// their area, of the distance from the centroid along the inward normal to the next surface crossing (0 when
// no ray crosses). The median: on a blade (a coronoid process) most of the area lies on its two faces, whose
// rays cross it, while the rays of its rim run along it.
double region_thickness(const SurfaceProjector& solid, const std::vector<int>& triangles) {
  const TriSurface& surface = solid.surface();
  std::vector<std::pair<double, double>> depth;  // (distance, triangle area)
  for (int t : triangles) {
    const auto& tri = surface.triangles[t];
    const Vec3& a = surface.vertices[tri[0]];
    const Vec3 n = cross(sub(surface.vertices[tri[1]], a), sub(surface.vertices[tri[2]], a));
    const double len = norm(n);
    if (len == 0) continue;
    const Vec3 inward = scale(n, -1.0 / len);
    const Vec3 c = scale(add(add(a, surface.vertices[tri[1]]), surface.vertices[tri[2]]), 1.0 / 3.0);
    // Started a hair inside so that the ray does not hit its own triangle.
    const double hair = 1e-6 * std::sqrt(len);
    SurfacePoint hit;
    if (solid.first_hit(add(c, scale(inward, hair)), inward, kInf, &hit))
      depth.emplace_back(hit.distance + hair, 0.5 * len);
  }
  if (depth.empty()) return 0.0;
  // The median by area, not by triangle count: a thin plate's few long narrow side triangles (whose rays
  // cross the whole plate) must not outvote its faces (a 1 mm plate of 100 x 100 mm was "100.0 mm thick").
  std::sort(depth.begin(), depth.end());
  double total = 0;
  for (const auto& [d, area] : depth) total += area;
  double below = 0;
  for (const auto& [d, area] : depth) {
    below += area;
    if (below >= 0.5 * total) return d;
  }
  return depth.back().first;
}

// Surface regions farther than `limit` (half the mean edge) from the mesh boundary, grouped by shared
// triangle vertices. A region that is a whole shell of a surface with several shells, far everywhere
// (every vertex and centroid), is named as a separate shell (a body) or a void that the mesh does not
// reach; any other region is named by the solid's thickness under it: a part thinner than the mean edge,
// or an edge, corner or tip of a thicker one.
std::vector<UnresolvedPart> unresolved_regions(const SurfaceProjector& solid, const Shells& shells,
                                               const std::vector<double>& vertex_dist,
                                               const std::vector<double>& centroid_dist, double limit) {
  const TriSurface& surface = solid.surface();
  const std::size_t nt = surface.triangles.size();
  UnionFind pieces(surface.vertices.size());
  std::vector<char> far_triangle(nt, 0);
  for (std::size_t t = 0; t < nt; ++t) {
    const auto& tri = surface.triangles[t];
    bool far = centroid_dist[t] > limit;
    for (int v : tri) far = far || vertex_dist[v] > limit;
    if (!far) continue;
    far_triangle[t] = 1;
    pieces.unite(tri[0], tri[1]);
    pieces.unite(tri[0], tri[2]);
  }
  std::vector<int> region(surface.vertices.size(), -1);
  std::vector<UnresolvedPart> parts;
  std::vector<Vec3> sums, lows, highs;
  std::vector<int> shell_of_part;
  std::vector<long> wholly_far;  // per part: triangles whose vertices and centroid are all far
  std::vector<std::vector<int>> triangles_of_part;
  for (std::size_t t = 0; t < nt; ++t) {
    if (!far_triangle[t]) continue;
    const auto& tri = surface.triangles[t];
    const std::size_t root = pieces.find(tri[0]);
    if (region[root] < 0) {
      region[root] = int(parts.size());
      parts.push_back({});
      sums.push_back({0, 0, 0});
      lows.push_back({kInf, kInf, kInf});
      highs.push_back({-kInf, -kInf, -kInf});
      shell_of_part.push_back(shells.shell_of_triangle[t]);
      wholly_far.push_back(0);
      triangles_of_part.emplace_back();
    }
    triangles_of_part[region[root]].push_back(int(t));
    UnresolvedPart& p = parts[region[root]];
    const Vec3& a = surface.vertices[tri[0]];
    const Vec3& b = surface.vertices[tri[1]];
    const Vec3& c = surface.vertices[tri[2]];
    sums[region[root]] = add(sums[region[root]], scale(add(add(a, b), c), 1.0 / 3.0));
    bool wholly = centroid_dist[t] > limit;
    for (int v : tri) wholly = wholly && vertex_dist[v] > limit;
    wholly_far[region[root]] += wholly;
    for (int v : tri)
      for (int e = 0; e < 3; ++e) {
        lows[region[root]][e] = std::min(lows[region[root]][e], surface.vertices[v][e]);
        highs[region[root]][e] = std::max(highs[region[root]][e], surface.vertices[v][e]);
      }
    ++p.samples;
    p.extent = std::max(p.extent, centroid_dist[t]);
    for (int v : tri) p.extent = std::max(p.extent, vertex_dist[v]);
  }
  for (std::size_t r = 0; r < parts.size(); ++r) {
    parts[r].location = scale(sums[r], 1.0 / parts[r].samples);
    std::ostringstream extent;
    extent.precision(1);
    extent << std::fixed << parts[r].extent;
    const int shell = shell_of_part[r];
    if (shells.shell_triangles.size() > 1 && wholly_far[r] == shells.shell_triangles[shell]) {
      std::ostringstream size;
      size.precision(1);
      size << std::fixed << highs[r][0] - lows[r][0] << " x " << highs[r][1] - lows[r][1] << " x "
           << highs[r][2] - lows[r][2] << " mm";
      parts[r].what =
          (shells.inner[shell] ? "the whole void near " : "the whole separate shell near ") +
          format_point_mm(parts[r].location) + " (" + size.str() + ") lies up to " + extent.str() +
          " mm from the mesh (" + std::to_string(parts[r].samples) + " triangles): " +
          (shells.inner[shell] ? "a void smaller than a cell is filled at this cell size"
                               : "a body smaller or thinner than a cell is not meshed at this size") +
          "; ask for more hexes to resolve it";
      continue;
    }
    parts[r].thickness = region_thickness(solid, triangles_of_part[r]);
    const double mean_edge = 2.0 * limit;
    std::ostringstream why;
    why.precision(1);
    why << std::fixed;
    if (parts[r].thickness == 0)
      why << "a part the mesh does not reach at this size; ask for more hexes to resolve it";
    else if (parts[r].thickness < mean_edge)
      why << "a part about " << parts[r].thickness << " mm thick, thinner than the mean edge (" << mean_edge
          << " mm); ask for more hexes to resolve it";
    else
      why << "an edge, corner or tip of a part about " << parts[r].thickness
          << " mm thick that the mesh cuts at this size (mean edge " << mean_edge
          << " mm); ask for more hexes to follow it closer";
    parts[r].what = std::string(shells.inner[shell] ? "the void's surface near " : "the surface near ") +
                    format_point_mm(parts[r].location) + " lies up to " + extent.str() +
                    " mm from the mesh (" + std::to_string(parts[r].samples) + " triangles): " + why.str();
  }
  std::stable_sort(parts.begin(), parts.end(),
                   [](const UnresolvedPart& a, const UnresolvedPart& b) { return a.extent > b.extent; });
  return parts;
}

}  // namespace

std::vector<std::string> unresolved_listing(const std::vector<UnresolvedPart>& parts, std::size_t shown) {
  std::vector<std::string> lines;
  for (std::size_t i = 0; i < parts.size() && i < shown; ++i) lines.push_back(parts[i].what);
  if (parts.size() > shown)
    lines.push_back("... and " + std::to_string(parts.size() - shown) + " smaller regions");
  return lines;
}

void name_unresolved_parts(const Landmarks& landmarks, std::vector<UnresolvedPart>& parts) {
  for (UnresolvedPart& part : parts) {
    // The nearest of each kind; ties go to the first in the file's order (points are ordered by name).
    NearbyPoint point{"", kInf}, insertion{"", kInf};
    for (const auto& [name, p] : landmarks.points) {
      const double d = norm(sub(p, part.location));
      if (d < point.distance) point = {name, d};
    }
    for (const MuscleLine& m : landmarks.muscles) {
      const double d = norm(sub(m.insertion, part.location));
      if (d < insertion.distance) insertion = {m.name + ".insertion", d};
    }
    part.near.clear();
    for (const NearbyPoint& n : {point, insertion})
      if (!n.name.empty()) part.near.push_back(n);
    if (part.near.size() == 2 && part.near[1].distance < part.near[0].distance)
      std::swap(part.near[0], part.near[1]);
    // In the sentence only the points within kNearMm: "near" a point 35 mm away misleads (the real jaw's
    // incisors "near left_anterior_digastric.insertion (35.4 mm)"); the JSON keeps both.
    constexpr double kNearMm = 20.0;
    std::string names;
    for (const NearbyPoint& n : part.near) {
      if (n.distance > kNearMm) continue;
      std::ostringstream d;
      d.precision(1);
      d << std::fixed << n.distance;
      names += (names.empty() ? "near " : ", ") + n.name + " (" + d.str() + " mm)";
    }
    if (!names.empty()) part.what = names + ": " + part.what;
  }
}

double hex_volume(const HexMesh& mesh, int hex) {
  // Reference coordinates of the VTK hexahedron's nodes.
  static const double ref[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                   {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  const double gp[2] = {0.5 - 0.5 / std::sqrt(3.0), 0.5 + 0.5 / std::sqrt(3.0)};
  const auto& h = mesh.hexes[hex];
  double volume = 0;
  for (int q = 0; q < 8; ++q) {
    const double xi[3] = {gp[q & 1], gp[q >> 1 & 1], gp[q >> 2 & 1]};
    double j[3][3] = {};
    for (int n = 0; n < 8; ++n) {
      double dn[3];
      for (int a = 0; a < 3; ++a) {
        dn[a] = ref[n][a] ? 1.0 : -1.0;
        for (int b = 0; b < 3; ++b)
          if (b != a) dn[a] *= ref[n][b] ? xi[b] : 1.0 - xi[b];
      }
      const Vec3& x = mesh.vertices[h[n]];
      for (int r = 0; r < 3; ++r)
        for (int a = 0; a < 3; ++a) j[r][a] += x[r] * dn[a];
    }
    const double det = j[0][0] * (j[1][1] * j[2][2] - j[1][2] * j[2][1]) -
                       j[0][1] * (j[1][0] * j[2][2] - j[1][2] * j[2][0]) +
                       j[0][2] * (j[1][0] * j[2][1] - j[1][1] * j[2][0]);
    volume += det / 8.0;
  }
  return volume;
}

double hex_mesh_volume(const HexMesh& mesh) {
  double volume = 0;
  for (std::size_t h = 0; h < mesh.hexes.size(); ++h) volume += hex_volume(mesh, static_cast<int>(h));
  return volume;
}

MeshFidelity measure_fidelity(const HexMesh& mesh, const SurfaceProjector& surface) {
  MeshFidelity f;
  const HexBoundary boundary = extract_boundary(mesh);
  const QuadSurface& q = boundary.surface;

  // The boundary as triangles, four per quad around its bilinear centre, for distances to the mesh.
  const TriSurface tri = fan_triangles(q);
  // Mesh to surface: boundary vertices, quad centres and edge midpoints.
  for (const Vec3& p : tri.vertices)
    f.hausdorff_mesh_to_surface = std::max(f.hausdorff_mesh_to_surface, surface.distance(p));
  for (const auto& quad : q.quads)
    for (int e = 0; e < 4; ++e) {
      const Vec3 m = scale(add(q.vertices[quad[e]], q.vertices[quad[(e + 1) % 4]]), 0.5);
      f.hausdorff_mesh_to_surface = std::max(f.hausdorff_mesh_to_surface, surface.distance(m));
    }
  // Surface to mesh: surface vertices and triangle centroids.
  const SurfaceProjector mesh_boundary(tri);
  const TriSurface& s = surface.surface();
  std::vector<double> vertex_dist(s.vertices.size()), centroid_dist(s.triangles.size());
  for (std::size_t v = 0; v < s.vertices.size(); ++v) vertex_dist[v] = mesh_boundary.distance(s.vertices[v]);
  for (std::size_t t = 0; t < s.triangles.size(); ++t) {
    const auto& tr = s.triangles[t];
    const Vec3 c = scale(add(add(s.vertices[tr[0]], s.vertices[tr[1]]), s.vertices[tr[2]]), 1.0 / 3.0);
    centroid_dist[t] = mesh_boundary.distance(c);
  }
  for (double d : vertex_dist) f.hausdorff_surface_to_mesh = std::max(f.hausdorff_surface_to_mesh, d);
  for (double d : centroid_dist) f.hausdorff_surface_to_mesh = std::max(f.hausdorff_surface_to_mesh, d);
  f.hausdorff = std::max(f.hausdorff_mesh_to_surface, f.hausdorff_surface_to_mesh);

  std::vector<std::pair<int, int>> edges;
  static const int kEdges[12][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6},
                                    {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
  edges.reserve(mesh.hexes.size() * 12);
  for (const auto& h : mesh.hexes)
    for (const auto& e : kEdges) edges.emplace_back(std::min(h[e[0]], h[e[1]]), std::max(h[e[0]], h[e[1]]));
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  double sum = 0;
  for (const auto& e : edges) sum += norm(sub(mesh.vertices[e.first], mesh.vertices[e.second]));
  f.mean_edge_length = edges.empty() ? 0.0 : sum / edges.size();

  f.mesh_volume = hex_mesh_volume(mesh);
  f.surface_volume = enclosed_volume(s);
  f.volume_difference = f.surface_volume != 0 ? (f.mesh_volume - f.surface_volume) / f.surface_volume : 0.0;
  f.unresolved =
      unresolved_regions(surface, find_shells(s), vertex_dist, centroid_dist, 0.5 * f.mean_edge_length);
  return f;
}

// One grid of grid_mesh(): steps 1 to 4 on the grid shifted by `shift` cells.
struct GridAttempt {
  GridMeshReport report;  // seconds_core, _pillow, _optimize of this grid; no fidelity yet
  HexMesh mesh;
  Selection selection;
  std::vector<Vec3> pillowed;  // the nodes before optimization
  bool fine = false;           // the cells are fine (GridMeshOptions::thick_margin_cells)
};

// How an attempt picks the core's margins at a trial cell size h. With coarse cells (the solid's mean
// thickness 2 V / A below thick_margin_cells * h) both rules use GridMeshOptions::margin everywhere.
enum class CoreRule {
  kPlain,   // fine cells: GridMeshOptions::fine_margin everywhere
  kThick,   // fine cells: margin where the solid is thinner than a cell, thick_margin elsewhere
  kMargin,  // fine cells too: margin everywhere
  // fine cells: the plain core, less deep cells (regular_margin) where the solid is thick, regularized
  kRegular,
  kSwept,  // coarse cells along the arch: the core swept across the arch (mesher/swept_core.h)
  // the swept core's retry: the optimizer with its Newton sweeps and no tips pass before it
  kSweptNewton,
};

// The frame the core is selected in: the body's own axes, the dental arch, or the principal axes.
struct CoreFrame {
  const ArchFrame* arch = nullptr;
  const PrincipalFrame* principal = nullptr;
  bool body() const { return arch == nullptr && principal == nullptr; }
  Vec3 to_grid(const Vec3& v) const {
    return arch ? arch->to_arch(v) : principal ? principal->to_frame(v) : v;
  }
  Vec3 to_body(const Vec3& v) const {
    return arch ? arch->to_body(v) : principal ? principal->to_body(v) : v;
  }
};

// Steps 1 and 2 of one grid, shifted by `shift` cells: the cell size and the core (`mesh` holds the core).
// In another frame than the body's, `projector` and `shells` are those of the surface in that frame (arch
// coordinates, or the principal axes), and the core's vertices are mapped back to the body.
GridAttempt grid_core(const SurfaceProjector& projector, const Shells& shells, const Vec3& lo, const Vec3& hi,
                      double volume, double mean_thickness, const GridMeshOptions& options, double shift,
                      CoreRule rule, const CoreFrame& frame) {
  const auto t_attempt = std::chrono::steady_clock::now();
  GridAttempt out;
  GridMeshReport& r = out.report;
  // The cell size: secant steps on log(total hexes) against log(h), where total = core cells + core
  // boundary quads (one pillow hex each). The count falls like h^-2 to h^-3; start from the slope -2.5.
  const double target = double(options.target_hexes);
  Progress progress("grid core");
  double h = std::cbrt(volume / target);
  Selection& best = out.selection;
  double best_error = kInf;
  CellSizeSearch size_search(target, -2.5, -1.0);
  for (int step = 0; step < 8; ++step) {
    const bool fine = options.thick_margin_cells * h <= mean_thickness;
    CoreSelection how;
    how.margin = how.thick_margin = options.margin;
    if (fine && (rule == CoreRule::kPlain || rule == CoreRule::kRegular))
      how.margin = how.thick_margin = options.fine_margin;
    if (fine && rule == CoreRule::kThick) how.thick_margin = options.thick_margin;
    if (fine && rule == CoreRule::kRegular) {
      how.thick_margin = options.regular_margin;
      how.thin_cells = options.regular_thin_cells;
      how.regularize = true;
      how.inside = options.regular_inside;
      how.outside = options.regular_outside;
    }
    Selection s = build_selection(projector, shells, lo, hi, h, shift, how);
    const double total = double(s.core_cells + s.boundary_quads);
    const double error = std::fabs(total - target) / target;
    if (s.core_cells > 0 && error < best_error) {
      best_error = error;
      best = std::move(s);
      out.fine = fine;
    }
    progress.update(double(step + 1) / 8,
                    "h = " + std::to_string(h) + " mm, " + std::to_string(long(total)) + " hexes");
    if (best_error < 0.02) break;
    h = size_search.next(h, total);
  }
  progress.finish();
  if (best.core_cells == 0)
    throw InputError("grid mesher: no grid cell fits inside the surface; the solid is too thin for " +
                     std::to_string(options.target_hexes) + " hexes, ask for more");
  r.cell_size = best.grid.h;
  r.grid = best.grid.n;
  r.cells_added_for_manifold = best.added_for_manifold;
  r.cells_in_dropped_components = best.dropped;
  for (const MissedBody& m : best.missed) r.cells_in_dropped_components += m.cells;
  std::tie(r.core_boundary_vertices, r.irregular_core_boundary_vertices) = boundary_valences(best);
  out.mesh = core_mesh(best);
  if (!frame.body())
    for (Vec3& v : out.mesh.vertices) v = frame.to_body(v);
  r.core_hexes = int(out.mesh.hexes.size());
  r.seconds_core = seconds_since(t_attempt);
  return out;
}

// Steps 1 and 2 with the swept core (coarse cells along the arch): `projector` is the straightened surface's.
// The attempt's selection holds only the cell size, for the messages about the kept grid.
GridAttempt swept_attempt(const SurfaceProjector& projector, const Vec3& lo, const Vec3& hi,
                          const GridMeshOptions& options, double shift, const ArchFrame& arch) {
  const auto t_attempt = std::chrono::steady_clock::now();
  GridAttempt out;
  SweptCoreOptions swept;
  swept.layers = options.swept_layers;
  SweptCore core = swept_core(projector, lo, hi, options.target_hexes, shift, swept);
  out.selection.grid.h = core.cell_size;
  out.selection.grid.n = core.grid;
  GridMeshReport& r = out.report;
  r.swept = true;
  r.cell_size = core.cell_size;
  r.grid = core.grid;
  r.cells_in_dropped_components = int(core.dropped_columns);
  out.mesh = std::move(core.mesh);
  for (Vec3& v : out.mesh.vertices) v = arch.to_body(v);
  r.core_hexes = int(out.mesh.hexes.size());
  r.seconds_core = seconds_since(t_attempt);
  return out;
}

// Steps 3 and 4 of one grid: the pillow layer and the optimization.
// With reach_far > 0 the pillow layer's nodes are first moved onto the surface's tips (reach_far_surface,
// validity only: the optimizer improves what the moves spoil, and starts from there).
void pillow_and_optimize(GridAttempt& attempt, const SurfaceProjector& projector,
                         const OptimizeOptions& optimize, double reach_far) {
  GridMeshReport& r = attempt.report;
  auto t0 = std::chrono::steady_clock::now();
  r.pillow_hexes = add_pillow_layer(attempt.mesh, projector, attempt.selection.grid.h);
  if (reach_far > 0) {
    FarSurfaceOptions far;
    far.limit = reach_far;
    far.keep_worst = false;
    reach_far_surface(attempt.mesh, projector, far);
  }
  r.seconds_pillow = seconds_since(t0);

  t0 = std::chrono::steady_clock::now();
  attempt.pillowed = attempt.mesh.vertices;
  r.optimize = optimize_hex_mesh(attempt.mesh, &projector, {}, optimize);
  r.seconds_optimize = seconds_since(t0);
}

// The swept core's tips again, after the optimizer and the mean stage moved the nodes, down to the floor
// (GridMeshOptions::swept_tips_*); then the interior nodes around the moved nodes restore the quality (the
// boundary held) and the tips go on from there. A round that takes the mesh's worst below the floor or
// above the cap is undone.
void reach_swept_tips(HexMesh& mesh, const SurfaceProjector& projector, const GridMeshOptions& options) {
  FarSurfaceOptions far;
  far.limit = options.swept_tips_limit;
  far.floor_scaled_jacobian = options.swept_tips_floor;
  far.max_condition = options.swept_tips_condition;
  FarSurfaceReport tips = reach_far_surface(mesh, projector, far);
  const std::vector<char> boundary = boundary_vertex_mask(mesh);
  const std::vector<char> sliding(mesh.vertices.size(), 0);
  std::vector<std::vector<int>> hexes_of(mesh.vertices.size());
  for (std::size_t e = 0; e < mesh.hexes.size(); ++e)
    for (int v : mesh.hexes[e]) hexes_of[v].push_back(int(e));
  // The worst-element pass keeps min(SJ, 3 / kappa), so where kappa is near the cap it may take a hex's
  // scaled Jacobian below the floor: such a round is undone (the 40 mm-wide ramus at 2,500 hexes: 0.326).
  QualitySummary worst = summarize_quality(mesh);
  const double sj_floor = std::min(worst.scaled_jacobian.min, options.swept_tips_floor);
  const double kappa_cap = std::max(worst.condition.max, options.swept_tips_condition);
  for (int relax = 0; relax < options.swept_tips_relax_rounds && !tips.moved.empty(); ++relax) {
    const std::vector<Vec3> before = mesh.vertices;
    std::vector<char> movable(mesh.vertices.size(), 0);
    for (int v : tips.moved)
      for (int e : hexes_of[v])
        for (int w : mesh.hexes[e]) movable[w] = !boundary[w];
    improve_worst_elements(mesh, movable, sliding, &projector, options.optimize);
    improve_mean_jacobian(mesh, movable, sliding, &projector, options.optimize);
    tips = reach_far_surface(mesh, projector, far);
    worst = summarize_quality(mesh);
    if (worst.inverted > 0 || worst.scaled_jacobian.min < sj_floor || worst.condition.max > kappa_cap) {
      mesh.vertices = before;
      break;
    }
  }
}

double worst_element_measure(const QualitySummary& q) {
  return std::min(q.scaled_jacobian.min, 3.0 / q.condition.max);
}

// grid_mesh in one frame (the coordinate axes, the arch or the principal axes).
static HexMesh grid_mesh_in_frame(const TriSurface& surface, const GridMeshOptions& options,
                                  GridMeshReport* report_out) {
  if (options.target_hexes < 8)
    throw InputError("grid mesher: the target hex count must be at least 8, got " +
                     std::to_string(options.target_hexes));
  const auto t_start = std::chrono::steady_clock::now();
  const SurfaceProjector projector(surface);
  const Shells shells = find_shells(surface);
  const double volume = enclosed_volume(surface);
  if (!(volume > 0))
    throw InputError("grid mesher: the surface encloses no volume (is it oriented outward?)");
  // With the arch frame (or the principal axes) the core is selected on the straightened (rotated) surface
  // and its vertices mapped back; the pillow layer, the optimization and the fidelity work on the surface
  // itself.
  std::optional<ArchFrame> arch;
  TriSurface straightened;
  std::unique_ptr<SurfaceProjector> straightened_projector;
  if (options.arch_frame || options.swept_core) {
    try {
      arch.emplace(surface);
    } catch (const NotAnArchError& e) {
      if (!options.swept_core) throw;
      // The arch frame's way out, the axis-aligned grid, is refused with the swept core: name the grid core.
      throw NotAnArchError(e.reason(),
                           "the swept core lies along the arch: use the grid core for other solids (--core "
                           "grid --grid-frame axes, in a scenario core: grid and grid_frame: axes)");
    }
  }
  std::optional<PrincipalFrame> principal;
  if (!arch && options.face_frame)
    principal = face_frame(surface);
  else if (!arch && options.principal_frame)
    principal = principal_frame(surface);
  CoreFrame frame;
  frame.arch = arch ? &*arch : nullptr;
  frame.principal = principal ? &*principal : nullptr;
  if (!frame.body()) {
    straightened = surface;
    for (Vec3& v : straightened.vertices) v = frame.to_grid(v);
    straightened_projector = std::make_unique<SurfaceProjector>(straightened);
  }
  const bool framed = !frame.body();
  const TriSurface& grid_surface = framed ? straightened : surface;
  const SurfaceProjector& grid_projector = framed ? *straightened_projector : projector;
  std::optional<Shells> straightened_shells;
  if (framed) straightened_shells = find_shells(straightened);
  const Shells& grid_shells = framed ? *straightened_shells : shells;
  const double grid_volume = framed ? enclosed_volume(straightened) : volume;
  double area = 0;
  for (const auto& t : grid_surface.triangles)
    area += 0.5 * norm(cross(sub(grid_surface.vertices[t[1]], grid_surface.vertices[t[0]]),
                             sub(grid_surface.vertices[t[2]], grid_surface.vertices[t[0]])));
  const double mean_thickness = 2.0 * grid_volume / area;
  Vec3 lo{kInf, kInf, kInf}, hi{-kInf, -kInf, -kInf};
  for (const Vec3& p : grid_surface.vertices)
    for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);

  // Where a thin part cuts through a cell decides how its hexes look: a grid can leave a tangle that the
  // untangler cannot undo, and the worst hexes of valid meshes differ widely between grid positions. So
  // the grid is also shifted by half a cell and by a quarter, and the mesh with the fewest inverted hexes,
  // then the largest worst-element measure min(scaled Jacobian, 3 / kappa), is kept.
  const double shifts[] = {0.0, 0.5, 0.25};
  const int grids = std::clamp(options.grids, 1, 3);
  // With fine cells, between two grids whose worst-element measures are both at least mean_tie_break the
  // higher mean (before the mean stage) wins: both minima meet the targets, the mean decides.
  auto better = [&](const GridAttempt& x, const GridAttempt& y) {
    const QualitySummary& q = x.report.optimize.phases.back().quality;
    const QualitySummary& r = y.report.optimize.phases.back().quality;
    if (q.inverted != r.inverted) return q.inverted < r.inverted;
    const double wq = worst_element_measure(q), wr = worst_element_measure(r);
    if (x.fine && y.fine && wq >= options.mean_tie_break && wr >= options.mean_tie_break)
      return q.scaled_jacobian.mean > r.scaled_jacobian.mean;
    return wq > wr;
  };
  // The mean stage does not lower the worst-element measure that picks the grid, so it runs on the kept
  // grid only.
  OptimizeOptions per_grid = options.optimize;
  per_grid.mean_jacobian_sweeps = 0;
  OptimizeOptions per_swept = per_grid;
  per_swept.boundary_tether = options.swept_tether;
  per_swept.max_iterations = options.swept_newton_sweeps;
  OptimizeOptions per_swept_newton = per_swept;
  per_swept_newton.max_iterations = per_grid.max_iterations;
  // The attempts: with coarse cells the plain core on each grid. With fine cells the plain core
  // (fine_margin, the cells whose centre lies inside) on the unshifted and the half-shifted grid, and the
  // thick-margin core (thin plates keep their cells) on the half- and the quarter-shifted grid: the plain
  // core gave the better means and minima on the built-in mandible, the thick margin the real jaw's better
  // minima at 30,000-50,000 hexes and its coronoid tips, and which grid position wins varies with the size
  // (docs/meshing_experiments.md); four attempts take two rounds in two threads, as three did. Attempts 0
  // and 1 are the same either way; attempt 0's core (the calling thread computes it first) decides whether
  // the cells are fine.
  struct Job {
    double shift;
    CoreRule rule;
  };
  // The swept core (options.swept_core) replaces the grid cores: unshifted and shifted by half a cell.
  const bool swept = options.swept_core;
  Job jobs[4 + 2] = {{shifts[0], swept ? CoreRule::kSwept : CoreRule::kRegular},
                     {shifts[1], swept ? CoreRule::kSwept : CoreRule::kPlain}};
  int job_count = 0;  // set with jobs[2] and jobs[3] once attempt 0's core is known
  std::promise<void> jobs_known;
  const std::shared_future<void> jobs_ready = jobs_known.get_future().share();
  auto decide_jobs = [&](bool fine) {
    job_count = std::min(grids, 2);  // the swept core: these two only
    if (!swept && fine)
      for (int a = 1; a < grids; ++a) jobs[job_count++] = {shifts[a], CoreRule::kThick};
    else if (!swept && grids == 3)
      jobs[job_count++] = {shifts[2], CoreRule::kPlain};
    jobs_known.set_value();
  };
  std::vector<GridAttempt> attempts(4 + 2);  // four, and one retry of two at most
  std::vector<std::exception_ptr> errors(4 + 2);
  auto run_job = [&](int a) {
    try {
      const bool swept_job = jobs[a].rule == CoreRule::kSwept || jobs[a].rule == CoreRule::kSweptNewton;
      if (a > 0 && swept_job)
        attempts[a] = swept_attempt(grid_projector, lo, hi, options, jobs[a].shift, *arch);
      else if (a > 0)
        attempts[a] = grid_core(grid_projector, grid_shells, lo, hi, grid_volume, mean_thickness, options,
                                jobs[a].shift, jobs[a].rule, frame);
      const CoreRule rule = jobs[a].rule;
      pillow_and_optimize(attempts[a], projector,
                          rule == CoreRule::kSwept         ? per_swept
                          : rule == CoreRule::kSweptNewton ? per_swept_newton
                                                           : per_grid,
                          rule == CoreRule::kSwept ? options.swept_reach_far : 0.0);
    } catch (...) {
      errors[a] = std::current_exception();
    }
  };
  // The grids are independent: up to `threads` of them run at once (the calling thread shows progress,
  // the others are quiet). Each attempt's result depends only on its shift and core rule, and the choice
  // below goes in attempt order, so the mesh does not depend on the number of threads.
  std::atomic<int> next{1};
  auto work = [&](bool quiet) {
    const QuietThread quiet_thread(quiet);
    for (int a = next++;; a = next++) {
      if (a >= 2) jobs_ready.wait();
      if (a >= (a < 2 ? std::min(grids, 2) : job_count)) break;
      run_job(a);
    }
  };
  {
    std::vector<std::thread> helpers;
    for (int t = 1; t < std::clamp(options.threads, 1, 4); ++t)
      if (!start_helper_thread(helpers, [&work] { work(true); })) break;  // the caller takes their jobs
    try {
      attempts[0] = swept ? swept_attempt(grid_projector, lo, hi, options, shifts[0], *arch)
                          : grid_core(grid_projector, grid_shells, lo, hi, grid_volume, mean_thickness,
                                      options, shifts[0], jobs[0].rule, frame);
      decide_jobs(attempts[0].fine);
      run_job(0);
    } catch (...) {
      errors[0] = std::current_exception();
      decide_jobs(false);
    }
    work(false);
    for (std::thread& t : helpers) t.join();
  }
  for (int a = 0; a < job_count; ++a)
    if (errors[a]) std::rethrow_exception(errors[a]);
  int best = 0;
  for (int a = 1; a < job_count; ++a)
    if (better(attempts[a], attempts[best])) best = a;
  // Meshes the attempts from job_count on that `add` appends (in up to `threads` threads) and keeps the
  // best of all.
  auto retry = [&](const std::vector<Job>& add) {
    const int from = job_count;
    for (const Job& job : add) jobs[job_count++] = job;
    std::atomic<int> next_retry{from};
    auto work_retry = [&](bool quiet) {
      const QuietThread quiet_thread(quiet);
      for (int a = next_retry++; a < job_count; a = next_retry++) run_job(a);
    };
    std::vector<std::thread> helpers;
    for (int t = 1; t < std::clamp(options.threads, 1, int(add.size())); ++t)
      if (!start_helper_thread(helpers, [&work_retry] { work_retry(true); })) break;
    work_retry(false);
    for (std::thread& t : helpers) t.join();
    for (int a = from; a < job_count; ++a)
      if (errors[a]) std::rethrow_exception(errors[a]);
    for (int a = from; a < job_count; ++a)
      if (better(attempts[a], attempts[best])) best = a;
  };
  auto worst_of = [&](int a) {
    return worst_element_measure(attempts[a].report.optimize.phases.back().quality);
  };
  // Where every fine attempt has a defect (a worst-element measure below retry_below, 0.3, not a minimum
  // merely short of 0.5), the grids with margin everywhere may do better (the real jaw at 35,000 hexes:
  // 0.19 at best with the fine cores, 0.352 / 0.306 with margin everywhere on the half- / quarter-shifted
  // grid), so they are tried too and the best of all kept. Only the shifted grids (the unshifted one gave
  // the jaw 0.199): two attempts are one round in two threads, three were two.
  const auto inverted_of = [&](int a) { return attempts[a].report.optimize.phases.back().quality.inverted; };
  if (swept && options.swept_reach_far > 0 && inverted_of(best) > 0) {
    // The swept retry: on short, wide rami (40 mm in a 75 mm arch, the generator's extreme corners) the swept
    // core without Newton sweeps can keep pillow hexes inverted (2 at 2,500 or 3,000 hexes), where its first
    // version, the Newton sweeps on and no tips pass before them, was valid: both grids again that way.
    std::vector<Job> add;
    for (int a = 0; a < std::min(grids, 2); ++a) add.push_back({shifts[a], CoreRule::kSweptNewton});
    retry(add);
  } else if (attempts[0].fine && worst_of(best) < options.retry_below) {
    std::vector<Job> add;
    for (int a = std::min(1, grids - 1); a < grids; ++a) add.push_back({shifts[a], CoreRule::kMargin});
    retry(add);
  } else if (attempts[0].fine && worst_of(0) < options.mean_tie_break &&
             worst_of(best) >= options.mean_tie_break) {
    // The mean retry: another grid meets the minimum, but the regular core (the better means) falls short
    // of it on the unshifted grid, which depends on where the grid falls (the built-in mandible at 20,000
    // and 25,000 hexes: 0.27 and 0.14 unshifted, 0.64-0.66 shifted): it is tried on the other grids too.
    std::vector<Job> add;
    for (int a = 1; a < grids; ++a) add.push_back({shifts[a], CoreRule::kRegular});
    if (!add.empty()) retry(add);
  }
  const int counted = job_count;
  GridMeshReport report = std::move(attempts[best].report);
  HexMesh mesh = std::move(attempts[best].mesh);
  const Selection kept = std::move(attempts[best].selection);
  const std::vector<Vec3> kept_pillowed = std::move(attempts[best].pillowed);  // nodes before optimization
  report.attempts = counted;

  auto t0 = std::chrono::steady_clock::now();
  if (options.optimize.mean_jacobian_sweeps > 0) {
    // Every node moves, boundary nodes slide, within worst_element_reach of where the pillow layer put them.
    const std::vector<char> movable(mesh.vertices.size(), 1);
    const std::vector<char> sliding = boundary_vertex_mask(mesh);
    report.optimize.mean_jacobian_sweeps =
        improve_mean_jacobian(mesh, movable, sliding, &projector, options.optimize, &kept_pillowed);
    PhaseQuality& final_phase = report.optimize.phases.back();
    final_phase.quality = summarize_quality(mesh);
    final_phase.seconds += seconds_since(t0);
    report.optimize.energy_after = condition_energy(mesh, nullptr);
    report.seconds_optimize += seconds_since(t0);
  }
  if (swept && options.swept_reach_far > 0 && report.optimize.inverted == 0) {
    t0 = std::chrono::steady_clock::now();
    reach_swept_tips(mesh, projector, options);
    PhaseQuality& final_phase = report.optimize.phases.back();
    final_phase.quality = summarize_quality(mesh);
    final_phase.seconds += seconds_since(t0);
    report.seconds_optimize += seconds_since(t0);
  }
  if (options.fit_volume && report.optimize.inverted == 0) {
    report.volume_fit = fit_boundary_to_volume(mesh, projector, {});
    report.optimize.phases.push_back({"volume fit", summarize_quality(mesh), report.volume_fit->seconds});
  }
  t0 = std::chrono::steady_clock::now();
  report.fidelity = measure_fidelity(mesh, projector);
  if (kept.dropped > 0) {
    UnresolvedPart part;
    part.location = frame.to_body(kept.dropped_centroid);
    part.samples = kept.dropped;
    part.what =
        std::to_string(kept.dropped) + " grid cells around " + format_point_mm(part.location) +
        " were not face-connected to the main core and were dropped (a narrow neck at this cell size)";
    report.fidelity.unresolved.insert(report.fidelity.unresolved.begin(), part);
  }
  std::ostringstream cell;
  cell.precision(2);
  cell << std::fixed << kept.grid.h;
  for (auto j = kept.joined.rbegin(); j != kept.joined.rend(); ++j) {
    UnresolvedPart part;
    part.location = frame.to_body(j->contact);
    std::string around;
    for (int b : j->bodies)
      around += (around.empty()          ? ""
                 : b == j->bodies.back() ? " and "
                                         : ", ") +
                format_point_mm(scale(add(shells.body_lo[b], shells.body_hi[b]), 0.5));
    part.what = "the separate shells of the surface around " + around + " come closer than a cell (" +
                cell.str() + " mm) near " + format_point_mm(part.location) +
                ": the mesh joins them across the gap; ask for more hexes to resolve it";
    report.fidelity.unresolved.insert(report.fidelity.unresolved.begin(), part);
  }
  for (auto m = kept.missed.rbegin(); m != kept.missed.rend(); ++m) {
    UnresolvedPart part;
    // The body's box on the surface itself (not in arch coordinates).
    const Vec3 &body_lo = shells.body_lo[m->body], &body_hi = shells.body_hi[m->body];
    part.location = scale(add(body_lo, body_hi), 0.5);
    part.samples = int(shells.body_triangles[m->body]);
    std::ostringstream size;
    size.precision(1);
    size << std::fixed << body_hi[0] - body_lo[0] << " x " << body_hi[1] - body_lo[1] << " x "
         << body_hi[2] - body_lo[2] << " mm";
    // The fidelity check finds the same shell far from the mesh: its distance goes here, once.
    auto& found = report.fidelity.unresolved;
    for (auto f = found.begin(); f != found.end(); ++f) {
      bool in_box = f->what.rfind("the whole separate shell near", 0) == 0;
      for (int a = 0; a < 3; ++a)
        in_box = in_box && f->location[a] >= body_lo[a] - 1e-9 && f->location[a] <= body_hi[a] + 1e-9;
      if (!in_box) continue;
      part.extent = f->extent;
      found.erase(f);
      break;
    }
    std::ostringstream extent;
    extent.precision(1);
    extent << std::fixed << part.extent;
    part.what = "a separate shell of the surface around " + format_point_mm(part.location) + " (" +
                size.str() + ") holds no grid cell centre at this cell size (" + cell.str() +
                " mm) and was not meshed (it lies up to " + extent.str() +
                " mm from the mesh): a body smaller or thinner than a cell; ask for more hexes to resolve it";
    report.fidelity.unresolved.insert(report.fidelity.unresolved.begin(), part);
  }
  report.seconds_fidelity = seconds_since(t0);
  report.seconds_total = seconds_since(t_start);
  report.principal_frame = principal.has_value() && !options.face_frame;
  report.face_frame = principal.has_value() && options.face_frame;
  if (report_out) *report_out = std::move(report);
  return mesh;
}

std::string principal_retry_text(const PrincipalRetry& retry) {
  std::string text =
      "the grids along the coordinate axes left " + std::to_string(retry.axes_inverted) + " inverted hexes";
  if (retry.principal_inverted >= 0)
    text += "; along the solid's principal axes " + std::to_string(retry.principal_inverted);
  if (retry.faces_inverted >= 0)
    text += "; along its largest flat faces " + std::to_string(retry.faces_inverted);
  if (!retry.kept) return text + ": kept the first";
  return text + ": kept those along the " + (retry.kept_frame == "faces" ? "faces" : "principal axes");
}

HexMesh grid_mesh(const TriSurface& surface, const GridMeshOptions& options, GridMeshReport* report_out) {
  GridMeshReport report;
  HexMesh mesh = grid_mesh_in_frame(surface, options, &report);
  const bool retry = options.principal_retry && !options.principal_frame && !options.face_frame &&
                     !options.arch_frame && !options.swept_core && report.optimize.inverted > 0;
  if (retry) {
    PrincipalRetry tried;
    tried.axes_inverted = report.optimize.inverted;
    double seconds = report.seconds_total;
    int attempts = report.attempts;
    // Meshes in the frame and keeps that mesh when it has fewer inverted hexes, or as many and a better
    // worst element (step 5's order); its count.
    const auto measure = [](const GridMeshReport& r) {
      return worst_element_measure(r.optimize.phases.back().quality);
    };
    const auto mesh_along = [&](bool faces) {
      GridMeshOptions along = options;
      along.principal_frame = !faces;
      along.face_frame = faces;
      GridMeshReport other;
      HexMesh other_mesh = grid_mesh_in_frame(surface, along, &other);
      seconds += other.seconds_total;
      attempts += other.attempts;
      const int inverted = other.optimize.inverted;
      if (inverted < report.optimize.inverted ||
          (inverted == report.optimize.inverted && tried.kept && measure(other) > measure(report))) {
        mesh = std::move(other_mesh);
        report = std::move(other);
        tried.kept = true;
        tried.kept_frame = faces ? "faces" : "principal";
      }
      return inverted;
    };
    const std::optional<PrincipalFrame> principal = principal_frame(surface);
    if (principal && !principal->along_coordinate_axes()) tried.principal_inverted = mesh_along(false);
    // The faces' frame also after a valid principal mesh: an L-shaped block's principal axes (its
    // diagonal) can give a valid but poor one (SJ min 0.22 against 0.66 along its faces).
    const std::optional<PrincipalFrame> faces = face_frame(surface);
    const bool tried_already =
        !faces || faces->along_coordinate_axes() ||
        (principal && !principal->along_coordinate_axes() && same_axes(*faces, *principal));
    if (!tried_already) tried.faces_inverted = mesh_along(true);
    if (tried.principal_inverted >= 0 || tried.faces_inverted >= 0) report.principal_retry = tried;
    report.seconds_total = seconds;
    report.attempts = attempts;
  }
  if (report_out) *report_out = std::move(report);
  return mesh;
}

}  // namespace hexbite
