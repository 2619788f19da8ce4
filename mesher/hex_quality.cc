#include "mesher/hex_quality.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <utility>

#include "mesher/hex_boundary.h"

namespace hexbite {

namespace {

// Statistics over the values selected by `use`; the sum runs in element order, so the mean is reproducible.
template <typename Use>
MeasureStats stats_of(const std::vector<double>& values, Use use) {
  MeasureStats s;
  double sum = 0.0;
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!use(i)) continue;
    const double v = values[i];
    if (s.count == 0) {
      s.min = v;
      s.max = v;
    } else {
      s.min = std::min(s.min, v);
      s.max = std::max(s.max, v);
    }
    sum += v;
    ++s.count;
  }
  if (s.count > 0) s.mean = sum / s.count;
  return s;
}

void count_degree(std::vector<int>& histogram, int& max_degree, int degree) {
  if (degree >= static_cast<int>(histogram.size())) histogram.resize(degree + 1, 0);
  ++histogram[degree];
  max_degree = std::max(max_degree, degree);
}

}  // namespace

HexQualityField compute_hex_quality(const HexMesh& mesh) {
  const std::size_t m = mesh.hexes.size();
  HexQualityField field;
  field.jacobian.resize(m);
  field.scaled_jacobian.resize(m);
  field.condition.resize(m);
  field.oddy.resize(m);
  for (std::size_t h = 0; h < m; ++h) {
    Vec3 x[8];
    for (int k = 0; k < 8; ++k) x[k] = mesh.vertices[mesh.hexes[h][k]];
    const HexQuality q = hex_quality(x);
    field.jacobian[h] = q.jacobian;
    field.scaled_jacobian[h] = q.scaled_jacobian;
    field.condition[h] = q.condition;
    field.oddy[h] = q.oddy;
  }
  return field;
}

Histogram make_histogram(const std::vector<double>& values, double lo, double hi, int bins) {
  Histogram hist;
  hist.lo = lo;
  hist.hi = hi;
  hist.counts.assign(std::max(bins, 1), 0);
  const double width = (hi - lo) / hist.counts.size();
  for (double v : values) {
    if (!(v >= lo)) {
      ++hist.below;
    } else if (v > hi) {
      ++hist.above;
    } else {
      // The clamp puts v == hi (a perfect hex's scaled Jacobian of 1) and any rounding of (v - lo) / width
      // up to the bin count into the last bin.
      const int bin = std::min(static_cast<int>((v - lo) / width), static_cast<int>(hist.counts.size()) - 1);
      ++hist.counts[bin];
    }
  }
  return hist;
}

NodeDegrees node_degrees(const HexMesh& mesh) {
  static constexpr int kEdges[12][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6},
                                        {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
  const std::size_t n = mesh.vertices.size();
  std::vector<std::pair<int, int>> edges;
  edges.reserve(mesh.hexes.size() * 12);
  std::vector<int> hex_count(n, 0);
  for (const auto& hex : mesh.hexes) {
    for (const auto& e : kEdges) {
      const int a = hex[e[0]], b = hex[e[1]];
      edges.emplace_back(std::min(a, b), std::max(a, b));
    }
    for (int v : hex) ++hex_count[v];
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  std::vector<int> edge_count(n, 0);
  for (const auto& [a, b] : edges) {
    ++edge_count[a];
    ++edge_count[b];
  }

  const std::vector<char> on_boundary = boundary_vertex_mask(mesh);
  NodeDegrees d;
  for (std::size_t v = 0; v < n; ++v) {
    // Unused vertices (no hex) are neither interior nor boundary nodes.
    if (on_boundary[v] || hex_count[v] == 0) continue;
    ++d.interior_nodes;
    count_degree(d.edges, d.max_edges, edge_count[v]);
    count_degree(d.hexes, d.max_hexes, hex_count[v]);
  }
  return d;
}

QualitySummary summarize_quality(const HexMesh& mesh) {
  return summarize_quality(mesh, compute_hex_quality(mesh));
}

QualitySummary summarize_quality(const HexMesh& mesh, const HexQualityField& field) {
  QualitySummary s;
  s.hexes = static_cast<int>(mesh.hexes.size());
  s.nodes = static_cast<int>(mesh.vertices.size());
  std::vector<char> valid(field.jacobian.size());
  for (std::size_t h = 0; h < field.jacobian.size(); ++h) {
    // The element Jacobian is the minimum corner Jacobian, so this is the "any corner <= 0" rule; the
    // negated comparison also counts a NaN hex as inverted.
    valid[h] = field.jacobian[h] > 0.0;
    if (!valid[h]) s.inverted_hexes.push_back(static_cast<int>(h));
  }
  s.inverted = static_cast<int>(s.inverted_hexes.size());
  const auto all = [](std::size_t) { return true; };
  const auto only_valid = [&](std::size_t h) { return valid[h] != 0; };
  s.jacobian = stats_of(field.jacobian, all);
  s.scaled_jacobian = stats_of(field.scaled_jacobian, all);
  s.condition = stats_of(field.condition, only_valid);
  s.oddy = stats_of(field.oddy, only_valid);
  s.condition_verdict = s.condition;
  s.condition_verdict.min /= 3.0;
  s.condition_verdict.mean /= 3.0;
  s.condition_verdict.max /= 3.0;
  s.node_degree = node_degrees(mesh);
  s.scaled_jacobian_histogram = make_histogram(field.scaled_jacobian, -1.0, 1.0, 20);
  s.condition_histogram = make_histogram(field.condition, 3.0, 13.0, 20);
  s.oddy_histogram = make_histogram(field.oddy, 0.0, 20.0, 20);
  return s;
}

std::string hex_list_text(const HexMesh& mesh, const std::vector<int>& hexes, std::size_t shown,
                          const std::function<std::string(int)>& label) {
  std::ostringstream out;
  shown = std::min(shown, hexes.size());
  for (std::size_t i = 0; i < shown; ++i) {
    const int h = hexes[i];
    const Vec3 c = hex_centroid(mesh, h);
    char buf[128];
    std::snprintf(buf, sizeof buf, " at (%.2f, %.2f, %.2f) mm", c[0], c[1], c[2]);
    out << (i ? ", " : "") << "hex " << h << (label ? label(h) : std::string()) << buf;
  }
  if (shown < hexes.size()) out << " and " << hexes.size() - shown << " more";
  return out.str();
}

std::string hex_count_text(std::size_t n) {
  return std::to_string(n) + (n == 1 ? " hex" : " hexes");
}

std::string stay_inverted_text(const HexMesh& mesh, const std::vector<int>& inverted) {
  return hex_count_text(inverted.size()) + (inverted.size() == 1 ? " stays" : " stay") +
         " inverted after optimization: " + hex_list_text(mesh, inverted);
}

}  // namespace hexbite
