#include "mesher/boundary_fit.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <utility>

#include "common/progress.h"
#include "mesher/hex_boundary.h"
#include "mesher/hex_quality_kernel.h"
#include "mesher/vec3.h"

namespace hexbite {

using vec3::add;
using vec3::cross;
using vec3::norm;
using vec3::scale;
using vec3::sub;

namespace {

// Signed distance of p to the surface, positive outside.
double signed_distance(const SurfaceProjector& surface, const Vec3& p) {
  const double d = surface.distance(p);
  return surface.inside(p) ? -d : d;
}

// Bilinear point of quad corners x at (u, v) in [0, 1]^2 and the area element there.
Vec3 bilinear(const std::array<Vec3, 4>& x, double u, double v, double* area) {
  const Vec3 du = add(scale(sub(x[1], x[0]), 1 - v), scale(sub(x[2], x[3]), v));
  const Vec3 dv = add(scale(sub(x[3], x[0]), 1 - u), scale(sub(x[2], x[1]), u));
  *area = norm(cross(du, dv));
  return add(add(scale(x[0], (1 - u) * (1 - v)), scale(x[1], u * (1 - v))),
             add(scale(x[2], u * v), scale(x[3], (1 - u) * v)));
}

HexQuality quality_of(const HexMesh& mesh, int e) {
  std::array<Vec3, 8> x;
  for (int i = 0; i < 8; ++i) x[i] = mesh.vertices[mesh.hexes[e][i]];
  return hex_quality(x);
}

// What both boundary passes check their moves against: each node's hexes, each hex's quality, and the
// mesh's smallest scaled Jacobian and largest condition number.
struct LocalQuality {
  std::vector<std::vector<int>> hexes_of;
  std::vector<HexQuality> quality;
  double sj_min = 1.0, kappa_max = 3.0;
  bool inverted = false;  // some hex is inverted

  explicit LocalQuality(const HexMesh& mesh) : hexes_of(mesh.vertices.size()), quality(mesh.hexes.size()) {
    for (std::size_t e = 0; e < mesh.hexes.size(); ++e) {
      for (int v : mesh.hexes[e]) hexes_of[v].push_back(static_cast<int>(e));
      quality[e] = quality_of(mesh, static_cast<int>(e));
      inverted = inverted || quality[e].inverted;
      sj_min = std::min(sj_min, quality[e].scaled_jacobian);
      kappa_max = std::max(kappa_max, quality[e].condition);
    }
  }
};

}  // namespace

BoundaryFitReport fit_boundary_to_volume(HexMesh& mesh, const SurfaceProjector& surface,
                                         const std::vector<char>& fixed, const BoundaryFitOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  BoundaryFitReport report;
  const HexBoundary boundary = extract_boundary(mesh);
  const std::vector<int>& ids = boundary.boundary_vertices;
  const auto& quads = boundary.surface.quads;
  const std::size_t nb = ids.size();
  report.boundary_nodes = static_cast<int>(nb);

  LocalQuality local(mesh);
  if (local.inverted) return report;  // only valid meshes are fitted
  auto& [hexes_of, quality, sj_min, kappa_max, inverted] = local;
  // Mean boundary edge length per node, for the offset limit.
  std::vector<double> edge(nb, 0.0);
  std::vector<int> edge_count(nb, 0);
  for (const auto& q : quads)
    for (int k = 0; k < 4; ++k) {
      const double len = norm(sub(mesh.vertices[ids[q[k]]], mesh.vertices[ids[q[(k + 1) % 4]]]));
      for (int w : {q[k], q[(k + 1) % 4]}) {
        edge[w] += len;
        ++edge_count[w];
      }
    }
  for (std::size_t i = 0; i < nb; ++i) edge[i] /= std::max(1, edge_count[i]);

  Progress progress("volume fit");
  constexpr std::array<double, 3> kSamples = {1.0 / 6, 0.5, 5.0 / 6};  // midpoint rule, 3 x 3
  for (int round = 0; round <= options.rounds; ++round) {
    std::vector<double> gap_sum(nb, 0.0), area_sum(nb, 0.0);
    std::vector<Vec3> normal(nb, Vec3{0, 0, 0});
    double total_gap = 0.0, total_area = 0.0;
    for (const auto& q : quads) {
      std::array<Vec3, 4> x;
      for (int k = 0; k < 4; ++k) x[k] = mesh.vertices[ids[q[k]]];
      double gap = 0.0, area = 0.0;
      for (double u : kSamples)
        for (double v : kSamples) {
          double da = 0.0;
          const Vec3 p = bilinear(x, u, v, &da);
          gap += da * signed_distance(surface, p);
          area += da;
        }
      const Vec3 n = cross(sub(x[2], x[0]), sub(x[3], x[1]));  // twice the area vector
      for (int k = 0; k < 4; ++k) {
        gap_sum[q[k]] += gap;
        area_sum[q[k]] += area;
        normal[q[k]] = add(normal[q[k]], n);
      }
      total_gap += gap;
      total_area += area;
    }
    const double mean_gap = total_area > 0 ? total_gap / total_area : 0.0;
    if (round == 0) report.mean_gap_before = mean_gap;
    report.mean_gap_after = mean_gap;
    if (round == options.rounds) break;
    progress.update(double(round) / options.rounds, "round " + std::to_string(round + 1));

    report.moved_nodes = 0;
    for (std::size_t i = 0; i < nb; ++i) {
      const int v = ids[i];
      if ((!fixed.empty() && fixed[v]) || area_sum[i] <= 0.0) continue;
      const double len = norm(normal[i]);
      if (len <= 0.0) continue;
      const Vec3 n = scale(normal[i], 1.0 / len);
      const Vec3 old = mesh.vertices[v];
      // Move out by the mean gap of the node's quads, but not farther than the limit from the surface.
      double step = -gap_sum[i] / area_sum[i];
      const double limit = options.max_offset * edge[i];
      const double now = signed_distance(surface, old);
      step = std::clamp(now + step, -limit, limit) - now;
      bool accepted = false;
      for (int halving = 0; halving < 4 && !accepted; ++halving, step *= 0.5) {
        mesh.vertices[v] = add(old, scale(n, step));
        accepted = true;
        for (int e : hexes_of[v]) {
          const HexQuality q = quality_of(mesh, e);
          if (q.scaled_jacobian < std::min(quality[e].scaled_jacobian, sj_min) ||
              q.scaled_jacobian < quality[e].scaled_jacobian - options.max_scaled_jacobian_drop ||
              q.condition > std::max(quality[e].condition, kappa_max)) {
            accepted = false;
            break;
          }
        }
        if (!accepted) ++report.limited_moves;
      }
      if (!accepted) {
        mesh.vertices[v] = old;
        continue;
      }
      for (int e : hexes_of[v]) quality[e] = quality_of(mesh, e);
      ++report.moved_nodes;
    }
  }
  progress.finish();
  for (int v : ids)
    report.max_node_offset = std::max(report.max_node_offset, surface.distance(mesh.vertices[v]));
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return report;
}

FarSurfaceReport reach_far_surface(HexMesh& mesh, const SurfaceProjector& surface,
                                   const FarSurfaceOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  FarSurfaceReport report;
  LocalQuality local(mesh);
  if (local.inverted && options.keep_worst) return report;  // only valid meshes keep their worst
  auto& [hexes_of, quality, sj_min, kappa_max, inverted] = local;
  const std::vector<Vec3>& samples = surface.surface().vertices;
  const double sj_bound =
      options.floor_scaled_jacobian > 0 ? std::min(sj_min, options.floor_scaled_jacobian) : sj_min;
  const double kappa_bound = std::max(kappa_max, options.max_condition);
  std::vector<char> ever_moved(mesh.vertices.size(), 0);
  // A surface vertex within the limit whose closest boundary quad kept its nodes is no farther now (that
  // quad's points are still there), so only the far vertices and those near moved nodes are measured again:
  // the same far vertices as measuring all, at a fraction of the queries on a fine surface (a 0.25 mm CT's
  // 394,000 vertices against a 4,000-hex boundary: this pass took half of the meshing time).
  std::vector<int> last_moved(mesh.vertices.size(), -1);  // the round in which a node last moved
  std::vector<double> known_distance(samples.size(), std::numeric_limits<double>::infinity());
  std::vector<int> known_quad(samples.size(), -1), known_round(samples.size(), -1);
  for (int round = 0; round < options.rounds; ++round) {
    const HexBoundary boundary = extract_boundary(mesh);
    const QuadSurface& q = boundary.surface;
    double length = 0.0;
    long edges = 0;
    for (const auto& quad : q.quads)
      for (int k = 0; k < 4; ++k, ++edges)
        length += norm(sub(q.vertices[quad[k]], q.vertices[quad[(k + 1) % 4]]));
    const double limit = options.limit * length / double(std::max(1L, edges));
    const SurfaceProjector boundary_surface(fan_triangles(q));
    std::vector<std::pair<double, int>> far;  // (distance, surface vertex), farthest first
    for (std::size_t v = 0; v < samples.size(); ++v) {
      if (known_quad[v] >= 0 && known_distance[v] <= limit) {
        const auto& quad = q.quads[static_cast<std::size_t>(known_quad[v])];
        if (std::none_of(quad.begin(), quad.end(), [&](int corner) {
              return last_moved[boundary.boundary_vertices[corner]] >= known_round[v];
            }))
          continue;
      }
      const SurfacePoint closest = boundary_surface.closest(samples[v]);
      known_distance[v] = closest.distance;
      known_quad[v] = closest.triangle / 4;  // fan_triangles: four triangles per quad, in quad order
      known_round[v] = round;
      if (closest.distance > limit) far.emplace_back(closest.distance, static_cast<int>(v));
    }
    std::sort(far.rbegin(), far.rend());
    if (round == 0) report.far_vertices = static_cast<int>(far.size());
    std::vector<char> used(mesh.vertices.size(), 0);
    int moved = 0;
    for (const auto& [distance, sample] : far) {
      const Vec3& p = samples[sample];
      int node = -1;
      double nearest = std::numeric_limits<double>::infinity();
      for (int v : boundary.boundary_vertices) {
        const double d = norm(sub(mesh.vertices[v], p));
        if (d < nearest) nearest = d, node = v;
      }
      if (node < 0 || used[node]) continue;
      used[node] = 1;
      const Vec3 old = mesh.vertices[node];
      Vec3 step = sub(p, old);
      bool accepted = false;
      for (int halving = 0; halving < 5 && !accepted; ++halving, step = scale(step, 0.5)) {
        mesh.vertices[node] = add(old, step);
        accepted = true;
        for (int e : hexes_of[node]) {
          const HexQuality h = quality_of(mesh, e);
          const bool pass =
              options.keep_worst
                  ? !h.inverted && h.scaled_jacobian >= std::min(quality[e].scaled_jacobian, sj_bound) &&
                        h.condition <= std::max(quality[e].condition, kappa_bound)
                  : h.scaled_jacobian >= std::min(quality[e].scaled_jacobian, options.min_scaled_jacobian);
          if (!pass) {
            accepted = false;
            break;
          }
        }
      }
      if (!accepted) {
        mesh.vertices[node] = old;
        continue;
      }
      for (int e : hexes_of[node]) quality[e] = quality_of(mesh, e);
      last_moved[node] = round;
      if (!ever_moved[node]) report.moved.push_back(node);
      ever_moved[node] = 1;
      ++moved;
    }
    report.moved_nodes += moved;
    if (moved == 0) break;
  }
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return report;
}

std::string describe(const BoundaryFitReport& fit) {
  char line[320];
  std::snprintf(line, sizeof line,
                "%d of %d boundary nodes moved along their normals (%d moves shortened to keep the hexes' "
                "quality); mean signed distance of the boundary to the surface %+.3f -> %+.3f mm, largest "
                "node offset %.2f mm",
                fit.moved_nodes, fit.boundary_nodes, fit.limited_moves, fit.mean_gap_before,
                fit.mean_gap_after, fit.max_node_offset);
  return line;
}

}  // namespace hexbite
