#include "mesher/swept_core.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/error.h"
#include "common/progress.h"
#include "mesher/cell_size_search.h"

namespace hexbite {

namespace {

// The bone along the line across the arch at (s, z): between the line's outermost crossings of the surface.
struct Interval {
  double a = 0, b = 0;
  int crossings = 0;  // 0: the line misses the bone
  double thickness() const { return crossings >= 2 ? b - a : 0.0; }
};

Interval across(const SurfaceProjector& surface, double s, double z, double t_lo, double t_hi) {
  std::vector<double> t;
  // A line that grazes an edge or a vertex gives no reliable crossings: it is moved by a hair and tried
  // again.
  for (int nudge = 0; nudge < 3; ++nudge) {
    const double d = nudge * 1e-6 * (t_hi - t_lo);
    if (surface.segment_crossings({s + d, t_lo, z + 0.7 * d}, {s + d, t_hi, z + 0.7 * d}, &t)) break;
    t.clear();
  }
  if (t.size() < 2) return {};
  return {t_lo + t.front() * (t_hi - t_lo), t_lo + t.back() * (t_hi - t_lo), int(t.size())};
}

// One trial size: the (s, z) grid and its selected columns.
struct Layout {
  double h = 0, s0 = 0, z0 = 0;
  int ns = 0, nz = 0;
  std::vector<Interval> centre;  // per cell, at its centre
  std::vector<char> selected;
  long columns = 0, outline_edges = 0, dropped = 0;
  long cell(int i, int j) const { return long(j) * ns + i; }
};

Layout lay_out(const SurfaceProjector& surface, const Vec3& lo, const Vec3& hi, double h, double shift,
               const SweptCoreOptions& options) {
  Layout l;
  // Whole cells along the arch: both ends of the bone's span on the same place in a cell, so a
  // mirror-symmetric mandible gets a mirror-symmetric core (before, from lo[0] alone: the default scenario
  // bitten on the left gave condyle reactions 5-6 N off the mirrored right bite).
  const double span = hi[0] - lo[0];
  h = span / std::max(1.0, std::round(span / h));
  l.h = h;
  l.s0 = lo[0] - h * (1.0 - shift);
  l.z0 = lo[2] - h * (1.0 - shift);
  l.ns = int(std::ceil((hi[0] - l.s0) / h)) + 1;
  l.nz = int(std::ceil((hi[2] - l.z0) / h)) + 1;
  const double t_lo = lo[1] - h, t_hi = hi[1] + h;
  l.centre.resize(std::size_t(l.ns) * l.nz);
  l.selected.assign(l.centre.size(), 0);
  for (int j = 0; j < l.nz; ++j)
    for (int i = 0; i < l.ns; ++i) {
      const long c = l.cell(i, j);
      l.centre[c] = across(surface, l.s0 + (i + 0.5) * h, l.z0 + (j + 0.5) * h, t_lo, t_hi);
      l.selected[c] = l.centre[c].thickness() >= options.min_thickness_cells * h;
    }
  l.dropped = detail::keep_manifold_columns(l.selected, l.ns, l.nz);
  for (int j = 0; j < l.nz; ++j)
    for (int i = 0; i < l.ns; ++i) {
      if (!l.selected[l.cell(i, j)]) continue;
      ++l.columns;
      const int next[4][2] = {{i - 1, j}, {i + 1, j}, {i, j - 1}, {i, j + 1}};
      for (const auto& n : next)
        if (n[0] < 0 || n[0] >= l.ns || n[1] < 0 || n[1] >= l.nz || !l.selected[l.cell(n[0], n[1])])
          ++l.outline_edges;
    }
  return l;
}

// The hexes of the kept layout, `layers` per column.
SweptCore build(const SurfaceProjector& surface, const Vec3& lo, const Vec3& hi, const Layout& l,
                const SweptCoreOptions& options) {
  SweptCore out;
  out.cell_size = l.h;
  out.grid = {l.ns, options.layers, l.nz};
  out.columns = l.columns;
  out.outline_edges = l.outline_edges;
  out.dropped_columns = l.dropped;
  const double t_lo = lo[1] - l.h, t_hi = hi[1] + l.h;
  const int nv = l.ns + 1;
  auto vertex = [nv](int i, int j) { return long(j) * nv + i; };
  std::vector<int> id(std::size_t(nv) * (l.nz + 1), -1);
  for (int j = 0; j < l.nz; ++j)
    for (int i = 0; i < l.ns; ++i)
      if (l.selected[l.cell(i, j)])
        for (int b = 0; b < 4; ++b) id[vertex(i + (b & 1), j + (b >> 1))] = 0;
  const int layers = options.layers;
  for (long v = 0; v < long(id.size()); ++v) {
    if (id[v] < 0) continue;
    const int i = int(v % nv), j = int(v / nv);
    const double s = l.s0 + i * l.h, z = l.z0 + j * l.h;
    Interval bone = across(surface, s, z, t_lo, t_hi);
    if (bone.crossings > 2) ++out.split_vertices;
    if (bone.thickness() < 0.5 * options.min_thickness_cells * l.h) {
      // Outside the side view (or nearly): the mean interval of the vertex's columns.
      Interval mean{0, 0, 2};
      int n = 0;
      for (int b = 0; b < 4; ++b) {
        const int ci = i - 1 + (b & 1), cj = j - 1 + (b >> 1);
        if (ci < 0 || cj < 0 || ci >= l.ns || cj >= l.nz || !l.selected[l.cell(ci, cj)]) continue;
        mean.a += l.centre[l.cell(ci, cj)].a;
        mean.b += l.centre[l.cell(ci, cj)].b;
        ++n;
      }
      bone = {mean.a / n, mean.b / n, 2};
    }
    // Both faces pulled in by a third of a cell, or of the thickness where the bone is thinner.
    const double inset = std::min(l.h, bone.thickness()) / 3.0;
    const double a = bone.a + inset, b = bone.b - inset;
    id[v] = int(out.mesh.vertices.size());
    for (int k = 0; k <= layers; ++k) out.mesh.vertices.push_back({s, a + (b - a) * k / layers, z});
  }
  // Axes (s, t, z) in the order of core_mesh's (x, y, z), which is right-handed in arch coordinates.
  for (int j = 0; j < l.nz; ++j)
    for (int i = 0; i < l.ns; ++i) {
      if (!l.selected[l.cell(i, j)]) continue;
      const int p = id[vertex(i, j)], q = id[vertex(i + 1, j)], r = id[vertex(i + 1, j + 1)],
                w = id[vertex(i, j + 1)];
      for (int k = 0; k < layers; ++k)
        out.mesh.hexes.push_back({p + k, q + k, q + k + 1, p + k + 1, w + k, r + k, r + k + 1, w + k + 1});
    }
  return out;
}

}  // namespace

namespace detail {

// The components first: a cell outside the largest set that meets one of it at a corner goes with its own
// set, instead of taking the largest set's cell with it (the later of the two).
long keep_manifold_columns(std::vector<char>& selected, int ns, int nz) {
  long dropped = 0;
  auto cell = [ns](int i, int j) { return long(j) * ns + i; };
  for (bool changed = true; changed;) {
    changed = false;
    std::vector<int> component(selected.size(), -1);
    int largest = -1, count = 0;
    long largest_size = 0;
    for (long c = 0; c < long(selected.size()); ++c) {
      if (!selected[c] || component[c] >= 0) continue;
      std::vector<long> stack{c};
      component[c] = count;
      long size = 0;
      while (!stack.empty()) {
        const long x = stack.back();
        stack.pop_back();
        ++size;
        const int i = int(x % ns), j = int(x / ns);
        const int next[4][2] = {{i - 1, j}, {i + 1, j}, {i, j - 1}, {i, j + 1}};
        for (const auto& n : next) {
          if (n[0] < 0 || n[0] >= ns || n[1] < 0 || n[1] >= nz) continue;
          const long y = cell(n[0], n[1]);
          if (selected[y] && component[y] < 0) component[y] = count, stack.push_back(y);
        }
      }
      if (size > largest_size) largest_size = size, largest = count;
      ++count;
    }
    for (long c = 0; c < long(selected.size()); ++c)
      if (selected[c] && component[c] != largest) selected[c] = 0, changed = true, ++dropped;
    for (int j = 0; j + 1 < nz; ++j)
      for (int i = 0; i + 1 < ns; ++i) {
        const long c00 = cell(i, j), c10 = c00 + 1, c01 = c00 + ns, c11 = c01 + 1;
        if (selected[c00] && selected[c11] && !selected[c10] && !selected[c01])
          selected[c11] = 0, changed = true, ++dropped;
        if (selected[c10] && selected[c01] && !selected[c00] && !selected[c11])
          selected[c01] = 0, changed = true, ++dropped;
      }
  }
  return dropped;
}

}  // namespace detail

SweptCore swept_core(const SurfaceProjector& straightened, const Vec3& lo, const Vec3& hi, long target_hexes,
                     double shift, const SweptCoreOptions& options) {
  if (options.layers < 1)
    throw std::invalid_argument("swept_core: layers must be at least 1, got " +
                                std::to_string(options.layers));
  // Start where a third of the side view's box holds the columns: the secant steps correct it.
  const double target = double(target_hexes);
  const double per_column = options.layers + 2.5;
  double h = std::sqrt((hi[0] - lo[0]) * (hi[2] - lo[2]) / 3.0 / (target / per_column));
  Progress progress("swept core");
  Layout best;
  double best_error = std::numeric_limits<double>::infinity();
  // The count falls like h^-2 (columns) to h^-1 (outline); start from the slope -2.
  CellSizeSearch size_search(target, -2.0, -0.5);
  for (int step = 0; step < 8; ++step) {
    Layout l = lay_out(straightened, lo, hi, h, shift, options);
    const double total = double(l.columns * (options.layers + 2) + l.outline_edges * options.layers);
    const double error = std::fabs(total - target) / target;
    if (l.columns > 0 && error < best_error) best_error = error, best = std::move(l);
    progress.update(double(step + 1) / 8,
                    "h = " + std::to_string(h) + " mm, " + std::to_string(long(total)) + " hexes");
    if (best_error < 0.02) break;
    h = size_search.next(h, total);
  }
  if (best.columns == 0) {
    std::ostringstream thick;
    thick << options.min_thickness_cells;
    throw InputError(
        "swept core: no column of the bone's side view holds it " + thick.str() +
        " cells thick at any trial cell size for " + std::to_string(target_hexes) +
        " hexes; ask for more hexes, or use the grid core (--core grid; in a scenario core: grid)");
  }
  return build(straightened, lo, hi, best, options);
}

}  // namespace hexbite
