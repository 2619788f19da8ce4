// The built-in mandible is a signed-distance-like function (negative inside) assembled from a few
// anatomical parts joined by smooth unions:
//   body     a vertical, rounded trapezoid section swept along a U-shaped arch in plan view
//            (symphysis in front, gonial angles behind), with a buccal widening toward the ramus
//            (the external oblique line) and a mental protuberance (chin);
//   teeth    (dentate only) one ellipsoid crown per tooth, fused to the alveolar crest;
//   ramus    a plate with rounded borders whose outline is a polygon in the (y, z) plane: lower
//            border, rounded gonial angle, posterior border, condylar neck, sigmoid notch, coronoid
//            process and anterior border;
//   condyle  an ellipsoid head, long axis mediolateral and turned so that the medial pole is posterior.
// Only x >= 0 is modelled; the other side is its mirror image. The function is sampled on a CT-like
// grid whose columns are mirror-symmetric about x = 0, and VTK's marching cubes (surface_from_volume)
// extracts the surface, exactly as a scanned jaw would be processed.
#include "mesher/mandible_generator.h"

#include <vtkCellArray.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkStaticCellLocator.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>

#include "common/error.h"
#include "common/number_format.h"
#include "mesher/ct_surface.h"

namespace hexbite {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kBoneHU = 1200.0;
constexpr double kSoftTissueHU = 40.0;
constexpr double kFar = 1e9;

double deg(double d) {
  return d * kPi / 180.0;
}
double clamp01(double t) {
  return std::min(1.0, std::max(0.0, t));
}
double smoothstep(double a, double b, double t) {
  const double x = clamp01((t - a) / (b - a));
  return x * x * (3 - 2 * x);
}

// Polynomial smooth minimum: a union whose seam is rounded over a width of about k.
double smin(double a, double b, double k) {
  const double h = std::max(k - std::abs(a - b), 0.0) / k;
  return std::min(a, b) - h * h * k * 0.25;
}

struct P2 {
  double y = 0, z = 0;
};
P2 operator+(P2 a, P2 b) {
  return {a.y + b.y, a.z + b.z};
}
P2 operator-(P2 a, P2 b) {
  return {a.y - b.y, a.z - b.z};
}
P2 operator*(double s, P2 a) {
  return {s * a.y, s * a.z};
}
double dot(P2 a, P2 b) {
  return a.y * b.y + a.z * b.z;
}
P2 unit(P2 a) {
  const double n = std::sqrt(dot(a, a));
  return {a.y / n, a.z / n};
}

// Exact signed distance to a simple polygon (winding-number sign), after Inigo Quilez.
double polygon_distance(const std::vector<P2>& v, P2 p) {
  double d = dot(p - v[0], p - v[0]);
  double s = 1.0;
  for (std::size_t i = 0, j = v.size() - 1; i < v.size(); j = i, ++i) {
    const P2 e = v[j] - v[i];
    const P2 w = p - v[i];
    const P2 b = w - clamp01(dot(w, e) / dot(e, e)) * e;
    d = std::min(d, dot(b, b));
    const bool c1 = p.z >= v[i].z, c2 = p.z<v[j].z, c3 = e.y * w.z> e.z * w.y;
    if ((c1 && c2 && c3) || (!c1 && !c2 && !c3)) s = -s;
  }
  return s * std::sqrt(d);
}

// Exact signed distance to a symmetric trapezoid centred at the origin: half-width r1 at the
// bottom, r2 at the top, half-height he (Inigo Quilez). p = (lateral, vertical).
double trapezoid_distance(double px, double py, double r1, double r2, double he) {
  px = std::abs(px);
  const double cax = px - std::min(px, py < 0 ? r1 : r2), cay = std::abs(py) - he;
  const double k1x = r2, k1y = he, k2x = r2 - r1, k2y = 2 * he;
  const double t = clamp01(((k1x - px) * k2x + (k1y - py) * k2y) / (k2x * k2x + k2y * k2y));
  const double cbx = px - k1x + k2x * t, cby = py - k1y + k2y * t;
  const double s = (cbx < 0 && cay < 0) ? -1.0 : 1.0;
  return s * std::sqrt(std::min(cax * cax + cay * cay, cbx * cbx + cby * cby));
}

// Distance bound for an ellipsoid with semi-axes r, in its own frame (Inigo Quilez).
double ellipsoid_distance(double a, double b, double c, const Vec3& r) {
  const double k0 = std::sqrt(a * a / (r[0] * r[0]) + b * b / (r[1] * r[1]) + c * c / (r[2] * r[2]));
  const double k1 =
      std::sqrt(a * a / std::pow(r[0], 4) + b * b / std::pow(r[1], 4) + c * c / std::pow(r[2], 4));
  if (k1 == 0) return -std::min({r[0], r[1], r[2]});
  return k0 * (k0 - 1.0) / k1;
}

// An ellipsoid turned about the z axis: axis 0 along (cos a, sin a, 0) in plan.
struct Ellipsoid {
  Vec3 centre{};
  Vec3 semi{};
  double cos_a = 1, sin_a = 0;
  double reach() const { return std::max({semi[0], semi[1], semi[2]}); }
  double distance(double x, double y, double z) const {
    const double dx = x - centre[0], dy = y - centre[1], dz = z - centre[2];
    return ellipsoid_distance(dx * cos_a + dy * sin_a, -dx * sin_a + dy * cos_a, dz, semi);
  }
};

// Linear interpolation in a table of (s, value) pairs with increasing s.
double profile(const std::vector<std::pair<double, double>>& table, double s) {
  if (s <= table.front().first) return table.front().second;
  for (std::size_t i = 1; i < table.size(); ++i)
    if (s <= table[i].first) {
      const double t = (s - table[i - 1].first) / (table[i].first - table[i - 1].first);
      return table[i - 1].second + t * (table[i].second - table[i - 1].second);
    }
  return table.back().second;
}

struct Tooth {
  const char* name;
  double mesiodistal, buccolingual, crown_height;
};

// Average permanent mandibular crowns (mm), central incisor to second molar (Wheeler's dental
// anatomy); third molars are left out, as in most adults' occlusion.
constexpr Tooth kTeeth[] = {{"central_incisor", 5.0, 6.0, 9.0}, {"lateral_incisor", 5.5, 6.4, 9.5},
                            {"canine", 7.0, 7.5, 11.0},         {"first_premolar", 7.0, 7.5, 8.5},
                            {"second_premolar", 7.0, 8.0, 8.0}, {"first_molar", 11.0, 10.5, 7.5},
                            {"second_molar", 10.5, 10.0, 7.0}};
constexpr int kFirstMolar = 5, kSecondPremolar = 4;

// The geometry of one side (x >= 0) with every derived point, built once from the parameters.
class MandibleModel {
 public:
  explicit MandibleModel(const MandibleParameters& p);

  // Nearest point of the arch centreline to (x, y) in plan view: parameter s in [0, 1], signed
  // lateral offset u (positive buccal) and how far the point lies beyond the posterior end.
  struct ArchCoordinates {
    double s = 0, u = 0, beyond = 0;
    double x = 0, y = 0;  // the nearest centreline point
  };
  ArchCoordinates arch_coordinates(double x, double y) const;

  // The body's section at arch parameter s, shared by every voxel of a grid column.
  struct Section {
    double lower = 0, crest = 0;  // z of the lower border and of the alveolar crest
    double half_base = 0, half_top = 0;
    double centre = 0;  // lateral offset of the section's centre (buccal widening)
    double radius = 0;  // rounding of the section's corners
  };
  Section section(double s) const;
  static double section_distance(const Section& sec, double u, double beyond, double z);

  double ramus_plane_x(double z) const { return xg_ + (z - gonion_.z) * std::tan(deg(5.0)); }
  double ramus_outline_distance(double y, double z) const { return polygon_distance(ramus_outline_, {y, z}); }
  double ramus_distance(double x, double outline_distance, double z) const;

  Vec3 arch_point(double s) const { return {xg_ * s, y_of(s), 0}; }
  double y_of(double s) const { return y0_ + depth_ * s * s * (1 + kArchBend - kArchBend * s); }
  double lower_border_z(double y) const { return z0_ + (y - y0_) * std::tan(deg(kPlaneSlopeDeg)); }
  double s_at_arc_length(double length) const;

  // Derived anatomy used for sampling bounds and landmarks.
  double xg_ = 0, y0_ = 0, z0_ = 0, depth_ = 0;
  double ramus_half_thickness_ = 3.25;
  P2 gonion_, condylion_, condyle_centre_, coronoid_tip_, anterior_border_mid_;
  P2 angle_bisector_, posterior_dir_, anterior_normal_;
  Ellipsoid condyle_head_, chin_;
  std::vector<Ellipsoid> teeth_;  // left side, central incisor first
  std::vector<double> tooth_s_;   // arch parameter of each crown's centre

  static constexpr double kArchBend = 0.1;      // > 0 makes the anterior arch narrower (more V than U)
  static constexpr double kPlaneSlopeDeg = 18;  // lower border rising posteriorly (mandibular plane)
  static constexpr double kOutlineRounding = 2.5;

 private:
  MandibleParameters p_;
  std::vector<P2> ramus_outline_;
  std::vector<Vec3> arch_;  // dense centreline samples (x, y, s)
  std::vector<double> arch_length_;
};

MandibleModel::MandibleModel(const MandibleParameters& p) : p_(p) {
  const double W = p.arch_width_mm, D = p.arch_depth_mm, T = p.body_thickness_mm;
  xg_ = W / 2 - ramus_half_thickness_;
  depth_ = D;
  // The symphysis centreline sits where the real jaw in ../shared/data/jaw has it, so that both
  // files share placement: incisors near y = -48, lower border near z = 8, condyles near y = 31, z = 80.
  y0_ = -39.0;
  z0_ = 8.0;

  const int n = 1024;
  arch_.resize(n);
  arch_length_.resize(n);
  for (int k = 0; k < n; ++k) {
    const double s = static_cast<double>(k) / (n - 1);
    arch_[k] = {xg_ * s, y_of(s), s};
    arch_length_[k] = k == 0 ? 0.0
                             : arch_length_[k - 1] +
                                   std::hypot(arch_[k][0] - arch_[k - 1][0], arch_[k][1] - arch_[k - 1][1]);
  }

  // Ramus: gonion (intersection of the tangents to the lower and posterior borders), posterior
  // border direction from the gonial angle, condylion at the ramus height above the gonion.
  const double alpha = deg(kPlaneSlopeDeg);
  const double tau = deg(p.gonial_angle_deg) - kPi / 2 - alpha;  // backward lean of the ramus
  const P2 along_lower{std::cos(alpha), std::sin(alpha)};        // lower border, pointing back
  posterior_dir_ = {std::sin(tau), std::cos(tau)};
  anterior_normal_ = {-std::cos(tau), std::sin(tau)};
  const double yg = y0_ + D + 3.0;
  gonion_ = {yg, lower_border_z(yg)};
  condylion_ = gonion_ + p.ramus_height_mm * posterior_dir_;
  condyle_centre_ = condylion_ + P2{-2.0, -5.5};
  coronoid_tip_ = condylion_ + P2{-(p.ramus_width_mm + 5.0), -6.0};
  anterior_border_mid_ =
      gonion_ + (0.45 * p.ramus_height_mm) * posterior_dir_ + p.ramus_width_mm * anterior_normal_;
  angle_bisector_ = unit(posterior_dir_ - along_lower);

  // The outline polygon is the final outline shrunk by kOutlineRounding, which the plate's rounded
  // borders add back; so every point below sits that far inside the bone's border.
  const double r = kOutlineRounding;
  const P2 up_normal{-std::sin(alpha), std::cos(alpha)};
  // Corner of the two borders moved inward by r (intersection of the two offset lines).
  const P2 g_in = gonion_ + (r / (1.0 + dot(up_normal, anterior_normal_))) * (up_normal + anterior_normal_);
  const double angle = deg(p.gonial_angle_deg);
  const double fillet = 11.0;  // the gonial angle is strongly rounded in adults
  const double tangent_len = fillet / std::tan(angle / 2);
  const P2 t1 = g_in - tangent_len * along_lower;
  const P2 centre = g_in + (fillet / std::sin(angle / 2)) * angle_bisector_;
  std::vector<P2>& o = ramus_outline_;
  const double y_front = y0_ + D - 10.0;
  o.push_back({y_front, lower_border_z(y_front) + r});
  // Gonial fillet from the lower border to the posterior border.
  const P2 a0 = t1 - centre, a1 = (g_in + tangent_len * posterior_dir_) - centre;
  const double phi0 = std::atan2(a0.z, a0.y), phi1 = std::atan2(a1.z, a1.y);
  double dphi = phi1 - phi0;
  if (dphi > kPi) dphi -= 2 * kPi;
  if (dphi < -kPi) dphi += 2 * kPi;
  for (int k = 0; k <= 8; ++k) {
    const double phi = phi0 + dphi * k / 8.0;
    o.push_back(centre + P2{fillet * std::cos(phi), fillet * std::sin(phi)});
  }
  // Posterior border and condylar neck up into the head.
  o.push_back(g_in + (p.ramus_height_mm - 22.0) * posterior_dir_);
  o.push_back(condyle_centre_ + P2{1.5 - r, -1.0});
  o.push_back(condyle_centre_ + P2{-3.0 + r, -1.0});
  // Anterior side of the neck (pterygoid fovea), then the sigmoid notch as a quadratic curve
  // down to its lowest point and up to the coronoid process.
  const P2 fovea = condyle_centre_ + P2{-4.5 + r, -9.0};
  const P2 coronoid_back = coronoid_tip_ + P2{2.0 + r, -7.0};
  const P2 notch_control{0.5 * (fovea.y + coronoid_back.y), condylion_.z - 27.0};
  for (int k = 0; k <= 10; ++k) {
    const double t = k / 10.0;
    o.push_back((1 - t) * (1 - t) * fovea + 2 * t * (1 - t) * notch_control + t * t * coronoid_back);
  }
  // Coronoid tip, anterior border, and down into the body behind the last molar.
  o.push_back(coronoid_tip_ + P2{0.0, -r});
  o.push_back(coronoid_tip_ + P2{-1.5, -9.0});
  o.push_back(anterior_border_mid_ - r * anterior_normal_);
  const double y_low = y0_ + D - 14.0;
  double s_low = 1.0;
  for (int k = n - 1; k >= 0 && arch_[k][1] > y_low; --k) s_low = arch_[k][2];
  const Section sec = section(s_low);
  o.push_back({y_low, sec.crest - 4.0});

  // Condyle head: about 20 mm mediolaterally, 9.6 mm anteroposteriorly (Solberg; Yale), turned
  // 15 degrees so that the medial pole is posterior.
  condyle_head_.centre = {ramus_plane_x(condyle_centre_.z) + 0.5, condyle_centre_.y, condyle_centre_.z};
  condyle_head_.semi = {10.0, 4.8, 5.5};
  condyle_head_.cos_a = std::cos(deg(-15.0));
  condyle_head_.sin_a = std::sin(deg(-15.0));

  // Mental protuberance, in front of and below the symphysis centre.
  chin_.centre = {0.0, y0_ - 0.5 * 1.05 * T + 3.5, z0_ + 7.5};
  chin_.semi = {17.0, 6.0, 8.0};

  // Crowns along the arch by arc length from the midline.
  double length = 0;
  for (const Tooth& t : kTeeth) {
    const double s = s_at_arc_length(length + 0.5 * t.mesiodistal);
    length += t.mesiodistal;
    tooth_s_.push_back(s);
    const Vec3 c = arch_point(s);
    const Section ts = section(s);
    const double dx = xg_, dy = depth_ * s * (2 * (1 + kArchBend) - 3 * kArchBend * s);
    const double norm = std::hypot(dx, dy);
    Ellipsoid e;
    e.cos_a = dx / norm;
    e.sin_a = dy / norm;
    e.semi = {0.5 * t.mesiodistal + 1.6, 0.5 * t.buccolingual, 0.5 * t.crown_height + 1.5};
    e.centre = {c[0], c[1], ts.crest + 0.5 * t.crown_height - 1.5};
    teeth_.push_back(e);
  }
}

double MandibleModel::s_at_arc_length(double length) const {
  const auto it = std::lower_bound(arch_length_.begin(), arch_length_.end(), length);
  if (it == arch_length_.end()) return 1.0;
  return arch_[static_cast<std::size_t>(it - arch_length_.begin())][2];
}

MandibleModel::ArchCoordinates MandibleModel::arch_coordinates(double x, double y) const {
  ArchCoordinates best;
  double best_d2 = std::numeric_limits<double>::infinity();
  std::size_t best_k = 0;
  double best_t = 0;
  for (std::size_t k = 0; k + 1 < arch_.size(); ++k) {
    const double ex = arch_[k + 1][0] - arch_[k][0], ey = arch_[k + 1][1] - arch_[k][1];
    const double wx = x - arch_[k][0], wy = y - arch_[k][1];
    const double t = clamp01((wx * ex + wy * ey) / (ex * ex + ey * ey));
    const double dx = wx - t * ex, dy = wy - t * ey;
    const double d2 = dx * dx + dy * dy;
    if (d2 < best_d2) {
      best_d2 = d2;
      best_k = k;
      best_t = t;
    }
  }
  const auto& a = arch_[best_k];
  const auto& b = arch_[best_k + 1];
  const double ex = b[0] - a[0], ey = b[1] - a[1], len = std::hypot(ex, ey);
  const double tx = ex / len, ty = ey / len;
  best.x = a[0] + best_t * ex;
  best.y = a[1] + best_t * ey;
  best.s = a[2] + best_t * (b[2] - a[2]);
  // Buccal normal: the tangent turned clockwise (points forward at the symphysis, outward behind).
  best.u = (x - best.x) * ty - (y - best.y) * tx;
  if (best_k + 2 == arch_.size() && best_t >= 1.0)
    best.beyond = std::max(0.0, (x - best.x) * tx + (y - best.y) * ty);
  return best;
}

MandibleModel::Section MandibleModel::section(double s) const {
  const MandibleParameters& p = p_;
  // Relative bone height along the arch: the symphysis is the tallest part; behind the molars
  // the body sinks into the lower border of the ramus, which takes over above it.
  static const std::vector<std::pair<double, double>> kHeight = {{0.0, 1.06},  {0.3, 1.02}, {0.55, 1.0},
                                                                 {0.75, 0.95}, {0.88, 0.8}, {1.0, 0.4}};
  // Relative thickness: thick symphysis, slimmer at the canines and premolars, thick at the molars.
  static const std::vector<std::pair<double, double>> kThickness = {
      {0.0, 1.05}, {0.3, 0.85}, {0.6, 1.0}, {0.85, 0.9}, {1.0, 0.75}};
  Section sec;
  const double y = y_of(s);
  sec.lower = lower_border_z(y);
  sec.crest = sec.lower + p.body_height_mm * profile(kHeight, s);
  const double half = 0.5 * p.body_thickness_mm * profile(kThickness, s);
  // A dentate alveolar process is almost as wide as the bone below it; after tooth loss the ridge
  // narrows (edentulous) and finally flattens into a low, broad basal remnant (atrophic).
  const double top_ratio = p.variant == MandibleVariant::kDentate      ? 0.8
                           : p.variant == MandibleVariant::kEdentulous ? 0.55
                                                                       : 0.8;
  // Buccal widening behind the premolars, so that the body's outer surface runs into the ramus
  // plate (the external oblique line) instead of leaving a groove between the two.
  const double x = xg_ * s;
  const double dy = depth_ * s * (2 * (1 + kArchBend) - 3 * kArchBend * s);
  const double nx = dy / std::hypot(xg_, dy);
  const double needed = std::max(0.0, (xg_ + 1.0 - x) - half * nx) / std::max(nx, 0.3);
  const double widen = smoothstep(0.55, 0.9, s) * std::min(needed, 6.0);
  sec.half_base = half + 0.5 * widen;
  sec.half_top = top_ratio * half + 0.5 * widen;
  sec.centre = 0.5 * widen;
  const double half_height = 0.5 * (sec.crest - sec.lower);
  sec.radius = std::min({3.5, 0.9 * sec.half_top, 0.9 * half_height});
  return sec;
}

double MandibleModel::section_distance(const Section& sec, double u, double beyond, double z) {
  const double he = 0.5 * (sec.crest - sec.lower), r = sec.radius;
  const double d = trapezoid_distance(u - sec.centre, z - 0.5 * (sec.crest + sec.lower), sec.half_base - r,
                                      sec.half_top - r, he - r) -
                   r;
  if (beyond <= 0) return d;
  // Behind the posterior end the section is capped by a rounded end.
  return std::hypot(std::max(d, 0.0), beyond);
}

double MandibleModel::ramus_distance(double x, double outline_distance, double z) const {
  const double r = kOutlineRounding;
  const double w = std::abs(x - ramus_plane_x(z)) - (ramus_half_thickness_ - r);
  const double qx = std::max(outline_distance, 0.0), qy = std::max(w, 0.0);
  return std::hypot(qx, qy) + std::min(std::max(outline_distance, w), 0.0) - r;
}

MandibleParameters defaults_for(MandibleVariant v) {
  MandibleParameters d;
  d.variant = v;
  // Adult averages: bigonial width about 96 mm, minimum ramus breadth 30 mm, ramus height
  // (condylion-gonion) 58 mm, body height at the first molar 27 mm and thickness 12 mm; gonial
  // angle 122 degrees, a few degrees more after tooth loss. See docs/mandible.md for sources.
  d.arch_width_mm = 96;
  d.arch_depth_mm = 55;
  d.body_thickness_mm = 12;
  d.ramus_height_mm = 58;
  d.ramus_width_mm = 30;
  switch (v) {
    case MandibleVariant::kDentate:
      d.body_height_mm = 27;
      d.gonial_angle_deg = 122;
      break;
    case MandibleVariant::kEdentulous:
      d.body_height_mm = 21;
      d.body_thickness_mm = 11;
      d.gonial_angle_deg = 124;
      break;
    case MandibleVariant::kAtrophic:
      d.body_height_mm = 12;
      d.body_thickness_mm = 10;
      d.gonial_angle_deg = 125;
      break;
  }
  return d;
}

void check_range(const char* name, double value, double lo, double hi) {
  if (!std::isfinite(value) || value < lo || value > hi) {
    // The value with its own digits: "%g" would print 150.0000001 as the limit 150.
    throw InputError(std::string("--") + name + " " + format_significant(value) +
                     " is outside the accepted range " + format_significant(lo) + " to " +
                     format_significant(hi));
  }
}

// A triangle surface with a cell locator for closest-point queries, and vertical rays for the
// occlusal and top points.
class SurfaceQueries {
 public:
  explicit SurfaceQueries(const TriSurface& s) : s_(s) {
    auto points = vtkSmartPointer<vtkPoints>::New();
    points->SetDataTypeToDouble();
    points->SetNumberOfPoints(static_cast<vtkIdType>(s.vertices.size()));
    for (std::size_t i = 0; i < s.vertices.size(); ++i)
      points->SetPoint(static_cast<vtkIdType>(i), s.vertices[i].data());
    auto polys = vtkSmartPointer<vtkCellArray>::New();
    for (const auto& t : s.triangles) {
      const vtkIdType ids[3] = {t[0], t[1], t[2]};
      polys->InsertNextCell(3, ids);
    }
    poly_ = vtkSmartPointer<vtkPolyData>::New();
    poly_->SetPoints(points);
    poly_->SetPolys(polys);
    locator_ = vtkSmartPointer<vtkStaticCellLocator>::New();
    locator_->SetDataSet(poly_);
    locator_->BuildLocator();
  }

  Vec3 closest(const Vec3& p) const {
    double q[3] = {p[0], p[1], p[2]}, c[3];
    vtkIdType cell = -1;
    int sub = 0;
    double d2 = 0;
    locator_->FindClosestPoint(q, c, cell, sub, d2);
    return {c[0], c[1], c[2]};
  }

  // The highest surface point on the vertical line through (x, y).
  Vec3 top(double x, double y, const char* what) const {
    double best = -std::numeric_limits<double>::infinity();
    for (const auto& t : s_.triangles) {
      const Vec3& a = s_.vertices[t[0]];
      const Vec3& b = s_.vertices[t[1]];
      const Vec3& c = s_.vertices[t[2]];
      const double det = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
      if (std::abs(det) < 1e-12) continue;
      const double l1 = ((x - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (y - a[1])) / det;
      const double l2 = ((b[0] - a[0]) * (y - a[1]) - (x - a[0]) * (b[1] - a[1])) / det;
      if (l1 < 0 || l2 < 0 || l1 + l2 > 1) continue;
      best = std::max(best, a[2] + l1 * (b[2] - a[2]) + l2 * (c[2] - a[2]));
    }
    if (!std::isfinite(best))
      throw RunError(std::string("mandible generator: no bone above the ") + what + " position");
    return {x, y, best};
  }

 private:
  const TriSurface& s_;
  vtkSmartPointer<vtkPolyData> poly_;
  vtkSmartPointer<vtkStaticCellLocator> locator_;
};

Vec3 add(const Vec3& a, const Vec3& b) {
  return {a[0] + b[0], a[1] + b[1], a[2] + b[2]};
}
Vec3 mirror(const Vec3& a) {
  return {-a[0], a[1], a[2]};
}

Landmarks make_landmarks(const MandibleModel& m, const TriSurface& surface) {
  const SurfaceQueries q(surface);
  Landmarks lm;
  std::map<std::string, Vec3> left;

  const Vec3 condyle_top = q.top(m.condyle_head_.centre[0], m.condyle_head_.centre[1], "condyle");
  // As in the real jaw's landmark file, the TMJ point lies 4 mm below the top of the condyle.
  const Vec3 tmj = add(condyle_top, {0, 0, -4.0});
  left["condyle_tmj_point"] = tmj;
  left["coronoid_tip"] = q.top(m.ramus_plane_x(m.coronoid_tip_.z), m.coronoid_tip_.y, "coronoid");
  left["gonion"] = q.closest({m.ramus_plane_x(m.gonion_.z), m.gonion_.y, m.gonion_.z});
  const auto& m1 = m.teeth_[kFirstMolar].centre;
  const auto& pm2 = m.teeth_[kSecondPremolar].centre;
  left["first_molar_bite_point"] = q.top(m1[0], m1[1], "first molar");
  left["premolar_bite_point"] = q.top(pm2[0], pm2[1], "premolar");
  for (const auto& [name, p] : left) {
    lm.points["left_" + name] = p;
    lm.points["right_" + name] = mirror(p);
  }
  lm.points["incisal_point"] = q.top(0.0, m.y0_, "incisor");

  // Insertions: a seed point just off the bone on the side where the muscle attaches, moved to the
  // closest surface point. Origins: the offsets from the TMJ point measured in the real jaw's
  // landmarks (ArtiSynth dynjaw), so that the lines of action have realistic directions.
  auto on_plate = [&](P2 yz, double dx) { return Vec3{m.ramus_plane_x(yz.z) + dx, yz.y, yz.z}; };
  const P2 angle_area = m.gonion_ + 7.0 * m.angle_bisector_ + 2.0 * m.posterior_dir_;
  const P2 upper_lateral = m.gonion_ +
                           0.68 * (m.condylion_.z - m.gonion_.z) / m.posterior_dir_.z * m.posterior_dir_ +
                           12.0 * m.anterior_normal_;
  const Vec3 head = m.condyle_head_.centre;
  struct MuscleSpec {
    const char* name;
    double force;
    Vec3 seed;
    Vec3 origin_offset;  // from the TMJ point (skull muscles) or from the insertion (digastric)
    bool from_insertion;
  };
  const MuscleSpec muscles[] = {
      {"superficial_masseter", 190.4, on_plate(angle_area, 10.0), {5.41, -35.51, -5.85}, false},
      {"deep_masseter", 81.6, on_plate(upper_lateral, 10.0), {10.40, -21.20, 1.90}, false},
      {"medial_pterygoid", 174.8, on_plate(angle_area, -10.0), {-29.88, -20.58, -3.60}, false},
      {"anterior_temporalis",
       158.0,
       on_plate(m.anterior_border_mid_ + P2{4.0, 0.0}, -8.0),
       {6.53, -40.29, 64.36},
       false},
      {"middle_temporalis", 95.6, on_plate(m.coronoid_tip_ + P2{0.0, 6.0}, 0.0), {22.28, 1.88, 69.44}, false},
      {"posterior_temporalis",
       75.6,
       on_plate(m.coronoid_tip_ + P2{6.0, 1.0}, 0.0),
       {21.02, 18.93, 28.99},
       false},
      {"inferior_lateral_pterygoid", 66.9, add(head, {-2.0, -9.0, -5.0}), {-28.56, -20.52, 0.20}, false},
      {"superior_lateral_pterygoid", 28.7, add(head, {-2.0, -9.0, 1.0}), {-7.65, -18.66, 10.11}, false},
      {"anterior_digastric", 40.0, {7.5, m.y0_ + 2.0, m.z0_ - 8.0}, {7.00, 39.37, -3.59}, true},
  };
  for (const auto& spec : muscles) {
    MuscleLine l;
    l.name = std::string("left_") + spec.name;
    l.max_force_N = spec.force;
    l.insertion = q.closest(spec.seed);
    l.origin = add(spec.from_insertion ? l.insertion : tmj, spec.origin_offset);
    MuscleLine r = l;
    r.name = std::string("right_") + spec.name;
    r.insertion = mirror(l.insertion);
    r.origin = mirror(l.origin);
    lm.muscles.push_back(l);
    lm.muscles.push_back(r);
  }
  return lm;
}

}  // namespace

const char* variant_name(MandibleVariant variant) {
  switch (variant) {
    case MandibleVariant::kDentate:
      return "dentate";
    case MandibleVariant::kEdentulous:
      return "edentulous";
    case MandibleVariant::kAtrophic:
      return "atrophic";
  }
  return "dentate";
}

MandibleVariant parse_variant(const std::string& name) {
  for (auto v : {MandibleVariant::kDentate, MandibleVariant::kEdentulous, MandibleVariant::kAtrophic})
    if (name == variant_name(v)) return v;
  throw InputError("unknown mandible variant '" + name + "'; use dentate, edentulous or atrophic");
}

const std::vector<MandibleDimension>& mandible_dimensions() {
  // The ranges span adult anatomy with room for what-if studies, and keep the thinnest part (the
  // 6.5 mm ramus plate, the atrophic ridge) at least four voxels across.
  using P = MandibleParameters;
  static const std::vector<MandibleDimension> dimensions = {
      {"voxel", "voxel_mm", "Voxel size of the CT-like grid", "mm", &P::voxel_mm, 0.25, 1.5},
      {"arch-width", "arch_width_mm", "Bigonial width", "mm", &P::arch_width_mm, 75, 120},
      {"arch-depth", "arch_depth_mm", "Symphysis to gonion along y", "mm", &P::arch_depth_mm, 40, 75},
      {"body-height", "body_height_mm", "Body height at the first molar", "mm", &P::body_height_mm, 8, 40},
      {"body-thickness", "body_thickness_mm", "Body thickness at the first molar", "mm",
       &P::body_thickness_mm, 8, 20},
      {"ramus-height", "ramus_height_mm", "Gonion to condylion", "mm", &P::ramus_height_mm, 40, 75},
      {"ramus-width", "ramus_width_mm", "Minimum ramus breadth", "mm", &P::ramus_width_mm, 22, 40},
      {"gonial-angle", "gonial_angle_deg", "Gonial angle", "deg", &P::gonial_angle_deg, 105, 140}};
  return dimensions;
}

MandibleParameters mandible_defaults(MandibleVariant variant) {
  MandibleParameters d = defaults_for(variant);
  d.voxel_mm = 1.0;
  return d;
}

MandibleParameters complete_parameters(MandibleParameters p) {
  const MandibleParameters d = mandible_defaults(p.variant);
  for (const MandibleDimension& dim : mandible_dimensions()) {
    double& value = p.*dim.field;
    if (value == 0) value = d.*dim.field;
    check_range(dim.option, value, dim.lo, dim.hi);
  }
  return p;
}

std::string mandible_landmark_header(const MandibleParameters& parameters) {
  const MandibleParameters p = complete_parameters(parameters);
  char buf[1024];
  std::snprintf(buf, sizeof buf,
                "Landmarks and muscle lines of action of the hexbite built-in mandible (%s).\n"
                "Frame: +x = subject's left, +y = posterior, +z = superior; millimetres. Right side = "
                "left mirrored in x.\n"
                "Parameters: voxel %g mm, arch width %g, arch depth %g, body height %g, body thickness %g, "
                "ramus height %g, ramus width %g mm, gonial angle %g deg.\n"
                "'insertion' lies on the bone surface (closest point); 'origin' is on the skull and only "
                "sets the line of action.\n"
                "Bite points lie on the occlusal surface; TMJ points 4 mm below the top of the condyle.",
                variant_name(p.variant), p.voxel_mm, p.arch_width_mm, p.arch_depth_mm, p.body_height_mm,
                p.body_thickness_mm, p.ramus_height_mm, p.ramus_width_mm, p.gonial_angle_deg);
  return buf;
}

GeneratedMandible generate_mandible(const MandibleParameters& parameters) {
  GeneratedMandible out;
  out.parameters = complete_parameters(parameters);
  const MandibleParameters& p = out.parameters;
  const MandibleModel m(p);
  const double h = p.voxel_mm;

  // Sampling bounds: every part's extent plus three voxels of soft tissue.
  const double margin = 3 * h;
  const double x_max = std::max(m.condyle_head_.centre[0] + m.condyle_head_.reach(),
                                m.ramus_plane_x(m.condylion_.z) + m.ramus_half_thickness_) +
                       margin;
  const double y_min = std::min(m.chin_.centre[1] - m.chin_.semi[1], m.y0_ - p.body_thickness_mm) - margin;
  const double y_max =
      std::max(m.condyle_head_.centre[1] + m.condyle_head_.reach(), m.gonion_.y + 3.0) + margin;
  const double z_min = std::min(m.chin_.centre[2] - m.chin_.semi[2], m.z0_) - margin;
  const double z_max = std::max(m.condylion_.z, m.coronoid_tip_.z) + 2.0 + margin;
  const int half = static_cast<int>(std::ceil(x_max / h));
  const int j0 = static_cast<int>(std::floor(y_min / h)), j1 = static_cast<int>(std::ceil(y_max / h));
  const int k0 = static_cast<int>(std::floor(z_min / h)), k1 = static_cast<int>(std::ceil(z_max / h));
  VoxelVolume& ct = out.ct;
  ct.dims = {2 * half + 1, j1 - j0 + 1, k1 - k0 + 1};
  ct.spacing = h;
  ct.origin = {-half * h, j0 * h, k0 * h};
  const int nx = ct.dims[0], ny = ct.dims[1], nz = ct.dims[2];
  ct.values.assign(static_cast<std::size_t>(nx) * ny * nz, static_cast<float>(kSoftTissueHU));

  // Per grid column (x >= 0): arch coordinates and the body section.
  struct Column {
    MandibleModel::ArchCoordinates arch;
    MandibleModel::Section section;
    int teeth[3] = {-1, -1, -1};
  };
  std::vector<Column> columns(static_cast<std::size_t>(half + 1) * ny);
  const bool dentate = p.variant == MandibleVariant::kDentate;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i <= half; ++i) {
      Column& c = columns[static_cast<std::size_t>(j) * (half + 1) + i];
      const double x = i * h, y = ct.origin[1] + j * h;
      c.arch = m.arch_coordinates(x, y);
      c.section = m.section(c.arch.s);
      if (!dentate) continue;
      int n = 0;
      for (std::size_t t = 0; t < m.teeth_.size() && n < 3; ++t) {
        const auto& e = m.teeth_[t].centre;
        if (std::hypot(x - e[0], y - e[1]) < m.teeth_[t].reach() + 4.0) c.teeth[n++] = static_cast<int>(t);
      }
    }
  // The ramus outline's distance depends on (y, z) only.
  std::vector<double> outline(static_cast<std::size_t>(ny) * nz);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      outline[static_cast<std::size_t>(k) * ny + j] =
          m.ramus_outline_distance(ct.origin[1] + j * h, ct.origin[2] + k * h);

  // Parts farther away than this cannot change the union or the partial-volume ramp.
  const double reach = 8.0 + 2 * h;
  const double ramus_x_min = m.xg_ - m.ramus_half_thickness_ - reach - 10.0;
  for (int k = 0; k < nz; ++k) {
    const double z = ct.origin[2] + k * h;
    for (int j = 0; j < ny; ++j) {
      const double y = ct.origin[1] + j * h;
      const double d_outline = outline[static_cast<std::size_t>(k) * ny + j];
      float* row = ct.values.data() + (static_cast<std::size_t>(k) * ny + j) * nx;
      for (int i = 0; i <= half; ++i) {
        const double x = i * h;
        const Column& c = columns[static_cast<std::size_t>(j) * (half + 1) + i];
        double d = MandibleModel::section_distance(c.section, c.arch.u, c.arch.beyond, z);
        if (std::hypot(x - m.chin_.centre[0], y - m.chin_.centre[1], z - m.chin_.centre[2]) <
            m.chin_.reach() + reach)
          d = smin(d, m.chin_.distance(x, y, z), 8.0);
        for (int t : c.teeth) {
          if (t < 0) break;
          const Ellipsoid& e = m.teeth_[static_cast<std::size_t>(t)];
          if (std::abs(z - e.centre[2]) < e.reach() + reach) d = smin(d, e.distance(x, y, z), 2.5);
        }
        if (x > ramus_x_min && d_outline < reach) d = smin(d, m.ramus_distance(x, d_outline, z), 4.0);
        const Ellipsoid& hd = m.condyle_head_;
        if (std::hypot(x - hd.centre[0], y - hd.centre[1], z - hd.centre[2]) < hd.reach() + reach)
          d = smin(d, hd.distance(x, y, z), 3.0);
        // Partial-volume ramp one voxel wide: the value crosses the threshold exactly where d = 0.
        const double fraction = clamp01(0.5 - d / h);
        const auto value = static_cast<float>(kSoftTissueHU + (kBoneHU - kSoftTissueHU) * fraction);
        row[half + i] = value;
        row[half - i] = value;
      }
    }
  }

  out.threshold = 0.5 * (kBoneHU + kSoftTissueHU);
  CtExtraction dropped;
  out.surface = surface_from_volume(ct, out.threshold, &dropped);
  // Each option alone keeps the model a single genus-0 solid, but some corners of the ranges together
  // (a short, wide ramus at a large gonial angle) make its parts close around an opening or come
  // apart; such a bone is not a mandible and must not be simulated as one. For a closed triangle
  // surface E = 3F/2, so V - F/2 is its Euler characteristic, 2 for a sphere-like surface.
  const long long euler = static_cast<long long>(out.surface.vertices.size()) -
                          static_cast<long long>(out.surface.triangles.size()) / 2;
  if (euler != 2 || dropped.dropped_bodies > 0) {
    const std::string shape = dropped.dropped_bodies > 0
                                  ? "in " + std::to_string(dropped.dropped_bodies + 1) + " separate pieces"
                                  : "with " + std::to_string((2 - euler) / 2) + " hole(s) through it";
    char buf[700];
    std::snprintf(buf, sizeof buf,
                  "the mandible dimensions arch width %g, arch depth %g, body height %g, body thickness %g, "
                  "ramus height %g, ramus width %g mm, gonial angle %g deg give a bone %s, not a single "
                  "solid without holes; move the extreme values toward the variant's defaults",
                  p.arch_width_mm, p.arch_depth_mm, p.body_height_mm, p.body_thickness_mm, p.ramus_height_mm,
                  p.ramus_width_mm, p.gonial_angle_deg, shape.c_str());
    throw InputError(buf);
  }
  out.landmarks = make_landmarks(m, out.surface);
  return out;
}

}  // namespace hexbite
