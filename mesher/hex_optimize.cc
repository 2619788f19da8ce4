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

using vec3::add;
using vec3::norm;
using vec3::scale;

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

// The directions a node may step in, as columns: the three axes, or for a node sliding on the surface
// (foot = its closest surface point) two unit vectors spanning the tangent plane there.
Eigen::Matrix<double, 3, Eigen::Dynamic> step_basis(const SurfacePoint* foot) {
  if (!foot) return Eigen::Matrix3d::Identity();
  const Vec3& n = foot->normal;
  const Vec3 helper = std::fabs(n[0]) < 0.6 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  Vec3 t1 = cross(n, helper);
  t1 = scale(t1, 1.0 / norm(t1));
  const Vec3 t2 = cross(n, t1);
  Eigen::Matrix<double, 3, Eigen::Dynamic> basis(3, 2);
  basis.col(0) = Eigen::Vector3d(t1[0], t1[1], t1[2]);
  basis.col(1) = Eigen::Vector3d(t2[0], t2[1], t2[2]);
  return basis;
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
// when the true minimum of those Jacobians grows. A boundary node released from the surface (`max_off` > 0)
// moves freely but no farther than max_off from the surface. Returns true when the node moved.
bool untangle_node(HexMesh& mesh, const Adjacency& adj, int v, double h, bool sliding, double max_off,
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
    SurfacePoint foot;
    if (sliding) foot = surface->closest(mesh.vertices[v]);
    const Eigen::MatrixXd b = step_basis(sliding ? &foot : nullptr);
    const int dims = static_cast<int>(b.cols());
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
      if (min_corner_det(mesh, corners) > old_min + 1e-12 * s &&
          (max_off <= 0.0 || surface->distance(trial) <= max_off)) {
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

// The two measures of corner k of hex e that the worst-element pass raises, both 1 for a cube corner and
// at most 1: the scaled Jacobian s = det A / (|a| |b| |c|) and q = 3 / kappa(A) (0 where det A <= 0), with
// their gradients with respect to the position of node v (one of the corner's four nodes).
void corner_measures(const HexMesh& mesh, int e, int k, int v, double& s, Vec3& gs, double& q, Vec3& gq) {
  const auto& h = mesh.hexes[e];
  const int* nb = kHexCornerNeighbours[k];
  const Vec3& x = mesh.vertices[h[k]];
  const Vec3 a = sub(mesh.vertices[h[nb[0]]], x), b = sub(mesh.vertices[h[nb[1]]], x),
             c = sub(mesh.vertices[h[nb[2]]], x);
  const Vec3 bc = cross(b, c), ca = cross(c, a), ab = cross(a, b);
  const double aa = dot(a, a), bb = dot(b, b), cc = dot(c, c);
  const double len = std::sqrt(aa * bb * cc);
  s = len > 0.0 ? dot(a, bc) / len : 0.0;
  // ds = d(det) / len - s (sum over the changed columns u of u . du / |u|^2).
  if (!(len > 0.0))
    gs = {0, 0, 0};
  else if (h[k] == v)
    gs = add(scale(add(add(bc, ca), ab), -1.0 / len),
             scale(add(add(scale(a, 1.0 / aa), scale(b, 1.0 / bb)), scale(c, 1.0 / cc)), s));
  else if (h[nb[0]] == v)
    gs = sub(scale(bc, 1.0 / len), scale(a, s / aa));
  else if (h[nb[1]] == v)
    gs = sub(scale(ca, 1.0 / len), scale(b, s / bb));
  else
    gs = sub(scale(ab, 1.0 / len), scale(c, s / cc));
  // q = 3 f^(-1/2) with f = kappa^2, so dq = -1.5 f^(-3/2) df.
  double f;
  Vec3 ga, gb, gc;
  if (!corner_energy(a, b, c, f, ga, gb, gc)) {
    q = 0.0;
    gq = {0, 0, 0};
    return;
  }
  q = 3.0 / std::sqrt(f);
  const Vec3 df = h[k] == v       ? scale(add(add(ga, gb), gc), -1.0)
                  : h[nb[0]] == v ? ga
                  : h[nb[1]] == v ? gb
                                  : gc;
  gq = scale(df, -0.5 * q / f);
}

// The smallest scaled Jacobian and the smallest 3 / kappa over the given corners.
void corner_measures_min(const HexMesh& mesh, const std::vector<CornerRef>& corners, int v, double& s_min,
                         double& q_min) {
  s_min = q_min = kInf;
  for (const CornerRef& c : corners) {
    double s, q;
    Vec3 gs, gq;
    corner_measures(mesh, c.hex, c.corner, v, s, gs, q, gq);
    s_min = std::min(s_min, s);
    q_min = std::min(q_min, q);
  }
}

// One ascent step of node v for the worst-element pass and the mean stage: a damped Gauss-Newton step on a
// soft-minimum model with gradient `grad` and negated Hessian model `neg_hess` (both per unit of the edge
// length h), capped at 0.1 edge and halved up to 8 times until `better()` holds at the trial position. A
// sliding node steps in its tangent plane, is projected back, and never steps farther from `home` than
// `reach` or than it already is. Returns true when the step was accepted (the node is then at the new
// position, else where it was).
template <class Better>
bool ascent_step(HexMesh& mesh, int v, double h, bool sliding, const SurfaceProjector* surface,
                 const Vec3& home, double reach, const Eigen::Vector3d& grad, const Eigen::Matrix3d& neg_hess,
                 Better better) {
  SurfacePoint here;
  if (sliding) here = surface->closest(mesh.vertices[v]);
  const Eigen::MatrixXd b = step_basis(sliding ? &here : nullptr);
  const int dims = static_cast<int>(b.cols());
  const Eigen::VectorXd rg = b.transpose() * grad;
  if (!(rg.norm() > 0.0)) return false;
  Eigen::MatrixXd rh = b.transpose() * neg_hess * b;
  const double damping = 1e-3 * (rh.trace() / dims) + 1e-12 + 1e-1 * rg.norm();
  rh += damping * Eigen::MatrixXd::Identity(dims, dims);
  Eigen::VectorXd step = rh.ldlt().solve(rg);
  if (!step.allFinite() || step.dot(rg) <= 0) step = rg;
  Eigen::Vector3d dp = h * (b * step);  // back to length units
  const double max_len = 0.1 * h;
  if (dp.norm() > max_len) dp *= max_len / dp.norm();

  const Vec3 old = mesh.vertices[v];
  for (int bt = 0; bt < 8; ++bt, dp *= 0.5) {
    Vec3 trial = {old[0] + dp[0], old[1] + dp[1], old[2] + dp[2]};
    if (sliding) {
      trial = surface->closest(trial, here).point;
      if (norm(sub(trial, home)) > std::max(reach, norm(sub(old, home)))) continue;
    }
    mesh.vertices[v] = trial;
    if (better()) return true;
  }
  mesh.vertices[v] = old;
  return false;
}

// What a worst-element visit raises: the corners' scaled Jacobians (stage 2), both measures (stage 1), or
// their 3 / kappa (the condition stage).
enum class Raise { kScaledJacobian, kBoth, kCondition };

// One worst-element visit of node v: ascent on the soft minimum S(p) = -(1/mu) log sum exp(-mu m_i(p))
// of the measures m_i of the corners that depend on p (`what`), with the untangler's damped Gauss-Newton
// model of its Hessian (ascent_step). A step is accepted only when the true minimum of the m_i grows, no
// corner's 3 / kappa falls below the smaller of its old minimum and `q_floor`, and (kCondition) the
// smallest of both measures does not fall. Returns true when the node moved.
bool raise_worst_node(HexMesh& mesh, const Adjacency& adj, int v, double h, bool sliding,
                      const SurfaceProjector* surface, const Vec3& home, double reach, Raise what,
                      double q_floor, double mu, std::vector<CornerRef>& corners) {
  corners_of_node(mesh, adj, v, corners);
  if (corners.empty()) return false;
  bool moved = false;
  for (int iter = 0; iter < 4; ++iter) {
    const std::size_t n = corners.size();
    std::vector<double> m;
    std::vector<Eigen::Vector3d> g;
    double smin = kInf, qmin = kInf;
    for (std::size_t i = 0; i < n; ++i) {
      double sj, q;
      Vec3 gs, gq;
      corner_measures(mesh, corners[i].hex, corners[i].corner, v, sj, gs, q, gq);
      if (what != Raise::kCondition) {
        m.push_back(sj);
        g.push_back(Eigen::Vector3d(gs[0], gs[1], gs[2]) * h);  // per unit of the edge length
      }
      if (what != Raise::kScaledJacobian) {
        m.push_back(q);
        g.push_back(Eigen::Vector3d(gq[0], gq[1], gq[2]) * h);
      }
      smin = std::min(smin, sj);
      qmin = std::min(qmin, q);
    }
    const double mmin = what == Raise::kScaledJacobian ? smin
                        : what == Raise::kBoth         ? std::min(smin, qmin)
                                                       : qmin;
    const double both_min = std::min(smin, qmin);
    const double q_limit = std::min(qmin, q_floor);
    double z = 0.0;
    std::vector<double> w(m.size());
    for (std::size_t i = 0; i < m.size(); ++i) z += (w[i] = std::exp(-mu * (m[i] - mmin)));
    Eigen::Vector3d grad = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < m.size(); ++i) grad += (w[i] / z) * g[i];
    Eigen::Matrix3d neg_hess = Eigen::Matrix3d::Zero();
    for (std::size_t i = 0; i < m.size(); ++i) neg_hess += (w[i] / z) * g[i] * g[i].transpose();
    neg_hess = mu * (neg_hess - grad * grad.transpose());
    const bool accepted = ascent_step(mesh, v, h, sliding, surface, home, reach, grad, neg_hess, [&] {
      double s_new, q_new;
      corner_measures_min(mesh, corners, v, s_new, q_new);
      if (q_new < q_limit) return false;
      switch (what) {
        case Raise::kScaledJacobian:
          return s_new > mmin + 1e-6;
        case Raise::kBoth:
          return std::min(s_new, q_new) > mmin + 1e-6;
        case Raise::kCondition:
          return q_new > mmin + 1e-6 && std::min(s_new, q_new) >= both_min;
      }
      return false;
    });
    if (!accepted) break;
    moved = true;
  }
  return moved;
}

// True when corner k of a hex depends on the hex's node at local index l (the corner itself or one of its
// three neighbours).
bool corner_uses(int k, int l) {
  const int* nb = kHexCornerNeighbours[k];
  return k == l || nb[0] == l || nb[1] == l || nb[2] == l;
}

// One mean visit of node v: ascent on the sum, over the hexes around v, of a soft minimum (mu = 30) of each
// hex's eight corner scaled Jacobians (a smooth stand-in for the element values whose mean is reported),
// with the same step as the worst-element visits (ascent_step). A step is accepted only when the sum of the
// true element values of those hexes grows, none of them falls below the smaller of its old value and
// `sj_floor`, and no corner that depends on v gets a 3 / kappa below the smaller of its old smallest and
// `q_floor`. Returns true when the node moved.
bool raise_mean_node(HexMesh& mesh, const Adjacency& adj, int v, double h, bool sliding,
                     const SurfaceProjector* surface, const Vec3& home, double reach, double sj_floor,
                     double q_floor) {
  const int first = adj.hex_start[v], last = adj.hex_start[v + 1];
  if (first == last) return false;
  const double mu = 30.0;
  // The element scaled Jacobians of the hexes around v (in adjacency order) and their sum, and the smallest
  // 3 / kappa of the corners that depend on v; with `grad`, also the soft-minimum model's gradient and
  // negated Hessian (added to).
  auto evaluate = [&](double& sum, std::vector<double>& element, double& q_min, Eigen::Vector3d* grad,
                      Eigen::Matrix3d* neg_hess) {
    sum = 0.0;
    q_min = kInf;
    element.clear();
    for (int i = first; i < last; ++i) {
      const int e = adj.hex_list[i];
      const auto& hx = mesh.hexes[e];
      int l = 0;
      while (hx[l] != v) ++l;
      Vec3 p[8];
      for (int j = 0; j < 8; ++j) p[j] = mesh.vertices[hx[j]];
      double s[8];
      Eigen::Vector3d g[8];
      double m = kInf;
      for (int k = 0; k < 8; ++k) {
        const bool uses = corner_uses(k, l);
        g[k] = Eigen::Vector3d::Zero();
        if (uses && grad) {
          double q;
          Vec3 gs, gq;
          corner_measures(mesh, e, k, v, s[k], gs, q, gq);
          g[k] = Eigen::Vector3d(gs[0], gs[1], gs[2]) * h;  // per unit of the edge length
          q_min = std::min(q_min, q);
        } else {
          // The values alone (as corner_measures computes them).
          Vec3 a, b, c;
          hex_corner_columns(p, k, a, b, c);
          const double len = std::sqrt(dot(a, a) * dot(b, b) * dot(c, c));
          s[k] = len > 0.0 ? corner_jacobian(a, b, c) / len : 0.0;
          if (uses) q_min = std::min(q_min, 3.0 / std::sqrt(corner_condition_squared(a, b, c)));
        }
        m = std::min(m, s[k]);
      }
      sum += m;
      element.push_back(m);
      if (!grad) continue;
      double z = 0.0, w[8];
      for (int k = 0; k < 8; ++k) z += (w[k] = std::exp(-mu * (s[k] - m)));
      Eigen::Vector3d ge = Eigen::Vector3d::Zero();
      Eigen::Matrix3d gg = Eigen::Matrix3d::Zero();
      for (int k = 0; k < 8; ++k) {
        ge += (w[k] / z) * g[k];
        gg += (w[k] / z) * g[k] * g[k].transpose();
      }
      *grad += ge;
      *neg_hess += mu * (gg - ge * ge.transpose());
    }
  };
  std::vector<double> before, after;
  bool moved = false;
  for (int iter = 0; iter < 4; ++iter) {
    double sum0, q_min0;
    Eigen::Vector3d grad = Eigen::Vector3d::Zero();
    Eigen::Matrix3d neg_hess = Eigen::Matrix3d::Zero();
    evaluate(sum0, before, q_min0, &grad, &neg_hess);
    const double q_limit = std::min(q_min0, q_floor);
    const bool accepted = ascent_step(mesh, v, h, sliding, surface, home, reach, grad, neg_hess, [&] {
      double sum, q_min;
      evaluate(sum, after, q_min, nullptr, nullptr);
      if (!(sum > sum0 + 1e-9 && q_min >= q_limit)) return false;
      for (std::size_t i = 0; i < after.size(); ++i)
        if (after[i] < std::min(before[i], sj_floor)) return false;
      return true;
    });
    if (!accepted) break;
    moved = true;
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
  bool release = false;
  while (inverted > 0 && sweeps < max_sweeps) {
    // The nodes to visit: those of the inverted hexes, widened by one ring of hexes after sweeps that did
    // not reduce the count (the tangle then needs room from its neighbours).
    std::vector<char> visit(mesh.vertices.size(), 0);
    for (std::size_t e = 0; e < mesh.hexes.size(); ++e)
      if (inv[e])
        for (int v : mesh.hexes[e]) visit[v] = 1;
    const std::vector<char> own = visit;
    for (int r = 0; r < ring; ++r) {
      std::vector<char> wider = visit;
      for (std::size_t v = 0; v < visit.size(); ++v)
        if (visit[v])
          for (int i = adj.hex_start[v]; i < adj.hex_start[v + 1]; ++i)
            for (int w : mesh.hexes[adj.hex_list[i]]) wider[w] = 1;
      visit.swap(wider);
    }
    for (std::size_t v = 0; v < visit.size(); ++v) {
      if (!visit[v] || !movable[v]) continue;
      const bool slides = !sliding.empty() && sliding[v] != 0;
      const bool released = slides && release && own[v];
      untangle_node(mesh, adj, static_cast<int>(v), h[v], slides && !released, released ? 0.25 * h[v] : 0.0,
                    surface, corners);
    }
    ++sweeps;
    inv = inverted_mask(mesh, &inverted);
    if (inverted < best) {
      best = inverted;
      stalled = 0;
    } else if (++stalled >= 2) {
      // Widen the region; when the widest region is stuck too, the surface itself is in the way (two
      // boundary nodes from opposite sides of a thin part on nearly the same surface point): then the
      // sliding nodes of the inverted hexes may leave the surface by up to a quarter edge, which costs a
      // little fidelity instead of an inverted hex.
      if (ring == 3) release = true;
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
  if (rounds_out) *rounds_out = 1;

  // Inverted hexes stay out of the objective and their nodes stay put, so that the energy is finite.
  int inverted = 0;
  const std::vector<char> inv = inverted_mask(mesh, &inverted);
  std::vector<char> movable = movable_in;
  for (std::size_t e = 0; e < mesh.hexes.size(); ++e)
    if (inv[e])
      for (int v : mesh.hexes[e]) movable[v] = 0;
  std::vector<char> sliding(nv, 0);
  for (std::size_t v = 0; v < nv; ++v)
    sliding[v] = movable[v] && surface != nullptr && !sliding_in.empty() && sliding_in[v];

  // The corners whose condition number depends on each movable node (corners of inverted hexes left out).
  std::vector<std::vector<CornerRef>> corners(nv);
  std::vector<CornerRef> all;
  for (std::size_t v = 0; v < nv; ++v) {
    if (!movable[v]) continue;
    corners_of_node(mesh, adj, static_cast<int>(v), all);
    for (const CornerRef& c : all)
      if (!inv[c.hex]) corners[v].push_back(c);
  }
  std::vector<char> valid(mesh.hexes.size());
  for (std::size_t e = 0; e < valid.size(); ++e) valid[e] = !inv[e];
  double energy = active_energy(mesh, valid, nullptr);

  // Sliding nodes are tethered to where they entered: a term ((|x - anchor| / r)^2)^2 with r a fraction of
  // the local edge length. Without it, nodes at a thin tip (the coronoid process) slide away from the tip,
  // because a blunter boundary has better shaped hexes, and the mesh silently loses the tip.
  const std::vector<Vec3> anchor = mesh.vertices;
  // The closest surface point of each sliding node (its tangent plane), kept up to date as it moves.
  std::vector<SurfacePoint> foot(nv);
  for (std::size_t v = 0; v < nv; ++v)
    if (sliding[v]) foot[v] = surface->closest(mesh.vertices[v]);
  // The local objective of node v at position p: the squared condition numbers of its corners plus the
  // tether, with the gradient with respect to p; +infinity when a corner is not positively oriented.
  auto local = [&](int v, const Vec3& p, Vec3* grad) {
    mesh.vertices[v] = p;
    double f = 0.0;
    Vec3 g{0, 0, 0};
    for (const CornerRef& c : corners[v]) {
      const auto& hx = mesh.hexes[c.hex];
      const int* nb = kHexCornerNeighbours[c.corner];
      const Vec3& x = mesh.vertices[hx[c.corner]];
      const Vec3 a = sub(mesh.vertices[hx[nb[0]]], x), b = sub(mesh.vertices[hx[nb[1]]], x),
                 cc = sub(mesh.vertices[hx[nb[2]]], x);
      double fc;
      Vec3 ga, gb, gc;
      if (!corner_energy(a, b, cc, fc, ga, gb, gc)) return kInf;
      f += fc;
      if (hx[c.corner] == v)
        g = sub(g, add(add(ga, gb), gc));
      else if (hx[nb[0]] == v)
        g = add(g, ga);
      else if (hx[nb[1]] == v)
        g = add(g, gb);
      else
        g = add(g, gc);
    }
    if (sliding[v] && options.boundary_tether > 0.0) {
      const double r = options.boundary_tether * h[v];
      const Vec3 d = sub(p, anchor[v]);
      const double q = dot(d, d) / (r * r);
      f += q * q;
      g = add(g, scale(d, 4.0 * q / (r * r)));
    }
    if (grad) *grad = g;
    return f;
  };

  // One Newton step on node v: the Hessian of the local objective by finite differences of its analytic
  // gradient (in the tangent plane for sliding nodes), eigenvalues floored so that the step descends,
  // the step capped at half an edge, then backtracking until the objective decreases. Sliding nodes are
  // projected back onto the surface at every trial, so the objective is measured where the node ends.
  // Returns the node's movement relative to its edge length; `decrease` receives the objective's decrease.
  auto relax = [&](int v, double& decrease) {
    const Vec3 p0 = mesh.vertices[v];
    Vec3 g0;
    const double f0 = local(v, p0, &g0);
    if (!(f0 < kInf)) {
      mesh.vertices[v] = p0;
      return 0.0;
    }
    const SurfacePoint& here = foot[v];
    const Eigen::Matrix<double, 3, Eigen::Dynamic> basis = step_basis(sliding[v] ? &here : nullptr);
    const int dims = static_cast<int>(basis.cols());
    const Eigen::Vector3d g3(g0[0], g0[1], g0[2]);
    const Eigen::VectorXd gr = basis.transpose() * g3;
    if (!(gr.norm() > 0.0)) return 0.0;
    const double eps = 1e-5 * h[v];
    Eigen::MatrixXd hess(dims, dims);
    bool finite = true;
    for (int k = 0; k < dims; ++k) {
      const Eigen::Vector3d dp = eps * basis.col(k);
      Vec3 gk;
      finite = finite && local(v, {p0[0] + dp[0], p0[1] + dp[1], p0[2] + dp[2]}, &gk) < kInf;
      hess.col(k) = basis.transpose() * (Eigen::Vector3d(gk[0], gk[1], gk[2]) - g3) / eps;
    }
    Eigen::VectorXd step;
    if (finite) {
      const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (hess + hess.transpose()));
      const double top = es.eigenvalues().cwiseAbs().maxCoeff();
      Eigen::VectorXd inv_l(dims);
      for (int k = 0; k < dims; ++k) inv_l[k] = 1.0 / std::max(es.eigenvalues()[k], 1e-3 * top + 1e-300);
      step = -(es.eigenvectors() * inv_l.asDiagonal() * es.eigenvectors().transpose()) * gr;
    } else {
      step = -gr * (0.1 * h[v] / gr.norm());
    }
    double t = std::min(1.0, 0.5 * h[v] / std::max(step.norm(), 1e-300));
    for (int bt = 0; bt < 12; ++bt, t *= 0.5) {
      const Eigen::Vector3d dp = t * (basis * step);
      Vec3 trial{p0[0] + dp[0], p0[1] + dp[1], p0[2] + dp[2]};
      SurfacePoint projected;
      if (sliding[v]) {
        projected = surface->closest(trial, here);
        trial = projected.point;
      }
      const double f = local(v, trial, nullptr);
      if (f < f0) {
        if (sliding[v]) foot[v] = projected;
        decrease = f0 - f;
        return norm(sub(trial, p0)) / h[v];
      }
    }
    mesh.vertices[v] = p0;
    return 0.0;
  };

  Progress progress("condition number optimization");
  int sweeps = 0;
  std::vector<char> active(nv, 1);
  while (sweeps < options.max_iterations) {
    double max_move = 0.0, decrease = 0.0;
    for (std::size_t v = 0; v < nv; ++v) {
      if (!movable[v] || corners[v].empty() || !active[v]) continue;
      double d = 0.0;
      const double move = relax(static_cast<int>(v), d);
      max_move = std::max(max_move, move);
      decrease += d;
      // A node that hardly moved rests until a node of its hexes moves (its local objective then changed).
      if (options.reactivate > 0.0) {
        active[v] = 0;
        if (move > options.reactivate)
          for (int i = adj.hex_start[v]; i < adj.hex_start[v + 1]; ++i)
            for (int w : mesh.hexes[adj.hex_list[i]]) active[w] = 1;
      }
    }
    ++sweeps;
    progress.update(double(sweeps) / options.max_iterations,
                    "sweep " + std::to_string(sweeps) + ", move " + std::to_string(max_move));
    // The sum of the local decreases is the decrease of the total energy over the sweep (each step changes
    // only the node's own terms), so the energy is tracked without re-evaluating it.
    energy -= decrease;
    if (max_move < options.tolerance || decrease < 1e-5 * energy) break;
  }
  progress.finish(std::to_string(sweeps) + " sweeps");
  return sweeps;
}

int improve_worst_elements(HexMesh& mesh, const std::vector<char>& movable, const std::vector<char>& sliding,
                           const SurfaceProjector* surface, const OptimizeOptions& options,
                           const std::vector<Vec3>* home_in) {
  if (!(options.worst_element_threshold > 0.0)) return 0;
  int inverted = 0;
  inverted_mask(mesh, &inverted);
  if (inverted > 0) return 0;
  const Adjacency adj(mesh);
  const std::vector<double> h = local_edge_length(mesh, adj);
  const std::vector<Vec3> home = home_in ? *home_in : mesh.vertices;
  // Per hex the measure of the stage (the smaller of the scaled Jacobian and 3 / kappa, or the scaled
  // Jacobian alone) and 3 / kappa, and the mesh's smallest 3 / kappa.
  std::vector<double> worst(mesh.hexes.size()), q_hex(mesh.hexes.size());
  double q_floor = kInf;
  auto measure = [&](bool with_kappa) {
    q_floor = kInf;
    for (std::size_t e = 0; e < mesh.hexes.size(); ++e) {
      Vec3 p[8];
      for (int i = 0; i < 8; ++i) p[i] = mesh.vertices[mesh.hexes[e][i]];
      const HexQuality q = hex_quality(p);
      q_hex[e] = 3.0 / q.condition;
      worst[e] = with_kappa ? std::min(q.scaled_jacobian, q_hex[e]) : q.scaled_jacobian;
      q_floor = std::min(q_floor, q_hex[e]);
    }
  };
  std::vector<CornerRef> corners;
  Progress progress("worst elements");
  int sweeps = 0;
  // Sweeps visiting the nodes of the hexes whose `key` is below `limit`, lowest first (ties by index), each
  // node once per sweep, until a sweep moves no node; returns after max_sweeps.
  auto visit_below = [&](const std::vector<double>& key, double limit, int max_sweeps, Raise what,
                         double reach, double mu, const char* label) {
    const bool with_kappa = what != Raise::kScaledJacobian;
    for (int sweep = 0; sweep < max_sweeps; ++sweep) {
      std::vector<int> bad;
      for (std::size_t e = 0; e < mesh.hexes.size(); ++e)
        if (key[e] < limit) bad.push_back(static_cast<int>(e));
      if (bad.empty()) break;
      std::stable_sort(bad.begin(), bad.end(), [&](int a, int b) { return key[a] < key[b]; });
      std::vector<char> seen(mesh.vertices.size(), 0);
      bool moved = false;
      for (int e : bad)
        for (int v : mesh.hexes[e]) {
          if (seen[v] || !movable[v]) continue;
          seen[v] = 1;
          const bool slides = surface != nullptr && !sliding.empty() && sliding[v] != 0;
          moved = raise_worst_node(mesh, adj, v, h[v], slides, surface, home[v], reach * h[v], what,
                                   with_kappa ? 0.0 : q_floor, mu, corners) ||
                  moved;
        }
      ++sweeps;
      measure(with_kappa);
      progress.update(double(sweep + 1) / max_sweeps,
                      std::string(label) + ", sweep " + std::to_string(sweep + 1));
      if (!moved) break;
    }
  };
  // The first stage raises both measures of the hexes below the threshold; the second the scaled Jacobian
  // of every hex, with no corner's 3 / kappa falling below the mesh's smallest.
  // The stages repeat worst_element_rounds times: the second stage moves nodes that then give the first
  // one room again.
  for (int run = 0; run < 2 * std::max(options.worst_element_rounds, 1); ++run) {
    const int stage = run % 2;
    const bool with_kappa = stage == 0;
    const double threshold = with_kappa ? options.worst_element_threshold : 1.0;
    const int max_sweeps = with_kappa ? options.worst_element_sweeps : options.scaled_jacobian_sweeps;
    measure(with_kappa);
    visit_below(worst, threshold, max_sweeps, with_kappa ? Raise::kBoth : Raise::kScaledJacobian,
                options.worst_element_reach, 30.0, with_kappa ? "stage 1" : "stage 2");
    // The condition stage: stage 1's soft minimum (mu = 30) weighs every corner within about 0.03 of the
    // smallest measure, and where a few hexes of nearly equal kappa share their nodes (pillow hexes on a
    // thin plate) its ascent stalls above the target; a sharp minimum (mu = 400) of 3 / kappa alone follows
    // the worst corner, and min(scaled Jacobian, 3 / kappa) around a node still never falls.
    if (with_kappa && options.condition_target > 0.0)
      visit_below(q_hex, 3.0 / options.condition_target, options.worst_element_sweeps, Raise::kCondition,
                  options.condition_reach, 400.0, "condition stage");
  }
  progress.finish(std::to_string(sweeps) + " sweeps");
  return sweeps;
}

int improve_mean_jacobian(HexMesh& mesh, const std::vector<char>& movable, const std::vector<char>& sliding,
                          const SurfaceProjector* surface, const OptimizeOptions& options,
                          const std::vector<Vec3>* home_in) {
  if (options.mean_jacobian_sweeps <= 0 || mesh.hexes.empty()) return 0;
  int inverted = 0;
  inverted_mask(mesh, &inverted);
  if (inverted > 0) return 0;
  const Adjacency adj(mesh);
  const std::vector<double> h = local_edge_length(mesh, adj);
  const std::vector<Vec3> home = home_in ? *home_in : mesh.vertices;
  // No hex may fall below the larger of the mesh's smallest scaled Jacobian and the floor
  // (mean_jacobian_floor, or the worst-element threshold where that is negative; nor below its own value
  // where that is lower), no corner's 3 / kappa below the mesh's smallest: the mesh's worst values never get
  // worse.
  const HexQualityField field = compute_hex_quality(mesh);
  const double sj_floor = std::max(
      options.mean_jacobian_floor < 0.0 ? options.worst_element_threshold : options.mean_jacobian_floor,
      *std::min_element(field.scaled_jacobian.begin(), field.scaled_jacobian.end()));
  const double q_floor = 3.0 / *std::max_element(field.condition.begin(), field.condition.end());
  Progress progress("mean scaled Jacobian");
  int sweeps = 0;
  // Every movable node in the first sweep; then only the nodes of hexes in which a node moved.
  std::vector<char> active(mesh.vertices.size(), 1);
  for (int sweep = 0; sweep < options.mean_jacobian_sweeps; ++sweep) {
    std::vector<char> next(mesh.vertices.size(), 0);
    bool moved = false;
    for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
      if (!movable[v] || !active[v]) continue;
      const bool slides = surface != nullptr && !sliding.empty() && sliding[v] != 0;
      if (!raise_mean_node(mesh, adj, static_cast<int>(v), h[v], slides, surface, home[v],
                           options.worst_element_reach * h[v], sj_floor, q_floor))
        continue;
      moved = true;
      for (int i = adj.hex_start[v]; i < adj.hex_start[v + 1]; ++i)
        for (int w : mesh.hexes[adj.hex_list[i]]) next[w] = 1;
    }
    ++sweeps;
    progress.update(double(sweep + 1) / options.mean_jacobian_sweeps, "sweep " + std::to_string(sweep + 1));
    if (!moved) break;
    active.swap(next);
  }
  progress.finish(std::to_string(sweeps) + " sweeps");
  return sweeps;
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
  const std::vector<Vec3> entry = mesh.vertices;
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
  report.worst_element_sweeps = improve_worst_elements(mesh, movable, sliding, surface, options, &entry);
  report.mean_jacobian_sweeps = improve_mean_jacobian(mesh, movable, sliding, surface, options, &entry);
  report.phases.push_back({"final", summarize_quality(mesh), seconds_since(t0)});
  report.inverted = report.phases.back().quality.inverted;
  valid = inverted_mask(mesh, nullptr);
  for (char& c : valid) c = !c;
  report.energy_after = active_energy(mesh, valid, nullptr);
  return report;
}

}  // namespace hexbite
