#include "mesher/hex_optimize.h"

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>

#include "common/progress.h"
#include "mesher/hex_boundary.h"
#include "mesher/hex_quality_kernel.h"
#include "mesher/surface_projector.h"

namespace hexbite {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kHexEdges[12][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6},
                                  {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};

using detail::cross;
using detail::dot;
using detail::sub;

Vec3 add(const Vec3& a, const Vec3& b) {
  return {a[0] + b[0], a[1] + b[1], a[2] + b[2]};
}
Vec3 scale(const Vec3& a, double s) {
  return {a[0] * s, a[1] * s, a[2] * s};
}
double norm(const Vec3& a) {
  return std::sqrt(dot(a, a));
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// kappa(A)^2 of the corner with columns a, b, c and its gradient with respect to the columns. Returns
// false (and leaves the outputs alone) when det(A) <= 0.
//   f = N1 N2 / d^2 with N1 = |A|_F^2, N2 = |adj A|_F^2 = |b x c|^2 + |c x a|^2 + |a x b|^2, d = det A;
//   dN2/da = 2 (|b|^2 + |c|^2) a - 2 (a.b) b - 2 (a.c) c (and cyclically), dd/da = b x c.
inline bool corner_energy(const Vec3& a, const Vec3& b, const Vec3& c, double& f, Vec3& ga, Vec3& gb,
                          Vec3& gc) {
  const Vec3 bc = cross(b, c), ca = cross(c, a), ab = cross(a, b);
  const double d = dot(a, bc);
  if (!(d > 0.0)) return false;
  const double aa = dot(a, a), bb = dot(b, b), cc = dot(c, c);
  const double ab_ = dot(a, b), ac = dot(a, c), bc_ = dot(b, c);
  const double n1 = aa + bb + cc;
  const double n2 = dot(bc, bc) + dot(ca, ca) + dot(ab, ab);
  const double inv_d2 = 1.0 / (d * d);
  f = n1 * n2 * inv_d2;
  const double t = 2.0 * f / d;
  for (int i = 0; i < 3; ++i) {
    const double dn2a = 2.0 * (bb + cc) * a[i] - 2.0 * ab_ * b[i] - 2.0 * ac * c[i];
    const double dn2b = 2.0 * (aa + cc) * b[i] - 2.0 * ab_ * a[i] - 2.0 * bc_ * c[i];
    const double dn2c = 2.0 * (aa + bb) * c[i] - 2.0 * ac * a[i] - 2.0 * bc_ * b[i];
    ga[i] = (2.0 * a[i] * n2 + n1 * dn2a) * inv_d2 - t * bc[i];
    gb[i] = (2.0 * b[i] * n2 + n1 * dn2b) * inv_d2 - t * ca[i];
    gc[i] = (2.0 * c[i] * n2 + n1 * dn2c) * inv_d2 - t * ab[i];
  }
  return true;
}

double hex_min_jacobian(const std::vector<Vec3>& x, const std::array<int, 8>& h) {
  Vec3 p[8];
  for (int i = 0; i < 8; ++i) p[i] = x[h[i]];
  double m = kInf;
  for (int k = 0; k < 8; ++k) {
    Vec3 a, b, c;
    hex_corner_columns(p, k, a, b, c);
    m = std::min(m, corner_jacobian(a, b, c));
  }
  return m;
}

// Node -> incident hexes and node -> edge neighbours, both in compressed rows, ascending.
struct Adjacency {
  std::vector<int> hex_start, hex_list;    // hexes around node v: hex_list[hex_start[v] .. hex_start[v+1])
  std::vector<int> edge_start, edge_list;  // edge neighbours of v

  explicit Adjacency(const HexMesh& mesh) {
    const std::size_t n = mesh.vertices.size();
    hex_start.assign(n + 1, 0);
    for (const auto& h : mesh.hexes)
      for (int v : h) ++hex_start[v + 1];
    for (std::size_t v = 0; v < n; ++v) hex_start[v + 1] += hex_start[v];
    hex_list.resize(hex_start[n]);
    std::vector<int> fill(hex_start.begin(), hex_start.end() - 1);
    for (std::size_t e = 0; e < mesh.hexes.size(); ++e)
      for (int v : mesh.hexes[e]) hex_list[fill[v]++] = static_cast<int>(e);

    std::vector<std::vector<int>> nb(n);
    for (const auto& h : mesh.hexes)
      for (const auto& e : kHexEdges) {
        nb[h[e[0]]].push_back(h[e[1]]);
        nb[h[e[1]]].push_back(h[e[0]]);
      }
    edge_start.assign(n + 1, 0);
    for (std::size_t v = 0; v < n; ++v) {
      std::sort(nb[v].begin(), nb[v].end());
      nb[v].erase(std::unique(nb[v].begin(), nb[v].end()), nb[v].end());
      edge_start[v + 1] = edge_start[v] + static_cast<int>(nb[v].size());
    }
    edge_list.reserve(edge_start[n]);
    for (std::size_t v = 0; v < n; ++v) edge_list.insert(edge_list.end(), nb[v].begin(), nb[v].end());
  }
};

// Mean length of the edges at each node: the length scale for relative movements and untangling.
std::vector<double> local_edge_length(const HexMesh& mesh, const Adjacency& adj) {
  std::vector<double> h(mesh.vertices.size(), 0.0);
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    const int b = adj.edge_start[v], e = adj.edge_start[v + 1];
    for (int i = b; i < e; ++i) h[v] += norm(sub(mesh.vertices[adj.edge_list[i]], mesh.vertices[v]));
    h[v] = e > b ? h[v] / (e - b) : 1.0;
    if (!(h[v] > 0.0)) h[v] = 1.0;
  }
  return h;
}

// Two unit vectors spanning the plane orthogonal to the unit vector n.
void tangent_frame(const Vec3& n, Vec3& t1, Vec3& t2) {
  const Vec3 helper = std::fabs(n[0]) < 0.6 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  t1 = cross(n, helper);
  t1 = scale(t1, 1.0 / norm(t1));
  t2 = cross(n, t1);
}

// Energy over the hexes flagged active, with the gradient accumulated per vertex in hex order (fixed
// summation order, so the result does not depend on anything but the input).
double active_energy(const HexMesh& mesh, const std::vector<char>& active, std::vector<Vec3>* gradient) {
  if (gradient) gradient->assign(mesh.vertices.size(), Vec3{0, 0, 0});
  double total = 0.0;
  for (std::size_t e = 0; e < mesh.hexes.size(); ++e) {
    if (!active.empty() && !active[e]) continue;
    const auto& h = mesh.hexes[e];
    Vec3 p[8];
    for (int i = 0; i < 8; ++i) p[i] = mesh.vertices[h[i]];
    for (int k = 0; k < 8; ++k) {
      Vec3 a, b, c, ga, gb, gc;
      hex_corner_columns(p, k, a, b, c);
      double f;
      if (!corner_energy(a, b, c, f, ga, gb, gc)) return kInf;
      total += f;
      if (gradient) {
        const int* nb = kHexCornerNeighbours[k];
        auto& g = *gradient;
        for (int i = 0; i < 3; ++i) {
          g[h[k]][i] -= ga[i] + gb[i] + gc[i];
          g[h[nb[0]]][i] += ga[i];
          g[h[nb[1]]][i] += gb[i];
          g[h[nb[2]]][i] += gc[i];
        }
      }
    }
  }
  return total;
}

// The corners whose Jacobian depends on one node, with the affine dependence det = d0 + g . (p - p0).
struct CornerRef {
  int hex;
  int corner;
};

void corners_of_node(const HexMesh& mesh, const Adjacency& adj, int v, std::vector<CornerRef>& out) {
  out.clear();
  for (int i = adj.hex_start[v]; i < adj.hex_start[v + 1]; ++i) {
    const int e = adj.hex_list[i];
    const auto& h = mesh.hexes[e];
    int l = 0;
    while (h[l] != v) ++l;
    for (int k = 0; k < 8; ++k) {
      const int* nb = kHexCornerNeighbours[k];
      if (k == l || nb[0] == l || nb[1] == l || nb[2] == l) out.push_back({e, k});
    }
  }
}

// Corner Jacobian of corner k of hex e and its gradient with respect to the position of node v.
double corner_det_and_gradient(const HexMesh& mesh, int e, int k, int v, Vec3& g) {
  const auto& h = mesh.hexes[e];
  const int* nb = kHexCornerNeighbours[k];
  const Vec3& x = mesh.vertices[h[k]];
  const Vec3 a = sub(mesh.vertices[h[nb[0]]], x), b = sub(mesh.vertices[h[nb[1]]], x),
             c = sub(mesh.vertices[h[nb[2]]], x);
  const Vec3 bc = cross(b, c), ca = cross(c, a), ab = cross(a, b);
  if (h[k] == v)
    g = scale(add(add(bc, ca), ab), -1.0);
  else if (h[nb[0]] == v)
    g = bc;
  else if (h[nb[1]] == v)
    g = ca;
  else
    g = ab;
  return dot(a, bc);
}

double min_corner_det(const HexMesh& mesh, const std::vector<CornerRef>& corners) {
  double m = kInf;
  for (const CornerRef& c : corners) {
    Vec3 p[8];
    for (int i = 0; i < 8; ++i) p[i] = mesh.vertices[mesh.hexes[c.hex][i]];
    Vec3 a, b, cc;
    hex_corner_columns(p, c.corner, a, b, cc);
    m = std::min(m, corner_jacobian(a, b, cc));
  }
  return m;
}

// One untangling visit of node v: damped Newton ascent on the soft minimum
//   S(p) = -(1/mu) log sum_i exp(-mu det_i(p) / h^3)
// of the corner Jacobians that depend on p (each is affine in p, so S is concave). A step is accepted only
// when the true minimum of those Jacobians grows. Returns true when the node moved.
bool untangle_node(HexMesh& mesh, const Adjacency& adj, int v, double h, bool sliding,
                   const SurfaceProjector* surface, std::vector<CornerRef>& corners) {
  corners_of_node(mesh, adj, v, corners);
  if (corners.empty()) return false;
  const double s = h * h * h;
  const double mu = 40.0;
  bool moved = false;
  for (int iter = 0; iter < 8; ++iter) {
    const std::size_t n = corners.size();
    std::vector<double> d(n);
    std::vector<Eigen::Vector3d> g(n);
    double dmin = kInf;
    for (std::size_t i = 0; i < n; ++i) {
      Vec3 gi;
      d[i] = corner_det_and_gradient(mesh, corners[i].hex, corners[i].corner, v, gi) / s;
      g[i] = Eigen::Vector3d(gi[0], gi[1], gi[2]) / s;
      dmin = std::min(dmin, d[i]);
    }
    double z = 0.0;
    std::vector<double> w(n);
    for (std::size_t i = 0; i < n; ++i) z += (w[i] = std::exp(-mu * (d[i] - dmin)));
    Eigen::Vector3d grad = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < n; ++i) grad += (w[i] / z) * g[i];
    Eigen::Matrix3d neg_hess = Eigen::Matrix3d::Zero();
    for (std::size_t i = 0; i < n; ++i) neg_hess += (w[i] / z) * g[i] * g[i].transpose();
    neg_hess = mu * (neg_hess - grad * grad.transpose());
    Eigen::Matrix3d basis = Eigen::Matrix3d::Identity();
    int dims = 3;
    if (sliding) {
      const SurfacePoint sp = surface->closest(mesh.vertices[v]);
      Vec3 t1, t2;
      tangent_frame(sp.normal, t1, t2);
      basis.col(0) = Eigen::Vector3d(t1[0], t1[1], t1[2]);
      basis.col(1) = Eigen::Vector3d(t2[0], t2[1], t2[2]);
      dims = 2;
    }
    const Eigen::MatrixXd b = basis.leftCols(dims);
    const Eigen::VectorXd rg = b.transpose() * grad;
    Eigen::MatrixXd rh = b.transpose() * neg_hess * b;
    // Levenberg damping: the soft minimum is flat along directions no active corner constrains.
    const double damping = 1e-3 * (rh.trace() / dims) + 1e-12 + 1e-2 * rg.norm() / h;
    rh += damping * Eigen::MatrixXd::Identity(dims, dims);
    Eigen::VectorXd step = rh.ldlt().solve(rg);
    if (!step.allFinite() || step.dot(rg) <= 0) step = rg;
    Eigen::Vector3d dp = b * step;
    const double max_len = 0.5 * h;
    if (dp.norm() > max_len) dp *= max_len / dp.norm();

    const Vec3 old = mesh.vertices[v];
    const double old_min = min_corner_det(mesh, corners);
    bool accepted = false;
    for (int bt = 0; bt < 12 && !accepted; ++bt) {
      Vec3 trial = {old[0] + dp[0], old[1] + dp[1], old[2] + dp[2]};
      if (sliding) trial = surface->closest(trial).point;
      mesh.vertices[v] = trial;
      if (min_corner_det(mesh, corners) > old_min + 1e-12 * s) {
        accepted = true;
      } else {
        dp *= 0.5;
      }
    }
    if (!accepted) {
      mesh.vertices[v] = old;
      break;
    }
    moved = true;
    if (min_corner_det(mesh, corners) > 0.05 * s) break;
  }
  return moved;
}

std::vector<char> inverted_mask(const HexMesh& mesh, int* count) {
  std::vector<char> inv(mesh.hexes.size(), 0);
  int c = 0;
  for (std::size_t e = 0; e < mesh.hexes.size(); ++e)
    if (!(hex_min_jacobian(mesh.vertices, mesh.hexes[e]) > 0.0)) inv[e] = 1, ++c;
  if (count) *count = c;
  return inv;
}

}  // namespace

double condition_energy(const HexMesh& mesh, std::vector<Vec3>* gradient) {
  return active_energy(mesh, {}, gradient);
}

void barycentric_smoothing(HexMesh& mesh, const std::vector<char>& movable, int iterations) {
  if (iterations <= 0) return;
  const Adjacency adj(mesh);
  std::vector<Vec3> next = mesh.vertices;
  Progress progress("barycentric smoothing");
  for (int it = 0; it < iterations; ++it) {
    for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
      if (!movable[v]) continue;
      const int b = adj.edge_start[v], e = adj.edge_start[v + 1];
      if (e == b) continue;
      Vec3 sum{0, 0, 0};
      for (int i = b; i < e; ++i) sum = add(sum, mesh.vertices[adj.edge_list[i]]);
      next[v] = scale(sum, 1.0 / (e - b));
    }
    mesh.vertices = next;
    progress.update(double(it + 1) / iterations, "pass " + std::to_string(it + 1));
  }
  progress.finish();
}

int move_inside(HexMesh& mesh, const SurfaceProjector& surface, const std::vector<char>& movable) {
  const Adjacency adj(mesh);
  const std::vector<double> h = local_edge_length(mesh, adj);
  int moved = 0;
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    if (!movable[v] || surface.inside(mesh.vertices[v])) continue;
    // Put the node a quarter of its edge length below the surface, along the normal at the closest point.
    const SurfacePoint sp = surface.closest(mesh.vertices[v]);
    mesh.vertices[v] = sub(sp.point, scale(sp.normal, 0.25 * h[v]));
    ++moved;
  }
  return moved;
}

int untangle(HexMesh& mesh, const std::vector<char>& movable, const std::vector<char>& sliding,
             const SurfaceProjector* surface, int max_sweeps) {
  const Adjacency adj(mesh);
  const std::vector<double> h = local_edge_length(mesh, adj);
  std::vector<CornerRef> corners;
  int inverted = 0;
  std::vector<char> inv = inverted_mask(mesh, &inverted);
  if (inverted == 0) return 0;
  Progress progress("untangling");
  int sweeps = 0, stalled = 0, ring = 0, best = inverted;
  while (inverted > 0 && sweeps < max_sweeps) {
    // The nodes to visit: those of the inverted hexes, widened by one ring of hexes after sweeps that did
    // not reduce the count (the tangle then needs room from its neighbours).
    std::vector<char> visit(mesh.vertices.size(), 0);
    for (std::size_t e = 0; e < mesh.hexes.size(); ++e)
      if (inv[e])
        for (int v : mesh.hexes[e]) visit[v] = 1;
    for (int r = 0; r < ring; ++r) {
      std::vector<char> wider = visit;
      for (std::size_t v = 0; v < visit.size(); ++v)
        if (visit[v])
          for (int i = adj.hex_start[v]; i < adj.hex_start[v + 1]; ++i)
            for (int w : mesh.hexes[adj.hex_list[i]]) wider[w] = 1;
      visit.swap(wider);
    }
    for (std::size_t v = 0; v < visit.size(); ++v)
      if (visit[v] && movable[v])
        untangle_node(mesh, adj, static_cast<int>(v), h[v], sliding.empty() ? false : sliding[v] != 0,
                      surface, corners);
    ++sweeps;
    inv = inverted_mask(mesh, &inverted);
    if (inverted < best) {
      best = inverted;
      stalled = 0;
    } else if (++stalled >= 2) {
      ring = std::min(ring + 1, 3);
      stalled = 0;
    }
    progress.update(double(sweeps) / max_sweeps,
                    "sweep " + std::to_string(sweeps) + ", " + std::to_string(inverted) + " inverted");
  }
  progress.finish(std::to_string(inverted) + " inverted");
  return sweeps;
}

int optimize_condition(HexMesh& mesh, const std::vector<char>& movable_in,
                       const std::vector<char>& sliding_in, const SurfaceProjector* surface,
                       const OptimizeOptions& options, int* rounds_out) {
  const std::size_t nv = mesh.vertices.size();
  const Adjacency adj(mesh);
  const std::vector<double> h = local_edge_length(mesh, adj);

  // Inverted hexes stay out of the objective and their nodes stay put, so that the energy is finite.
  int inverted = 0;
  const std::vector<char> inv = inverted_mask(mesh, &inverted);
  std::vector<char> active(mesh.hexes.size(), 1);
  std::vector<char> movable = movable_in;
  for (std::size_t e = 0; e < mesh.hexes.size(); ++e)
    if (inv[e]) {
      active[e] = 0;
      for (int v : mesh.hexes[e]) movable[v] = 0;
    }
  std::vector<char> sliding(nv, 0);
  for (std::size_t v = 0; v < nv; ++v)
    sliding[v] = movable[v] && surface != nullptr && !sliding_in.empty() && sliding_in[v];

  // Variables: three per free interior node, two (tangent-plane coordinates) per sliding node.
  std::vector<int> offset(nv, -1);
  int nvar = 0;
  for (std::size_t v = 0; v < nv; ++v)
    if (movable[v]) {
      offset[v] = nvar;
      nvar += sliding[v] ? 2 : 3;
    }
  if (rounds_out) *rounds_out = 0;
  if (nvar == 0) return 0;

  std::vector<Vec3> t1(nv), t2(nv);
  std::vector<Vec3> base = mesh.vertices;
  std::vector<Vec3> node_grad;
  Eigen::VectorXd z = Eigen::VectorXd::Zero(nvar), g(nvar);

  auto place = [&](const Eigen::VectorXd& zz) {
    for (std::size_t v = 0; v < nv; ++v) {
      const int o = offset[v];
      if (o < 0) continue;
      if (sliding[v]) {
        mesh.vertices[v] = add(base[v], add(scale(t1[v], zz[o]), scale(t2[v], zz[o + 1])));
      } else {
        mesh.vertices[v] = {base[v][0] + zz[o], base[v][1] + zz[o + 1], base[v][2] + zz[o + 2]};
      }
    }
  };
  auto evaluate = [&](const Eigen::VectorXd& zz, Eigen::VectorXd* gz) {
    place(zz);
    const double f = active_energy(mesh, active, gz ? &node_grad : nullptr);
    if (gz && f < kInf) {
      for (std::size_t v = 0; v < nv; ++v) {
        const int o = offset[v];
        if (o < 0) continue;
        if (sliding[v]) {
          (*gz)[o] = dot(node_grad[v], t1[v]);
          (*gz)[o + 1] = dot(node_grad[v], t2[v]);
        } else {
          for (int i = 0; i < 3; ++i) (*gz)[o + i] = node_grad[v][i];
        }
      }
    }
    return f;
  };
  // Largest node displacement for the variable step dz, relative to the node's edge length.
  auto relative_move = [&](const Eigen::VectorXd& dz) {
    double m = 0.0;
    for (std::size_t v = 0; v < nv; ++v) {
      const int o = offset[v];
      if (o < 0) continue;
      const double len = sliding[v]
                             ? std::hypot(dz[o], dz[o + 1])
                             : std::sqrt(dz[o] * dz[o] + dz[o + 1] * dz[o + 1] + dz[o + 2] * dz[o + 2]);
      m = std::max(m, len / h[v]);
    }
    return m;
  };

  const bool any_sliding = std::any_of(sliding.begin(), sliding.end(), [](char c) { return c != 0; });
  const int per_round = any_sliding ? options.iterations_per_round : options.max_iterations;
  Progress progress("condition number optimization");
  int iterations = 0, rounds = 0;
  bool done = false;
  while (!done && iterations < options.max_iterations) {
    // A new round: the current positions become the base, sliding nodes get a fresh tangent frame.
    base = mesh.vertices;
    for (std::size_t v = 0; v < nv; ++v)
      if (sliding[v]) tangent_frame(surface->closest(base[v]).normal, t1[v], t2[v]);
    z.setZero();
    double f = evaluate(z, &g);
    if (!(f < kInf)) break;  // cannot happen: the round starts from a valid state
    std::vector<Eigen::VectorXd> s_hist, y_hist;
    std::vector<double> rho_hist;
    int round_iterations = 0;
    bool converged = false;
    while (round_iterations < per_round && iterations < options.max_iterations) {
      // L-BFGS two-loop recursion.
      Eigen::VectorXd q = g;
      const int m = static_cast<int>(s_hist.size());
      std::vector<double> alpha(m);
      for (int i = m - 1; i >= 0; --i) {
        alpha[i] = rho_hist[i] * s_hist[i].dot(q);
        q -= alpha[i] * y_hist[i];
      }
      if (m > 0) q *= s_hist[m - 1].dot(y_hist[m - 1]) / y_hist[m - 1].dot(y_hist[m - 1]);
      for (int i = 0; i < m; ++i) {
        const double beta = rho_hist[i] * y_hist[i].dot(q);
        q += (alpha[i] - beta) * s_hist[i];
      }
      Eigen::VectorXd d = -q;
      double gd = g.dot(d);
      if (!(gd < 0.0)) {
        d = -g;
        gd = g.dot(d);
        s_hist.clear(), y_hist.clear(), rho_hist.clear();
      }
      // The first step and every steepest-descent step are scaled to move nodes at most a tenth of their
      // edge length; quasi-Newton steps start at 1 but are capped at half an edge length.
      const double rel = relative_move(d);
      double t = (s_hist.empty() ? 0.1 : 0.5) / std::max(rel, 1e-300);
      if (!s_hist.empty()) t = std::min(1.0, t);
      Eigen::VectorXd z_new, g_new(nvar);
      double f_new = kInf;
      bool accepted = false;
      for (int bt = 0; bt < 40; ++bt) {
        z_new = z + t * d;
        f_new = evaluate(z_new, &g_new);
        if (f_new < kInf && f_new <= f + 1e-4 * t * gd) {
          accepted = true;
          break;
        }
        t *= 0.5;
      }
      ++iterations;
      ++round_iterations;
      if (!accepted) {
        // Back to the last valid state; without curvature information there is nothing left to try.
        place(z);
        if (s_hist.empty()) {
          converged = true;
          break;
        }
        s_hist.clear(), y_hist.clear(), rho_hist.clear();
        continue;
      }
      const Eigen::VectorXd s = z_new - z;
      const Eigen::VectorXd y = g_new - g;
      const double move = relative_move(s);
      const double sy = s.dot(y);
      if (sy > 1e-12 * std::sqrt(s.squaredNorm() * y.squaredNorm())) {
        s_hist.push_back(s);
        y_hist.push_back(y);
        rho_hist.push_back(1.0 / sy);
        if (static_cast<int>(s_hist.size()) > options.lbfgs_memory) {
          s_hist.erase(s_hist.begin());
          y_hist.erase(y_hist.begin());
          rho_hist.erase(rho_hist.begin());
        }
      }
      z = z_new;
      g = g_new;
      const double decrease = f - f_new;
      f = f_new;
      progress.update(double(iterations) / options.max_iterations,
                      "iteration " + std::to_string(iterations) + ", move " + std::to_string(move));
      if (move < options.tolerance || decrease <= 1e-14 * f) {
        converged = true;
        break;
      }
    }
    place(z);
    ++rounds;
    double projection_move = 0.0;
    if (any_sliding) {
      // Project the sliding nodes back onto the surface. Where that inverts a hex, its nodes return to the
      // round's start (which was valid); repeated until every hex around a returned node is valid again.
      const std::vector<Vec3> before = mesh.vertices;
      for (std::size_t v = 0; v < nv; ++v)
        if (sliding[v]) mesh.vertices[v] = surface->closest(mesh.vertices[v]).point;
      std::vector<int> check;
      for (std::size_t e = 0; e < mesh.hexes.size(); ++e) check.push_back(static_cast<int>(e));
      while (!check.empty()) {
        std::vector<int> next;
        std::vector<char> reverted(nv, 0);
        for (int e : check) {
          if (!active[e] || hex_min_jacobian(mesh.vertices, mesh.hexes[e]) > 0.0) continue;
          for (int v : mesh.hexes[e])
            if (mesh.vertices[v] != base[v]) {
              mesh.vertices[v] = base[v];
              reverted[v] = 1;
            }
        }
        for (std::size_t v = 0; v < nv; ++v)
          if (reverted[v])
            for (int i = adj.hex_start[v]; i < adj.hex_start[v + 1]; ++i) next.push_back(adj.hex_list[i]);
        std::sort(next.begin(), next.end());
        next.erase(std::unique(next.begin(), next.end()), next.end());
        check.swap(next);
      }
      for (std::size_t v = 0; v < nv; ++v)
        if (sliding[v])
          projection_move = std::max(projection_move, norm(sub(mesh.vertices[v], before[v])) / h[v]);
    }
    if (converged && (round_iterations <= 1 || !any_sliding) && projection_move < 10 * options.tolerance)
      done = true;
    if (!any_sliding) done = true;
  }
  progress.finish(std::to_string(iterations) + " iterations, " + std::to_string(rounds) + " rounds");
  if (rounds_out) *rounds_out = rounds;
  return iterations;
}

OptimizeReport optimize_hex_mesh(HexMesh& mesh, const SurfaceProjector* surface,
                                 const std::vector<char>& fixed, const OptimizeOptions& options) {
  const std::size_t nv = mesh.vertices.size();
  const std::vector<char> boundary = boundary_vertex_mask(mesh);
  const bool slide = surface != nullptr && options.slide_boundary;
  std::vector<char> movable(nv, 0), interior(nv, 0), sliding(nv, 0);
  for (std::size_t v = 0; v < nv; ++v) {
    const bool free = fixed.empty() || !fixed[v];
    interior[v] = free && !boundary[v];
    sliding[v] = free && boundary[v] && slide;
    movable[v] = interior[v] || sliding[v];
  }

  OptimizeReport report;
  // Energies cover the valid hexes only: an inverted hex has none.
  std::vector<char> valid = inverted_mask(mesh, nullptr);
  for (char& c : valid) c = !c;
  report.energy_before = active_energy(mesh, valid, nullptr);

  auto t0 = std::chrono::steady_clock::now();
  barycentric_smoothing(mesh, interior, options.barycentric_iterations);
  if (surface != nullptr && options.barycentric_iterations > 0) move_inside(mesh, *surface, interior);
  report.phases.push_back({"barycentric", summarize_quality(mesh), seconds_since(t0)});

  t0 = std::chrono::steady_clock::now();
  report.untangle_sweeps += untangle(mesh, movable, sliding, surface, options.max_untangle_sweeps);
  report.phases.push_back({"untangled", summarize_quality(mesh), seconds_since(t0)});

  t0 = std::chrono::steady_clock::now();
  for (int repeat = 0; repeat < options.max_repeats && report.iterations < options.max_iterations; ++repeat) {
    int rounds = 0;
    OptimizeOptions remaining = options;
    remaining.max_iterations = options.max_iterations - report.iterations;
    report.iterations += optimize_condition(mesh, movable, sliding, surface, remaining, &rounds);
    report.rounds += rounds;
    int inverted = 0;
    inverted_mask(mesh, &inverted);
    if (inverted == 0) break;
    report.untangle_sweeps += untangle(mesh, movable, sliding, surface, options.max_untangle_sweeps);
  }
  report.phases.push_back({"final", summarize_quality(mesh), seconds_since(t0)});
  report.inverted = report.phases.back().quality.inverted;
  valid = inverted_mask(mesh, nullptr);
  for (char& c : valid) c = !c;
  report.energy_after = active_energy(mesh, valid, nullptr);
  return report;
}

}  // namespace hexbite
