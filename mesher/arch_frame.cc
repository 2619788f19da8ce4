#include "mesher/arch_frame.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "mesher/units.h"
#include "mesher/vec3.h"

namespace hexbite {

using vec3::cross;
using vec3::norm;
using vec3::sub;

namespace {

constexpr int kBins = 80;
constexpr int kDegree = 6;
constexpr int kTable = 4001;
// The map may stretch or shrink the bone across the arch by at most this factor (1 - curvature * t).
constexpr double kMinStretch = 0.2;

[[noreturn]] void not_an_arch(const std::string& why) {
  throw NotAnArchError("arch frame: " + why +
                           "; the arch frame needs a whole mandible in the mandible frame (+x left, +y "
                           "posterior, +z superior)",
                       "use the axis-aligned grid for other solids (--grid-frame axes, in a scenario "
                       "grid_frame: axes)");
}

}  // namespace

double ArchFrame::rho(double theta) const {
  const double u = (theta - centre_) / half_width_;
  double r = 0;
  for (auto c = coefficients_.rbegin(); c != coefficients_.rend(); ++c) r = r * u + *c;
  return r;
}

ArchFrame::Point2 ArchFrame::curve(double theta) const {
  const double r = rho(theta);
  return {ox_ + r * std::sin(theta), oy_ - r * std::cos(theta)};
}

ArchFrame::Point2 ArchFrame::tangent(double theta) const {
  const double u = (theta - centre_) / half_width_;
  double dr = 0;
  for (std::size_t i = coefficients_.size() - 1; i >= 1; --i) dr = dr * u + double(i) * coefficients_[i];
  dr /= half_width_;
  const double r = rho(theta);
  const double x = dr * std::sin(theta) + r * std::cos(theta),
               y = -dr * std::cos(theta) + r * std::sin(theta);
  const double l = std::hypot(x, y);
  return {x / l, y / l};
}

double ArchFrame::s_of_theta(double theta) const {
  const double f = (theta - theta_lo_) / (theta_hi_ - theta_lo_) * (kTable - 1);
  const int i = std::clamp(int(f), 0, kTable - 2);
  return s_[i] + (f - i) * (s_[i + 1] - s_[i]);
}

double ArchFrame::theta_of_s(double s) const {
  const int i = std::clamp(int(std::upper_bound(s_.begin(), s_.end(), s) - s_.begin()) - 1, 0, kTable - 2);
  return theta_[i] + (s - s_[i]) / (s_[i + 1] - s_[i]) * (theta_[i + 1] - theta_[i]);
}

Vec3 ArchFrame::to_body(const Vec3& q) const {
  // Beyond the tabulated ends the curve goes on straight along its end tangent.
  const double s = q[0];
  const double theta = s < 0 ? theta_lo_ : s > length() ? theta_hi_ : theta_of_s(s);
  const double along = s < 0 ? s : s > length() ? s - length() : 0.0;
  const Point2 c = curve(theta), t = tangent(theta);
  // (tangent, normal, z) right-handed: the normal z x tangent points into the arch (lingual).
  return {c.x + along * t.x - q[1] * t.y, c.y + along * t.y + q[1] * t.x, q[2]};
}

Vec3 ArchFrame::to_arch(const Vec3& p) const {
  // The closest point of the curve: the nearest of every 8th tabulated point, then Newton steps on
  // g(theta) = (p - c(theta)) . c'(theta) = 0 within the tabulated angles.
  int nearest = 0;
  double nearest_d2 = std::numeric_limits<double>::infinity();
  for (int i = 0; i < kTable; i += 8) {
    const double d2 = std::pow(p[0] - x_[i], 2) + std::pow(p[1] - y_[i], 2);
    if (d2 < nearest_d2) nearest_d2 = d2, nearest = i;
  }
  auto g = [&](double th) {
    const Point2 c = curve(th), t = tangent(th);
    return (p[0] - c.x) * t.x + (p[1] - c.y) * t.y;
  };
  double theta = theta_[nearest];
  for (int it = 0; it < 60; ++it) {
    const double d = 1e-6;
    const double slope = (g(theta + d) - g(theta - d)) / (2 * d);
    if (!(slope < 0)) break;  // not a distance minimum along the curve
    const double next = std::clamp(theta - std::clamp(g(theta) / slope, -0.05, 0.05), theta_lo_, theta_hi_);
    const bool done = std::fabs(next - theta) < 1e-13;
    theta = next;
    if (done) break;
  }
  const Point2 c = curve(theta), t = tangent(theta);
  const double dx = p[0] - c.x, dy = p[1] - c.y;
  const double along = dx * t.x + dy * t.y;  // 0 at the closest point; beyond an end along the straight end
  const bool before = theta == theta_lo_ && along < 0, after = theta == theta_hi_ && along > 0;
  if (!before && !after && std::fabs(along) > 1e-9 * (1 + std::hypot(dx, dy)))
    not_an_arch("no closest point on the arch for " + format_point_mm(p));
  const double s = before ? along : after ? length() + along : s_of_theta(theta);
  return {s, -dx * t.y + dy * t.x, p[2]};
}

ArchFrame::ArchFrame(const TriSurface& surface) {
  // A sharply bent arch (a narrow or deep arch, a gonial angle near 105 degrees, a jaw turned 20 degrees
  // about z) squeezes the tops of the rami across a curve fitted about a centre close behind the bone;
  // a centre further back bends the curve's ends less. The first centre whose map passes the checks
  // wins; if none does, the first one's reason is reported. Far behind, a ring's curve passes the checks
  // below through its hole, hence the further check of the fallback: the curve runs inside the bone.
  constexpr double kBack[] = {0.3, 1.0};
  std::optional<NotAnArchError> first;
  for (const double back : kBack) {
    try {
      fit(surface, back, back != kBack[0]);
      return;
    } catch (const NotAnArchError& e) {
      if (!first) first = e;
    }
  }
  throw *first;
}

void ArchFrame::fit(const TriSurface& surface, double back, bool curve_inside) {
  if (surface.triangles.empty()) not_an_arch("the surface has no triangles");
  Vec3 lo = surface.vertices.front(), hi = lo;
  for (const Vec3& p : surface.vertices)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
  ox_ = 0.5 * (lo[0] + hi[0]);
  oy_ = hi[1] + back * (hi[1] - lo[1]);
  double a0 = M_PI, a1 = -M_PI;
  for (const Vec3& p : surface.vertices) {
    const double a = std::atan2(p[0] - ox_, oy_ - p[1]);
    a0 = std::min(a0, a), a1 = std::max(a1, a);
  }
  if (!(a1 - a0 > 0.2)) not_an_arch("the surface spans no arch around the back of its bounding box");
  centre_ = 0.5 * (a0 + a1);
  half_width_ = 0.5 * (a1 - a0);

  // The area-weighted mean distance from the centre per angle bin, then the polynomial through the bins.
  std::vector<double> area(kBins, 0.0), radius(kBins, 0.0);
  for (const auto& tri : surface.triangles) {
    const Vec3 &a = surface.vertices[tri[0]], &b = surface.vertices[tri[1]], &c = surface.vertices[tri[2]];
    const double w = 0.5 * norm(cross(sub(b, a), sub(c, a)));
    const double x = (a[0] + b[0] + c[0]) / 3 - ox_, y = oy_ - (a[1] + b[1] + c[1]) / 3;
    const int bin = std::clamp(int((std::atan2(x, y) - a0) / (a1 - a0) * kBins), 0, kBins - 1);
    area[bin] += w;
    radius[bin] += w * std::hypot(x, y);
  }
  const int filled = int(std::count_if(area.begin(), area.end(), [](double w) { return w > 0; }));
  if (filled <= kDegree + 1) not_an_arch("too few directions around the back hold surface");
  Eigen::MatrixXd A(filled, kDegree + 1);
  Eigen::VectorXd b(filled);
  for (int bin = 0, row = 0; bin < kBins; ++bin) {
    if (!(area[bin] > 0)) continue;
    const double u = (a0 + (bin + 0.5) * (a1 - a0) / kBins - centre_) / half_width_;
    const double w = std::sqrt(area[bin]);
    double power = 1;
    for (int i = 0; i <= kDegree; ++i, power *= u) A(row, i) = w * power;
    b[row++] = w * radius[bin] / area[bin];
  }
  const Eigen::VectorXd fit = A.colPivHouseholderQr().solve(b);
  coefficients_.assign(fit.data(), fit.data() + fit.size());

  // The arc length table, a little beyond the bone's angles.
  theta_lo_ = a0 - 0.02 * (a1 - a0);
  theta_hi_ = a1 + 0.02 * (a1 - a0);
  theta_.resize(kTable);
  s_.resize(kTable);
  x_.resize(kTable);
  y_.resize(kTable);
  for (int i = 0; i < kTable; ++i) {
    theta_[i] = theta_lo_ + (theta_hi_ - theta_lo_) * i / (kTable - 1);
    const Point2 q = curve(theta_[i]);
    x_[i] = q.x;
    y_[i] = q.y;
    s_[i] = i > 0 ? s_[i - 1] + std::hypot(q.x - x_[i - 1], q.y - y_[i - 1]) : 0.0;
    if (rho(theta_[i]) <= 0)
      not_an_arch(
          "the fitted arch passes behind the bone (is the chin towards +y? the frame needs it towards -y)");
  }

  // When asked, the curve must run inside the bone seen from above (a ring's curve runs through its hole):
  // the triangles' shadow on a raster of 1/200 of the bone's size covers every tabulated point within the
  // bone's angles but a quarter (the curve's ends may pass beside a ramus or a condyle).
  if (curve_inside) {
    const double h = std::max(hi[0] - lo[0], hi[1] - lo[1]) / 200;
    const int nx = int((hi[0] - lo[0]) / h) + 3, ny = int((hi[1] - lo[1]) / h) + 3;
    std::vector<char> shadow(std::size_t(nx) * ny, 0);
    for (const auto& tri : surface.triangles) {
      const Vec3 &a = surface.vertices[tri[0]], &b = surface.vertices[tri[1]], &c = surface.vertices[tri[2]];
      const double area2 = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
      const int i0 = int((std::min({a[0], b[0], c[0]}) - lo[0]) / h) + 1,
                i1 = int((std::max({a[0], b[0], c[0]}) - lo[0]) / h) + 1;
      const int j0 = int((std::min({a[1], b[1], c[1]}) - lo[1]) / h) + 1,
                j1 = int((std::max({a[1], b[1], c[1]}) - lo[1]) / h) + 1;
      for (int i = i0; i <= i1; ++i)
        for (int j = j0; j <= j1; ++j) {
          if (std::fabs(area2) < 1e-300) {
            shadow[std::size_t(j) * nx + i] = 1;
            continue;
          }
          const double x = lo[0] + (i - 0.5) * h, y = lo[1] + (j - 0.5) * h;
          const double u = ((b[0] - x) * (c[1] - y) - (b[1] - y) * (c[0] - x)) / area2;
          const double v = ((c[0] - x) * (a[1] - y) - (c[1] - y) * (a[0] - x)) / area2;
          const double w = 1 - u - v, e = 0.5;  // generous: half the triangle's size beyond it counts
          if (u >= -e && v >= -e && w >= -e) shadow[std::size_t(j) * nx + i] = 1;
        }
    }
    int inside = 0, outside = 0;
    for (int k = 0; k < kTable; k += 8) {
      if (theta_[k] < a0 || theta_[k] > a1) continue;
      const int i = int((x_[k] - lo[0]) / h) + 1, j = int((y_[k] - lo[1]) / h) + 1;
      const bool in = i >= 0 && j >= 0 && i < nx && j < ny && shadow[std::size_t(j) * nx + i];
      (in ? inside : outside)++;
    }
    if (outside > 0.25 * (inside + outside))
      not_an_arch("the arch's curve runs outside the bone seen from above (through a hole?) at " +
                  std::to_string(int(100.0 * outside / (inside + outside))) + " % of its length");
  }

  // Every point of the surface must map back to itself, where the map neither folds nor squeezes the bone.
  const double tolerance = 1e-6 * std::max(1.0, largest_extent(surface));
  for (const Vec3& p : surface.vertices) {
    const Vec3 q = to_arch(p);
    if (norm(sub(to_body(q), p)) > tolerance) not_an_arch("the map does not return " + format_point_mm(p));
    const double d = 1e-4;
    const Vec3 ds = sub(to_body({q[0] + d, q[1], q[2]}), to_body({q[0] - d, q[1], q[2]}));
    const Vec3 dt = sub(to_body({q[0], q[1] + d, q[2]}), to_body({q[0], q[1] - d, q[2]}));
    const double stretch = (ds[0] * dt[1] - ds[1] * dt[0]) / (4 * d * d);
    if (!(stretch > kMinStretch && stretch < 1 / kMinStretch))
      not_an_arch("the bone at " + format_point_mm(p) + " lies too far across the arch's curve (stretch " +
                  std::to_string(stretch) + ")");
  }
}

}  // namespace hexbite
