#include "mesher/mandible_quad_template.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <tuple>

#include "mesher/hex_boundary.h"

namespace hexbite {

namespace {

constexpr double kPi = 3.14159265358979323846;

// The default dentate mandible's arch (mesher/mandible_generator.cc with its default parameters):
// x = kXg s, y = kY0 + kDepth s^2 (1.1 - 0.1 s), lower border z = kZ0 + (y - kY0) tan 18 deg.
constexpr double kXg = 44.75, kY0 = -39.0, kDepth = 55.0, kZ0 = 8.0;

Vec3 arch_point(double s) {
  return {kXg * s, kY0 + kDepth * s * s * (1.1 - 0.1 * s), 0.0};
}
// Unit buccal normal of the arch in plan view (forward at the symphysis, outward behind).
Vec3 arch_normal(double s) {
  const double tx = kXg, ty = kDepth * s * (2.2 - 0.3 * s), n = std::hypot(tx, ty);
  return {ty / n, -tx / n, 0.0};
}
double lower_border_z(double y) {
  return kZ0 + (y - kY0) * std::tan(18.0 * kPi / 180.0);
}
double ramus_plane_x(double z) {
  return kXg + (z - 26.8) * std::tan(5.0 * kPi / 180.0);
}

// Mid-surface point and buccal half-thickness vector of lattice node (a, b) on the left side.
struct Lattice {
  Vec3 mid;
  Vec3 half;
};

Lattice body_node(double s, double z, double half_thickness, double buccal_shift) {
  const Vec3 p = arch_point(s), n = arch_normal(s);
  return {{p[0] + buccal_shift * n[0], p[1] + buccal_shift * n[1], z},
          {half_thickness * n[0], half_thickness * n[1], 0.0}};
}

Lattice ramus_node(double y, double z, double half_thickness) {
  return {{ramus_plane_x(z), y, z}, {half_thickness, 0.0, 0.0}};
}

// Left-side lattice, a = 0..6, b = 0..3 (unused entries are never referenced). Body columns sit at arch
// parameters 0, 0.4, 0.65 and 0.82; the lower row at the lower border, the upper one at the top of the
// crowns (alveolar crest + 6 to 8 mm). The ramus rows: the crest level, the sigmoid notch level and the
// process tips; the condyle head is about 20 mm wide mediolaterally, the ramus plate 6.5 mm.
Lattice lattice(int a, int b) {
  static const double kS[4] = {0.0, 0.4, 0.65, 0.82};
  static const double kTop[4] = {44.0, 44.5, 49.0, 48.0};
  static const double kHalf[4] = {6.3, 5.4, 5.9, 5.5};
  // The junction of the anterior ramus border with the body (retromolar area), between the body's and
  // the ramus plate's mid-surfaces, thickness across the ramus.
  if (a == 3 && b == 1) return {{41.0, 1.0, 44.0}, {4.5, 0.0, 0.0}};
  if (a <= 3 && b <= 1) {
    const double s = kS[a];
    const double z = b == 0 ? lower_border_z(arch_point(s)[1]) + 1.0 : kTop[a];
    return body_node(s, z, kHalf[a], a == 3 ? 1.5 : 0.0);
  }
  // Ramus plane (y, z) per lattice node, a = 3..6, b = 0..3.
  static const double kY[4][4] = {
      {-1.35, -1.35, -4.5, -6.0}, {6.0, 6.0, 8.0, 2.0}, {13.0, 15.0, 19.0, 25.5}, {19.5, 23.5, 28.0, 36.0}};
  static const double kZ[4][4] = {
      {21.7, 48.0, 62.0, 74.0}, {23.0, 45.0, 63.0, 78.0}, {25.0, 45.0, 64.0, 82.0}, {27.0, 45.0, 64.0, 81.0}};
  const double half = b == 3 && a >= 5 ? 9.0 : (b == 2 && a >= 5 ? 4.0 : 3.0);
  return ramus_node(kY[a - 3][b], kZ[a - 3][b], half);
}

}  // namespace

std::map<std::string, Vec3> extreme_points(const std::vector<Vec3>& points) {
  std::map<std::string, Vec3> out;
  // "min_y" only among the points in the lowest quarter of the height: the chin, not the incisors, whose
  // inclination varies between jaws.
  double z0 = 1e300, z1 = -1e300;
  for (const Vec3& p : points) {
    z0 = std::min(z0, p[2]);
    z1 = std::max(z1, p[2]);
  }
  const double chin_z = z0 + 0.25 * (z1 - z0);
  // name, axis, sign (+1 maximum, -1 minimum), side filter (+1 x > 0, -1 x < 0, 0 all)
  const std::tuple<const char*, int, double, int> kinds[] = {
      {"max_x", 0, 1, 0},        {"min_x", 0, -1, 0},     {"min_y", 1, -1, 0},       {"left_max_y", 1, 1, 1},
      {"right_max_y", 1, 1, -1}, {"left_max_z", 2, 1, 1}, {"right_max_z", 2, 1, -1}, {"min_z", 2, -1, 0}};
  for (const auto& [name, axis, sign, side] : kinds) {
    double best = -1e300;
    for (const Vec3& p : points) {
      if (side * p[0] < 0 || (side != 0 && p[0] == 0)) continue;
      if (axis == 1 && sign < 0 && p[2] > chin_z) continue;
      if (sign * p[axis] > best) {
        best = sign * p[axis];
        out[name] = p;
      }
    }
  }
  return out;
}

MandibleQuadTemplate mandible_quad_template() {
  // Cells per side: columns 0..2 the body (row 0), column 3 body + anterior ramus + coronoid (rows 0..2),
  // column 4 body + ramus below the notch (rows 0..1), column 5 body + posterior ramus + condyle (rows 0..2).
  static const int kRows[6] = {1, 1, 1, 3, 2, 3};
  // Lattice node ids in index space: a = -6..6, b = 0..3, c = 0..1.
  auto node_id = [](int a, int b, int c) { return ((a + 6) * 4 + b) * 2 + c; };
  HexMesh index_mesh;
  index_mesh.vertices.resize(13 * 4 * 2);
  for (int a = -6; a <= 6; ++a)
    for (int b = 0; b < 4; ++b)
      for (int c = 0; c < 2; ++c) index_mesh.vertices[node_id(a, b, c)] = {double(a), double(b), double(c)};
  for (int col = -6; col < 6; ++col) {
    const int side_col = col >= 0 ? col : -col - 1;
    for (int b = 0; b < kRows[side_col]; ++b) {
      if (b == 2 && side_col == 4) continue;  // the sigmoid notch
      // VTK order, positive in the right-handed index space (a, b, c): the bottom face (height b) runs
      // along c first, so that it is counter-clockwise seen from +b.
      const int a0 = col, a1 = col + 1;
      index_mesh.hexes.push_back({node_id(a0, b, 0), node_id(a0, b, 1), node_id(a1, b, 1), node_id(a1, b, 0),
                                  node_id(a0, b + 1, 0), node_id(a0, b + 1, 1), node_id(a1, b + 1, 1),
                                  node_id(a1, b + 1, 0)});
    }
  }
  HexBoundary boundary = extract_boundary(index_mesh);

  MandibleQuadTemplate t;
  t.macro.quads = boundary.surface.quads;
  t.macro.vertices.resize(boundary.boundary_vertices.size());
  for (std::size_t i = 0; i < boundary.boundary_vertices.size(); ++i) {
    const Vec3& ix = index_mesh.vertices[boundary.boundary_vertices[i]];
    const int a = static_cast<int>(ix[0]), b = static_cast<int>(ix[1]), c = static_cast<int>(ix[2]);
    const Lattice l = lattice(std::abs(a), b);
    const double sign = c == 1 ? 1.0 : -1.0;  // c = 1 buccal
    Vec3 p{l.mid[0] + sign * l.half[0], l.mid[1] + sign * l.half[1], l.mid[2] + sign * l.half[2]};
    if (a < 0) p[0] = -p[0];
    t.macro.vertices[i] = p;
  }
  // Key nodes: the buccal corners of the gonial angles and of the process tips, the symphysis corners.
  auto key = [&](const std::string& name, int a, int b, int c) {
    const int id = node_id(a, b, c);
    for (std::size_t i = 0; i < boundary.boundary_vertices.size(); ++i)
      if (boundary.boundary_vertices[i] == id) t.key_nodes[name] = static_cast<int>(i);
  };
  for (const auto& [side, sign] : {std::pair<std::string, int>{"left_", 1}, {"right_", -1}}) {
    key(side + "gonion_corner", sign * 6, 0, 1);
    key(side + "condyle_top_back", sign * 6, 3, 1);
    key(side + "condyle_top_front", sign * 5, 3, 1);
    key(side + "coronoid_tip_back", sign * 4, 3, 1);
    key(side + "coronoid_tip_front", sign * 3, 3, 1);
    key(side + "notch_front", sign * 4, 2, 1);
    key(side + "notch_back", sign * 5, 2, 1);
  }
  key("symphysis_top_buccal", 0, 1, 1);
  key("symphysis_top_lingual", 0, 1, 0);  // with the one above: an edge through the bone (its chord's count)
  key("symphysis_bottom_buccal", 0, 0, 1);

  // The default dentate mandible's landmarks and insertions (hexbite generate mandible --landmarks, left
  // side; the right side is the mirror image).
  const std::pair<const char*, Vec3> left[] = {
      {"condyle_tmj_point", {49.6924, 31.0315, 79.1834}},
      {"coronoid_tip", {49.1487, -1.9685, 77.1864}},
      {"first_molar_bite_point", {27.9086, -16.8029, 49.2832}},
      {"gonion", {44.4571, 17.8018, 27.5485}},
      {"premolar_bite_point", {22.7031, -24.1464, 47.8091}},
      {"superficial_masseter.insertion", {49.3856, 14.3220, 33.4026}},
      {"deep_masseter.insertion", {50.9165, 17.1554, 64.0000}},
      {"medial_pterygoid.insertion", {38.7297, 12.8811, 33.1189}},
      {"anterior_temporalis.insertion", {44.3936, 0.2053, 59.1415}},
      {"middle_temporalis.insertion", {49.6534, -2.0000, 77.1943}},
      {"posterior_temporalis.insertion", {49.1702, 1.0583, 75.1493}},
      {"inferior_lateral_pterygoid.insertion", {48.0000, 25.6460, 71.6853}},
      {"superior_lateral_pterygoid.insertion", {48.6065, 26.2124, 78.0000}},
      {"anterior_digastric.insertion", {6.7963, -38.4332, 6.6649}},
  };
  for (const auto& [name, p] : left) {
    t.reference[std::string("left_") + name] = p;
    t.reference[std::string("right_") + name] = {-p[0], p[1], p[2]};
  }
  t.reference["incisal_point"] = {0.0, -39.0, 44.2288};
  const std::pair<const char*, Vec3> derived[] = {{"condyle_top", {50.0, 31.0, 83.2}},
                                                  {"coronoid_top", {49.0, -2.0, 77.2}},
                                                  {"sigmoid_notch", {48.0, 16.0, 65.3}},
                                                  {"condyle_back", {50.0, 36.4, 78.0}}};
  for (const auto& [name, p] : derived) {
    t.derived[std::string("left_") + name] = p;
    t.derived[std::string("right_") + name] = {-p[0], p[1], p[2]};
  }
  t.derived["incisal_top"] = {0.0, -39.0, 44.23};
  // extreme_points() of the default mandible's surface (hexbite generate mandible, voxel 1 mm).
  t.extremes = {
      {"max_x", {59.45, 29.0, 78.0}},        {"min_x", {-59.45, 29.0, 78.0}},
      {"min_y", {0.0, -48.61, 15.0}},        {"left_max_y", {46.0, 36.4, 78.0}},
      {"right_max_y", {-46.0, 36.4, 78.0}},  {"left_max_z", {50.0, 31.0, 83.19}},
      {"right_max_z", {-50.0, 31.0, 83.19}}, {"min_z", {0.0, -42.0, 5.66}},
  };
  return t;
}

}  // namespace hexbite
