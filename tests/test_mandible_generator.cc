// The built-in CT-like mandible, its landmark files and surface extraction from CT volumes.
#include <gtest/gtest.h>

#include <tuple>

#include <cstring>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <utility>

#include "common/error.h"
#include "mesher/ct_surface.h"
#include "mesher/landmarks.h"
#include "mesher/mandible_generator.h"
#include "mesher/surface_check.h"
#include "mesher/surface_io.h"
#include "tests/test_util.h"

namespace hexbite {
namespace {

namespace fs = std::filesystem;

const GeneratedMandible& generated(MandibleVariant variant) {
  static std::map<MandibleVariant, GeneratedMandible> cache;
  auto it = cache.find(variant);
  if (it == cache.end()) {
    MandibleParameters p;
    p.variant = variant;
    it = cache.emplace(variant, generate_mandible(p)).first;
  }
  return it->second;
}

struct Box {
  Vec3 lo, hi;
  double size(int k) const { return hi[k] - lo[k]; }
};

Box bbox(const TriSurface& s) {
  Box b{{1e300, 1e300, 1e300}, {-1e300, -1e300, -1e300}};
  for (const auto& v : s.vertices)
    for (int k = 0; k < 3; ++k) {
      b.lo[k] = std::min(b.lo[k], v[k]);
      b.hi[k] = std::max(b.hi[k], v[k]);
    }
  return b;
}

Vec3 sub(const Vec3& a, const Vec3& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
double dot(const Vec3& a, const Vec3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

// Distance from p to triangle abc (closest point by Voronoi regions, Ericson's Real-Time Collision
// Detection 5.1.5), written out here so that the test does not share code with the generator.
double point_triangle_distance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = sub(b, a), ac = sub(c, a), ap = sub(p, a);
  auto dist_to = [&](const Vec3& q) { return std::sqrt(dot(sub(p, q), sub(p, q))); };
  auto along = [](const Vec3& o, const Vec3& d, double t) {
    return Vec3{o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]};
  };
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return dist_to(a);
  const Vec3 bp = sub(p, b);
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return dist_to(b);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return dist_to(along(a, ab, d1 / (d1 - d3)));
  const Vec3 cp = sub(p, c);
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return dist_to(c);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return dist_to(along(a, ac, d2 / (d2 - d6)));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return dist_to(along(b, sub(c, b), (d4 - d3) / ((d4 - d3) + (d5 - d6))));
  const double denom = 1.0 / (va + vb + vc);
  const double v = vb * denom, w = vc * denom;
  return dist_to({a[0] + ab[0] * v + ac[0] * w, a[1] + ab[1] * v + ac[1] * w, a[2] + ab[2] * v + ac[2] * w});
}

double distance_to_surface(const TriSurface& s, const Vec3& p) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& t : s.triangles)
    best = std::min(best, point_triangle_distance(p, s.vertices[t[0]], s.vertices[t[1]], s.vertices[t[2]]));
  return best;
}

// All heights where the vertical line through (x, y) crosses the surface.
std::vector<double> vertical_crossings(const TriSurface& s, double x, double y) {
  std::vector<double> z;
  for (const auto& t : s.triangles) {
    const Vec3 &a = s.vertices[t[0]], &b = s.vertices[t[1]], &c = s.vertices[t[2]];
    const double det = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
    if (std::abs(det) < 1e-12) continue;
    const double l1 = ((x - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (y - a[1])) / det;
    const double l2 = ((b[0] - a[0]) * (y - a[1]) - (x - a[0]) * (b[1] - a[1])) / det;
    if (l1 < 0 || l2 < 0 || l1 + l2 > 1) continue;
    z.push_back(a[2] + l1 * (b[2] - a[2]) + l2 * (c[2] - a[2]));
  }
  std::sort(z.begin(), z.end());
  return z;
}

double enclosed_volume(const TriSurface& s) {
  double six = 0;
  for (const auto& t : s.triangles) {
    const Vec3 &a = s.vertices[t[0]], &b = s.vertices[t[1]], &c = s.vertices[t[2]];
    six += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
           a[2] * (b[0] * c[1] - b[1] * c[0]);
  }
  return six / 6.0;
}

TEST(MandibleGenerator, EveryVariantIsClosedGenusZeroAndOutward) {
  for (auto v : {MandibleVariant::kDentate, MandibleVariant::kEdentulous, MandibleVariant::kAtrophic}) {
    SCOPED_TRACE(variant_name(v));
    TriSurface s = generated(v).surface;
    const std::size_t triangles = s.triangles.size();
    const SurfaceReport r = check_surface(s, variant_name(v));
    EXPECT_TRUE(r.usable()) << (r.problems.empty() ? "" : r.problems.front());
    EXPECT_TRUE(r.closed);
    EXPECT_TRUE(r.manifold);
    EXPECT_TRUE(r.consistently_oriented);
    EXPECT_TRUE(r.outward);
    EXPECT_EQ(r.components, 1u);
    EXPECT_EQ(r.euler_characteristic, 2);
    EXPECT_EQ(r.genus, 0);
    EXPECT_EQ(r.self_intersections, 0u);
    EXPECT_EQ(r.degenerate_triangles, 0u);
    // Nothing needed repairing: the generator's vertices are already shared and oriented.
    EXPECT_EQ(s.triangles.size(), triangles);
    EXPECT_GT(enclosed_volume(s), 0.0);
  }
}

TEST(MandibleGenerator, SizeAndBoundingBoxAreAnatomical) {
  const TriSurface& s = generated(MandibleVariant::kDentate).surface;
  EXPECT_GE(s.triangles.size(), 25000u);
  EXPECT_LE(s.triangles.size(), 50000u);
  const Box b = bbox(s);
  EXPECT_GE(b.size(0), 90.0);
  EXPECT_LE(b.size(0), 125.0);
  EXPECT_GE(b.size(1), 70.0);
  EXPECT_LE(b.size(1), 105.0);
  EXPECT_GE(b.size(2), 60.0);
  EXPECT_LE(b.size(2), 95.0);
  // Mirror-symmetric about x = 0 and placed like the real jaw in ../shared/data/jaw.
  EXPECT_NEAR(b.lo[0], -b.hi[0], 1e-6);
  EXPECT_GT(b.lo[2], 0.0);
  EXPECT_LT(b.lo[2], 15.0);
  EXPECT_LT(b.lo[1], -40.0);
  EXPECT_GT(b.hi[1], 25.0);
  const double volume_cm3 = enclosed_volume(s) / 1000.0;
  EXPECT_GT(volume_cm3, 40.0);
  EXPECT_LT(volume_cm3, 80.0);
}

TEST(MandibleGenerator, LandmarksHaveTheSharedNamesAndLieOnTheBone) {
  const GeneratedMandible& g = generated(MandibleVariant::kDentate);
  for (const char* side : {"left_", "right_"})
    for (const char* name :
         {"condyle_tmj_point", "coronoid_tip", "gonion", "first_molar_bite_point", "premolar_bite_point"})
      EXPECT_TRUE(g.landmarks.points.count(std::string(side) + name)) << side << name;
  EXPECT_TRUE(g.landmarks.points.count("incisal_point"));
  ASSERT_EQ(g.landmarks.muscles.size(), 18u);
  const std::vector<std::pair<std::string, double>> expected = {
      {"superficial_masseter", 190.4},      {"deep_masseter", 81.6},
      {"medial_pterygoid", 174.8},          {"anterior_temporalis", 158.0},
      {"middle_temporalis", 95.6},          {"posterior_temporalis", 75.6},
      {"inferior_lateral_pterygoid", 66.9}, {"superior_lateral_pterygoid", 28.7},
      {"anterior_digastric", 40.0}};
  for (const auto& [name, force] : expected)
    for (const char* side : {"left_", "right_"}) {
      const auto it = std::find_if(g.landmarks.muscles.begin(), g.landmarks.muscles.end(),
                                   [&](const MuscleLine& m) { return m.name == side + name; });
      ASSERT_NE(it, g.landmarks.muscles.end()) << side << name;
      EXPECT_DOUBLE_EQ(it->max_force_N, force);
      EXPECT_LE(distance_to_surface(g.surface, it->insertion), 1.0) << it->name;
      // The skull side: every line of action is at least 15 mm long.
      const Vec3 d = sub(it->origin, it->insertion);
      EXPECT_GT(std::sqrt(dot(d, d)), 15.0) << it->name;
    }
  for (const char* name : {"left_first_molar_bite_point", "left_premolar_bite_point", "incisal_point",
                           "left_coronoid_tip", "left_gonion"})
    EXPECT_LE(distance_to_surface(g.surface, g.landmarks.points.at(name)), 1e-6) << name;
  // The TMJ point is inside the condyle, 4 mm below its top, as in the real jaw's file.
  const Vec3 tmj = g.landmarks.points.at("left_condyle_tmj_point");
  EXPECT_GT(tmj[0], 40.0);
  EXPECT_GT(tmj[1], 20.0);
  EXPECT_GT(tmj[2], 70.0);
  // Elevators pull up, the digastric pulls down and back.
  const auto& ms = g.landmarks.muscles;
  const auto find = [&](const std::string& n) {
    return *std::find_if(ms.begin(), ms.end(), [&](const MuscleLine& m) { return m.name == n; });
  };
  for (const char* up : {"left_superficial_masseter", "left_deep_masseter", "left_medial_pterygoid",
                         "left_anterior_temporalis", "left_middle_temporalis"})
    EXPECT_GT(find(up).origin[2], find(up).insertion[2]) << up;
  EXPECT_LT(find("left_anterior_digastric").origin[2], find("left_anterior_digastric").insertion[2]);
  // Bite points are on the occlusal side: the highest crossing of their vertical line.
  const Vec3 m1 = g.landmarks.points.at("left_first_molar_bite_point");
  EXPECT_NEAR(vertical_crossings(g.surface, m1[0], m1[1]).back(), m1[2], 1e-6);
}

TEST(MandibleGenerator, SameParametersGiveTheSameBytes) {
  const std::string dir = test::temp_dir();
  MandibleParameters p;
  p.variant = MandibleVariant::kEdentulous;
  for (int run = 0; run < 2; ++run) {
    const GeneratedMandible g = generate_mandible(p);
    write_surface(dir + "/jaw" + std::to_string(run) + ".stl", g.surface);
    write_landmarks(dir + "/jaw" + std::to_string(run) + ".yaml", g.landmarks, mandible_landmark_header(p));
  }
  const std::string a = test::read_file(dir + "/jaw0.stl");
  EXPECT_GT(a.size(), 100000u);
  EXPECT_EQ(a, test::read_file(dir + "/jaw1.stl"));
  EXPECT_EQ(test::read_file(dir + "/jaw0.yaml"), test::read_file(dir + "/jaw1.yaml"));
}

// Body height in the molar region: the vertical extent of the bone on the line through the
// first-molar bite point.
double molar_body_height(const GeneratedMandible& g) {
  const Vec3 m = g.landmarks.points.at("left_first_molar_bite_point");
  const std::vector<double> z = vertical_crossings(g.surface, m[0], m[1]);
  EXPECT_GE(z.size(), 2u);
  return z.back() - z.front();
}

TEST(MandibleGenerator, AtrophicBodyIsClearlyLower) {
  const double dentate = molar_body_height(generated(MandibleVariant::kDentate));
  const double edentulous = molar_body_height(generated(MandibleVariant::kEdentulous));
  const double atrophic = molar_body_height(generated(MandibleVariant::kAtrophic));
  EXPECT_GT(dentate, 28.0);  // bone plus the fused crowns
  EXPECT_LT(edentulous, dentate - 5.0);
  EXPECT_LT(atrophic, edentulous - 5.0);
  EXPECT_LT(atrophic, 16.0);
  EXPECT_GT(atrophic, 8.0);
}

TEST(MandibleGenerator, ParametersChangeTheGeometry) {
  const Box base = bbox(generated(MandibleVariant::kDentate).surface);
  MandibleParameters wide;
  wide.arch_width_mm = 110;
  const Box w = bbox(generate_mandible(wide).surface);
  EXPECT_GT(w.size(0), base.size(0) + 10.0);

  MandibleParameters tall;
  tall.ramus_height_mm = 70;
  const Box t = bbox(generate_mandible(tall).surface);
  EXPECT_GT(t.hi[2], base.hi[2] + 8.0);

  MandibleParameters deep;
  deep.arch_depth_mm = 65;
  const Box d = bbox(generate_mandible(deep).surface);
  EXPECT_GT(d.size(1), base.size(1) + 5.0);
}

TEST(MandibleGenerator, RejectsParametersOutsideTheirRanges) {
  MandibleParameters p;
  p.body_height_mm = 3;
  EXPECT_THROW(complete_parameters(p), InputError);
  p = {};
  p.gonial_angle_deg = 200;
  EXPECT_THROW(complete_parameters(p), InputError);
  // Just past the limit: the message quotes the value with its own digits ("%g" printed the limit, 140).
  p.gonial_angle_deg = 140.0000001;
  try {
    complete_parameters(p);
    ADD_FAILURE() << "a gonial angle past its range was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "--gonial-angle 140.0000001 is outside the accepted range 105 to 140");
  }
  p = {};
  p.voxel_mm = -1;
  EXPECT_THROW(generate_mandible(p), InputError);
  EXPECT_THROW(parse_variant("healthy"), InputError);
  EXPECT_EQ(parse_variant("atrophic"), MandibleVariant::kAtrophic);
}

TEST(Landmarks, RoundTripAndFind) {
  const GeneratedMandible& g = generated(MandibleVariant::kDentate);
  const std::string path = test::temp_dir() + "/jaw.landmarks.yaml";
  write_landmarks(path, g.landmarks, "a header\nsecond line");
  const std::string text = test::read_file(path);
  EXPECT_EQ(text.rfind("# a header\n# second line\n", 0), 0u);
  const Landmarks back = read_landmarks(path);
  ASSERT_EQ(back.points.size(), g.landmarks.points.size());
  for (const auto& [name, p] : g.landmarks.points)
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(back.points.at(name)[k], p[k], 1e-4) << name;
  ASSERT_EQ(back.muscles.size(), g.landmarks.muscles.size());
  for (std::size_t i = 0; i < back.muscles.size(); ++i) {
    EXPECT_EQ(back.muscles[i].name, g.landmarks.muscles[i].name);
    EXPECT_NEAR(back.muscles[i].max_force_N, g.landmarks.muscles[i].max_force_N, 1e-4);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(back.muscles[i].insertion[k], g.landmarks.muscles[i].insertion[k], 1e-4);
      EXPECT_NEAR(back.muscles[i].origin[k], g.landmarks.muscles[i].origin[k], 1e-4);
    }
  }
  const auto ins = back.find("left_deep_masseter.insertion");
  ASSERT_TRUE(ins.has_value());
  EXPECT_NEAR((*ins)[2], g.landmarks.muscles[2].insertion[2], 1e-4);
  EXPECT_TRUE(back.find("incisal_point").has_value());
  EXPECT_FALSE(back.find("left_deep_masseter.belly").has_value());
  EXPECT_FALSE(back.find("nowhere").has_value());
}

TEST(Landmarks, ReadsTheSharedRealJawFile) {
  const Landmarks lm = read_landmarks(test::shared_data("jaw/landmarks.yaml"));
  EXPECT_EQ(lm.muscles.size(), 18u);
  EXPECT_EQ(lm.points.size(), 4u);
  const auto tmj = lm.find("left_condyle_tmj_point");
  ASSERT_TRUE(tmj.has_value());
  EXPECT_NEAR((*tmj)[0], 51.78, 1e-9);
  EXPECT_EQ(lm.muscles.front().name, "left_superficial_masseter");
  EXPECT_DOUBLE_EQ(lm.muscles.front().max_force_N, 190.4);
  // Scaling converts units (a file in cm read with 10 mm/cm).
  const Landmarks cm = read_landmarks(test::shared_data("jaw/landmarks.yaml"), 10.0);
  EXPECT_NEAR(cm.points.at("left_condyle_tmj_point")[2], 796.4, 1e-9);
}

// A landmark file of another mandible in the same frame was accepted silently, and the quad template placed
// by it landed 6.4-6.7 mm off the bone. Each file fits its own bone (median insertion distance 0 mm on the
// built-in mandible, 0.5 mm on the real jaw) and is flagged on the other (2.9 and 3.2 mm).
TEST(Landmarks, AFileOfAnotherMandibleIsFlaggedAndItsOwnIsNot) {
  const std::string kHow = "write units: <unit> in landmarks";
  const std::string jaw_file = test::shared_data("jaw/landmarks.yaml");
  const Landmarks jaw_landmarks = read_landmarks(jaw_file);
  const TriSurface jaw = load_closed_surface(test::shared_data("jaw/jaw_smooth.stl"), 1.0);
  const GeneratedMandible& built_in = generated(MandibleVariant::kDentate);
  EXPECT_EQ(landmark_fit_warning(jaw_landmarks, jaw, jaw_file, "mm", kHow), "");
  EXPECT_EQ(landmark_fit_warning(built_in.landmarks, built_in.surface, "m.yaml", "mm", kHow), "");
  const std::string on_jaw = landmark_fit_warning(built_in.landmarks, jaw, "m.yaml", "mm", kHow);
  EXPECT_NE(on_jaw.find("landmark file m.yaml: its 18 muscle insertions lie a median 2."), std::string::npos)
      << on_jaw;
  EXPECT_NE(on_jaw.find("deep_masseter"), std::string::npos) << on_jaw;
  const std::string on_built_in = landmark_fit_warning(jaw_landmarks, built_in.surface, jaw_file, "mm", kHow);
  EXPECT_NE(on_built_in.find("anterior_temporalis"), std::string::npos) << on_built_in;
  EXPECT_NE(on_jaw.find("; check that the file was written for this surface and in its frame"),
            std::string::npos)
      << on_jaw;
  // A file in cm read as mm is off by far more. The warning said only "check ... its frame and units"; read
  // in cm it fits, and the warning says so and how to give the unit.
  const Landmarks cm = read_landmarks(jaw_file, 0.1);
  const std::string in_cm = landmark_fit_warning(cm, jaw, jaw_file, "mm", kHow);
  EXPECT_NE(in_cm.find(" will be off; read in cm, they lie a median 0."), std::string::npos) << in_cm;
  EXPECT_NE(in_cm.find("mm from it: write units: cm in landmarks"), std::string::npos) << in_cm;
}

// A file with left and right swapped (x negated) fits the nearly symmetric bone as well as the right one and
// was taken without a word: the bite then lands on the other side. The real jaw's and the built-in
// mandible's files (which the shipped scenarios use) keep their sides; the mirrored ones are warned of.
TEST(Landmarks, SwappedSidesAreWarnedOfNamingAPair) {
  const std::string jaw_file = test::shared_data("jaw/landmarks.yaml");
  const Landmarks jaw = read_landmarks(jaw_file);
  EXPECT_EQ(landmark_side_warning(jaw, jaw_file), "");
  for (MandibleVariant variant :
       {MandibleVariant::kDentate, MandibleVariant::kEdentulous, MandibleVariant::kAtrophic})
    EXPECT_EQ(landmark_side_warning(generated(variant).landmarks, "m.yaml"), "");
  Landmarks mirrored = jaw;
  for (auto& [name, p] : mirrored.points) p[0] = -p[0];
  for (MuscleLine& m : mirrored.muscles) m.insertion[0] = -m.insertion[0];
  const std::string warning = landmark_side_warning(mirrored, "m.yaml");
  // Named by the pair farthest apart: the condyles, not insertions near the midline.
  EXPECT_NE(warning.find("landmark file m.yaml: left_condyle_tmj_point lies at x = -51.8 mm, at smaller x "
                         "than its partner right_condyle_tmj_point (x = 51.8 mm)"),
            std::string::npos)
      << warning;
  EXPECT_NE(warning.find("(and 10 more of its 11 left/right pairs)"), std::string::npos) << warning;
  EXPECT_NE(warning.find("swap left_ and right_ in its names"), std::string::npos) << warning;
}

void expect_landmark_error(const std::string& contents, const std::string& expected_fragment) {
  const std::string path = test::temp_dir() + "/bad.yaml";
  test::write_file(path, contents);
  try {
    read_landmarks(path);
    ADD_FAILURE() << "no error for:\n" << contents;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(expected_fragment), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

TEST(Landmarks, MalformedFilesNameTheFileLineAndColumn) {
  expect_landmark_error("landmarks:\n  a: [1, 2]\n", ":2:6: landmark 'a' must be a list of three");
  expect_landmark_error("landmarks:\n  a: [1, 2, x]\n", ":2:13: landmark 'a' coordinate must be a number");
  expect_landmark_error("landmarks: {a: [1, 2, 3]\n", "not valid YAML");
  expect_landmark_error("muscles:\n  - {name: m, max_force_N: 1, insertion: [0, 0, 0]}\n",
                        ":2:5: muscle 'm' has no 'origin'");
  expect_landmark_error("muscles:\n  - {name: m, max_force_N: -1, insertion: [0, 0, 0], origin: [0, 0, 1]}\n",
                        "must not be negative");
  expect_landmark_error("landmarks:\n  a: [1, 2, 3]\nmuscle:\n  - {}\n",
                        ":3:1: unknown section 'muscle'; did you mean 'muscles'?");
  expect_landmark_error(
      "units: cm\nlandmarks:\n  a: [1, 2, 3]\n",
      ":1:1: unknown section 'units'; a landmark file has no unit of its own: a scenario's "
      "landmarks.units says it, `hexbite mesh` reads it in the --units of its surface, and `hexbite "
      "reorder` in millimetres");
  // A mistyped muscle key gets the key it is a typo of (it listed the four keys only).
  expect_landmark_error("muscles:\n  - {name: m, max_force: 1, insertion: [0, 0, 0], origin: [0, 0, 1]}\n",
                        ":2:15: unknown muscle key 'max_force'; did you mean 'max_force_N'?");
  expect_landmark_error("landmarks:\n  a: [1, 2, 3]\n  a: [1, 2, 4]\n",
                        ":3: name 'a' is given twice (first on line 2)");
  expect_landmark_error("", "is empty");
  // yaml-cpp alone says "bad conversion" for a list used as a name.
  expect_landmark_error("landmarks:\n  a: [1, 2, 3]\n  ? [x, y]\n  : [1, 2, 3]\n",
                        ":3:5: expected a name (a plain word) as the key");
  EXPECT_THROW(read_landmarks(test::temp_dir() + "/missing.yaml"), InputError);
  // A folder was read as a stream and failed with a std::ios exception (exit 1, no file named).
  const std::string folder = test::temp_dir() + "/landmarks.yaml";
  std::filesystem::create_directory(folder);
  try {
    read_landmarks(folder);
    ADD_FAILURE() << "no error for a folder";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'" + folder + "' is a folder"), std::string::npos) << e.what();
  }
}

// Coordinates of 1e300 were accepted (the scenario's own are refused beyond 1e6 mm), and so was a muscle of
// 1e9 N; a coordinate in range could also overflow to infinity when scaled to millimetres.
TEST(Landmarks, CoordinatesAndForcesBeyondTheScenariosBoundsAreRefused) {
  expect_landmark_error("landmarks:\n  a: [1, 2, 3]\n  b: [0, 1e300, 0]\n",
                        ":3:10: landmark 'b' coordinate is 1e+300, beyond 1e+06 mm in size");
  expect_landmark_error("landmarks:\n  a: [-2000000, 0, 0]\n",
                        ":2:7: landmark 'a' coordinate is -2e+06, beyond");
  expect_landmark_error("landmarks:\n  a: [.nan, 0, 0]\n",
                        ":2:7: landmark 'a' coordinate must be a number, found '.nan'; write a plain finite "
                        "number such as 2.5");
  expect_landmark_error("landmarks:\n  a: [0, 0, -.inf]\n",
                        ":2:13: landmark 'a' coordinate must be a number, found '-.inf'");
  expect_landmark_error(
      "muscles:\n  - {name: m, max_force_N: 1,\n     insertion: [0, 0, 0],\n     origin: [0, 0, 1e7]}\n",
      ":4:21: muscle 'm' origin coordinate is 1e+07, beyond 1e+06 mm in size");
  expect_landmark_error(
      "muscles:\n  - {name: m, max_force_N: 1, insertion: [0, 1e300, 0], origin: [0, 0, 1]}\n",
      ":2:46: muscle 'm' insertion coordinate is 1e+300, beyond");
  expect_landmark_error(
      "muscles:\n  - {name: m, max_force_N: 1e9, insertion: [0, 0, 0], origin: [0, 0, 1]}\n",
      ":2:28: muscle 'm' max_force_N is 1e+09 N, more than 10000 N");
  // In range in the file's unit, beyond it in millimetres.
  const std::string path = test::temp_dir() + "/m.yaml";
  test::write_file(path, "landmarks:\n  a: [0, 0, 5000]\n");
  const std::string scaled =
      test::message_of<InputError>([&] { read_landmarks(path, /*scale_to_mm=*/1000.0); });
  EXPECT_NE(
      scaled.find(path + ":2:13: landmark 'a' coordinate is 5e+06 mm (5000 in the file's unit), beyond"),
      std::string::npos)
      << scaled;
  // The bounds themselves are accepted.
  test::write_file(path,
                   "landmarks:\n  a: [1e6, -1e6, 0]\nmuscles:\n  - {name: m, max_force_N: 10000, "
                   "insertion: [0, 0, 0], origin: [0, 0, 1]}\n");
  EXPECT_EQ(read_landmarks(path).muscles.at(0).max_force_N, 10000.0);
}

// Quoted numbers were read as numbers, where a scenario refuses them ("a quoted "0.5" is text"): the same
// rule and message now.
TEST(Landmarks, QuotedNumbersAreRefusedAsInAScenario) {
  expect_landmark_error(
      "muscles:\n  - {name: m, max_force_N: \"190.4\", insertion: [0, 0, 0], origin: [0, 0, 1]}\n",
      ":2:28: muscle 'm' max_force_N must be a number, found the quoted text \"190.4\"; write it as a plain "
      "number, without quotes: 190.4");
  expect_landmark_error("landmarks:\n  a: [\"47.12\", 0, 0]\n",
                        ":2:7: landmark 'a' coordinate must be a number, found the quoted text \"47.12\"");
}

// A landmark named like a muscle's insertion or origin was shadowed by the muscle's point, without a word
// (a scenario refuses such an extra point as ambiguous).
TEST(Landmarks, PointNamedLikeAMusclesInsertionIsRefusedAsAmbiguous) {
  expect_landmark_error(
      "landmarks:\n  m.insertion: [1, 2, 3]\nmuscles:\n  - {name: m, max_force_N: 1, insertion: [0, 0, 0], "
      "origin: [0, 0, 1]}\n",
      ":2:3: landmark 'm.insertion' has the name of the insertion of muscle 'm' (line 4), so the name would "
      "be "
      "ambiguous; rename it or use the muscle's insertion");
  expect_landmark_error(
      "muscles:\n  - {name: m, max_force_N: 1, insertion: [0, 0, 0], origin: [0, 0, 1]}\nlandmarks:\n  "
      "m.origin: [1, 2, 3]\n",
      ":4:3: landmark 'm.origin' has the name of the origin of muscle 'm' (line 2)");
  // A dotted name of no muscle of the file is a name like any other.
  const std::string path = test::temp_dir() + "/dotted.yaml";
  test::write_file(path, "landmarks:\n  implant.insertion: [1, 2, 3]\n");
  EXPECT_TRUE(read_landmarks(path).find("implant.insertion").has_value());
}

// Every option within its range, but together a short, wide ramus at the largest gonial angle made a bone
// of genus 2 (an opening through each ramus), written with exit 0 as if it were a mandible.
TEST(MandibleGenerator, DimensionsThatGiveABoneWithHolesAreRefused) {
  MandibleParameters p;
  p.ramus_height_mm = 40;
  p.ramus_width_mm = 40;
  p.gonial_angle_deg = 140;
  try {
    generate_mandible(p);
    ADD_FAILURE() << "a mandible with holes through it was generated";
  } catch (const InputError& e) {
    EXPECT_NE(
        std::string(e.what()).find("ramus height 40, ramus width 40 mm, gonial angle 140 deg give a bone "
                                   "with 2 hole(s) through it"),
        std::string::npos)
        << e.what();
  }
  p.ramus_height_mm = 45;  // one step back from the corner: a genus-0 mandible again
  TriSurface ok = generate_mandible(p).surface;
  const SurfaceReport r = check_surface(ok);
  EXPECT_TRUE(r.usable());
  EXPECT_EQ(r.genus, 0);
}

TEST(CtVolume, WritesAndReadsMetaImageAndNifti) {
  const VoxelVolume& ct = generated(MandibleVariant::kAtrophic).ct;
  for (const char* name : {"jaw.mha", "jaw.mhd", "jaw.nii", "jaw.nii.gz"}) {
    SCOPED_TRACE(name);
    const std::string path = test::temp_dir() + "/" + name;
    write_volume(path, ct);
    VolumeInfo info;
    const VoxelVolume back = read_volume(path, &info);
    // A NIfTI states millimetres (it said no unit, xyzt_units 0, and other tools had to guess); a
    // MetaImage has no field for it.
    EXPECT_EQ(info.length_unit, std::string(name).find(".nii") != std::string::npos ? "mm" : "") << name;
    EXPECT_EQ(back.dims, ct.dims);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(back.origin[k], ct.origin[k], 1e-4);
      EXPECT_NEAR(back.spacing_xyz()[k], ct.spacing, 1e-6);
    }
    ASSERT_EQ(back.values.size(), ct.values.size());
    EXPECT_TRUE(back.values == ct.values);
  }
  EXPECT_THROW(read_volume(test::temp_dir() + "/missing.mha"), InputError);
  const std::string bad = test::temp_dir() + "/jaw.raw";
  test::write_file(bad, "1234");
  EXPECT_THROW(read_volume(bad), InputError);
  const std::string garbage = test::temp_dir() + "/garbage.nii";
  test::write_file(garbage, "this is not a NIfTI header");
  EXPECT_THROW(read_volume(garbage), InputError);
}

TEST(CtVolume, SurfaceFromVolumeMatchesTheGeneratorAndRejectsHighThresholds) {
  const GeneratedMandible& g = generated(MandibleVariant::kAtrophic);
  const TriSurface s = surface_from_volume(g.ct, g.threshold);
  EXPECT_EQ(s.triangles.size(), g.surface.triangles.size());
  EXPECT_NEAR(enclosed_volume(s), enclosed_volume(g.surface), 1e-6 * enclosed_volume(s));
  EXPECT_THROW(surface_from_volume(g.ct, 5000.0), InputError);
  // An object touching the border of the scan is still closed (the volume is padded).
  VoxelVolume full = g.ct;
  std::fill(full.values.begin(), full.values.end(), 1000.0f);
  full.values[0] = 0.0f;
  TriSurface box = surface_from_volume(full, 500.0);
  const SurfaceReport r = check_surface(box);
  EXPECT_TRUE(r.closed);
  EXPECT_EQ(r.genus, 0);
}

// A damaged origin or spacing (Offset = 1e40) gave a surface of infinite coordinates with exit 0.
TEST(CtVolume, VoxelsBeyondTheCoordinateLimitAreRefused) {
  VoxelVolume far = generated(MandibleVariant::kAtrophic).ct;
  far.origin[0] = 1e40;
  EXPECT_NE(test::message_of<InputError>([&] {
              surface_from_volume(far, 500.0);
            }).find("the volume's voxels reach 1e+40 mm along x (origin 1e+40 mm"),
            std::string::npos);
  VoxelVolume wide = generated(MandibleVariant::kAtrophic).ct;
  wide.spacing = 1e300;
  EXPECT_NE(test::message_of<InputError>([&] {
              surface_from_volume(wide, 500.0);
            }).find("its origin or spacing is damaged or in other units"),
            std::string::npos);
}

// Damaged headers that crashed VTK's readers (found by mutation fuzzing): a MetaImage key of 255 characters
// (MetaIO's buffer overflow, exit 134), NDims = -1 (a hang), a NIfTI datatype VTK has no reader for (1536,
// FLOAT128, and 144) and a NIfTI dimension of size 0 (segmentation faults). Each is refused, naming the file.
TEST(CtVolume, DamagedHeadersAreRefusedNotACrash) {
  const std::string dir = test::temp_dir();
  const std::string tail = "ElementType = MET_UCHAR\nElementDataFile = LOCAL\nABCDEFGH";
  test::write_file(dir + "/key.mha", "ObjectType = Image\nNDims = 3\nDimSize = 2 2 2\n" +
                                         std::string(255, 'A') + " = 1\n" + tail);
  EXPECT_NE(test::message_of<InputError>([&] {
              read_volume(dir + "/key.mha");
            }).find("key.mha' line 4: a header key of 255 characters"),
            std::string::npos);
  test::write_file(dir + "/ndims.mha", "ObjectType = Image\nNDims = -1\nDimSize = 2 2 2\n" + tail);
  EXPECT_NE(test::message_of<InputError>([&] {
              read_volume(dir + "/ndims.mha");
            }).find("ndims.mha' line 2: NDims = -1, but a CT volume has 3 dimensions"),
            std::string::npos);
  // A number MetaIO cannot read was said to be "DimSize required and not defined", whichever key held it,
  // and a fractional DimSize was truncated.
  for (const auto& [line, fragment] : std::vector<std::pair<std::string, std::string>>{
           {"Offset = nan 0 0", "line 4: Offset = nan 0 0: expected 3 finite numbers, one per dimension"},
           {"ElementSpacing = 1 1", "line 4: ElementSpacing = 1 1: expected 3 finite numbers"},
           {"DimSize = 2 2 2.5", "line 4: DimSize = 2 2 2.5: expected 3 whole numbers of at least 1"}}) {
    test::write_file(dir + "/num.mha",
                     "ObjectType = Image\nNDims = 3\nDimSize = 2 2 2\n" + line + "\n" + tail);
    EXPECT_NE(
        test::message_of<InputError>([&] { read_volume(dir + "/num.mha"); }).find("num.mha' " + fragment),
        std::string::npos)
        << line;
  }
  // A 2 x 2 x 2 float NIfTI-1 file, then with one header field changed.
  std::string nifti(352, '\0');
  const auto put16 = [&](std::size_t at, int v) {
    nifti[at] = static_cast<char>(v & 0xff);
    nifti[at + 1] = static_cast<char>((v >> 8) & 0xff);
  };
  put16(0, 348 & 0xffff);
  const int dims[8] = {3, 2, 2, 2, 1, 1, 1, 1};
  for (int k = 0; k < 8; ++k) put16(40 + 2 * k, dims[k]);
  put16(70, 16);  // FLOAT32
  put16(72, 32);
  const float one = 1.0f, offset = 352.0f;
  for (int k = 0; k < 4; ++k) std::memcpy(&nifti[80 + 4 * k], &one, 4);  // pixdim[1..3]
  std::memcpy(&nifti[108], &offset, 4);
  nifti.replace(344, 4, std::string("n+1\0", 4));
  nifti += std::string(8 * 4, '\0');
  test::write_file(dir + "/ok.nii", nifti);
  EXPECT_NO_THROW(read_volume(dir + "/ok.nii"));
  for (const auto& [name, at, value, fragment] : std::vector<std::tuple<std::string, int, int, std::string>>{
           {"f128.nii", 70, 1536, "has NIfTI datatype 1536, not one of"},
           {"t144.nii", 70, 144, "has NIfTI datatype 144"},
           {"dim0.nii", 46, 0, "has NIfTI dimension 3 of size 0"}}) {
    std::string bad = nifti;
    bad[at] = static_cast<char>(value & 0xff);
    bad[at + 1] = static_cast<char>((value >> 8) & 0xff);
    test::write_file(dir + "/" + name, bad);
    EXPECT_NE(
        test::message_of<InputError>([&] { read_volume(dir + "/" + name); }).find(name + "' " + fragment),
        std::string::npos)
        << name;
  }
}

// A small volume that is not symmetric along any axis: value i + 10 j + 100 k.
VoxelVolume ramp_volume() {
  VoxelVolume v;
  v.dims = {4, 3, 2};
  v.origin = {10, 20, 30};
  v.spacing = 0.5;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 4; ++i) v.values.push_back(static_cast<float>(i + 10 * j + 100 * k));
  return v;
}

// A MetaImage write that failed (a full disk) was told by MetaIO on standard error only, and the cut-off
// file was kept: `generate mandible --ct` exited 0. Now an error, and nothing is left.
TEST(CtVolume, AFailedVolumeWriteIsAnErrorAndLeavesNothing) {
  VoxelVolume v;
  v.dims = {40, 40, 40};
  v.spacing = 0.5;
  std::uint32_t state = 12345;  // noise, which compression cannot shrink below the limit
  for (int i = 0; i < 40 * 40 * 40; ++i) {
    state = state * 1664525u + 1013904223u;
    v.values.push_back(static_cast<float>(state >> 8));
  }
  const std::string dir = test::temp_dir();
  for (const char* name : {"/ct.mha", "/ct.mhd", "/ct.nii"}) {
    std::string message;
    {
      const test::FileSizeLimit limit(20000);
      message = test::message_of<RunError>([&] { write_volume(dir + name, v); });
    }
    EXPECT_NE(message.find("cannot write volume '" + dir + name + "'"), std::string::npos) << message;
    EXPECT_TRUE(fs::is_empty(dir)) << name;
  }
  const std::string mha = test::message_of<RunError>([&] {
    const test::FileSizeLimit limit(20000);
    write_volume(dir + "/ct.mha", v);
  });
  EXPECT_NE(mha.find("the disk is full or the file passed a size limit"), std::string::npos) << mha;
}

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void write_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

void replace_once(std::string& s, const std::string& from, const std::string& to) {
  const auto at = s.find(from);
  ASSERT_NE(at, std::string::npos) << from;
  s.replace(at, from.size(), to);
}

// Uncompressed voxel data beyond what DimSize announces (a slice count too small in a hand-edited header):
// MetaIO read the first slices and ignored the rest, a cut bone with exit 0. Refused, in the file itself and
// in a separate data file; the right header reads.
TEST(CtVolume, MetaImageWithMoreVoxelDataThanItsHeaderAnnouncesIsRefused) {
  const std::string dir = test::temp_dir();
  std::string voxels;
  for (int i = 0; i < 4 * 3 * 2; ++i) {
    const float x = float(i);
    voxels.append(reinterpret_cast<const char*>(&x), sizeof x);
  }
  const auto header = [](const std::string& dims, const std::string& file) {
    return "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
           "ElementSpacing = 1 1 1\nDimSize = " +
           dims + "\nElementType = MET_FLOAT\nElementDataFile = " + file + "\n";
  };
  write_bytes(dir + "/right.mha", header("4 3 2", "LOCAL") + voxels);
  EXPECT_EQ(read_volume(dir + "/right.mha").dims, (std::array<int, 3>{4, 3, 2}));
  write_bytes(dir + "/extra.mha", header("4 3 1", "LOCAL") + voxels);
  write_bytes(dir + "/extra.mhd", header("4 3 1", "extra.raw"));
  write_bytes(dir + "/extra.raw", voxels);
  for (const char* name : {"extra.mha", "extra.mhd"}) {
    const std::string e = test::message_of<InputError>([&] { read_volume(dir + "/" + name); });
    EXPECT_NE(e.find(std::string(name) + "' holds 48 bytes of voxel data more than its header announces"),
              std::string::npos)
        << e;
  }
}

TEST(CtVolume, MetaImageDirectionAndNegativeSpacingAreHonouredOrRefused) {
  const std::string dir = test::temp_dir();
  write_volume(dir + "/ramp.mha", ramp_volume());
  const std::string plain = read_bytes(dir + "/ramp.mha");
  // VTK's reader ignores the direction; a flipped x axis must come out mirrored and placed from
  // the Offset towards -x, not silently as the identity.
  std::string flipped = plain;
  replace_once(flipped, "TransformMatrix = 1 0 0 0 1 0 0 0 1", "TransformMatrix = -1 0 0 0 1 0 0 0 1");
  write_bytes(dir + "/flipped.mha", flipped);
  const VoxelVolume f = read_volume(dir + "/flipped.mha");
  EXPECT_NEAR(f.origin[0], 10 - 3 * 0.5, 1e-9);
  EXPECT_NEAR(f.origin[1], 20, 1e-9);
  EXPECT_NEAR(f.origin[2], 30, 1e-9);
  ASSERT_EQ(f.values.size(), 24u);
  EXPECT_EQ(f.values[0], 3.0f);  // voxel (3, 0, 0) of the file is now the lowest x
  EXPECT_EQ(f.values[3], 0.0f);
  EXPECT_EQ(f.values[23], 120.0f);
  // A negative spacing points the axis backwards in the same way.
  std::string negative = plain;
  replace_once(negative, "ElementSpacing = 0.5 0.5 0.5", "ElementSpacing = 0.5 0.5 -0.5");
  write_bytes(dir + "/negative.mha", negative);
  const VoxelVolume n = read_volume(dir + "/negative.mha");
  EXPECT_NEAR(n.origin[2], 30 - 0.5, 1e-9);
  EXPECT_NEAR(n.spacing_xyz()[2], 0.5, 1e-12);
  EXPECT_EQ(n.values[0], 100.0f);
  // A rotated grid would need resampling: refused, naming the file.
  std::string rotated = plain;
  replace_once(rotated, "TransformMatrix = 1 0 0 0 1 0 0 0 1", "TransformMatrix = 0 1 0 -1 0 0 0 0 1");
  write_bytes(dir + "/rotated.mha", rotated);
  try {
    read_volume(dir + "/rotated.mha");
    ADD_FAILURE() << "a rotated MetaImage grid was read as axis-aligned";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("rotated.mha' is stored in a rotated orientation"),
              std::string::npos)
        << e.what();
  }
}

TEST(CtVolume, NiftiLengthsInMetresOrMicrometresAreConvertedToMillimetres) {
  const std::string dir = test::temp_dir();
  write_volume(dir + "/ramp.nii", ramp_volume());
  const std::string mm = read_bytes(dir + "/ramp.nii");
  ASSERT_GT(mm.size(), 348u);
  const VoxelVolume as_mm = read_volume(dir + "/ramp.nii");
  EXPECT_NEAR(as_mm.spacing_xyz()[0], 0.5, 1e-9);
  // Byte 123 of the NIfTI-1 header is xyzt_units: 1 metre, 2 millimetre, 3 micrometre.
  for (const auto& [code, scale] : {std::pair<char, double>{1, 1000}, {3, 0.001}}) {
    std::string other = mm;
    other[123] = static_cast<char>((other[123] & ~0x07) | code);
    write_bytes(dir + "/other.nii", other);
    const VoxelVolume v = read_volume(dir + "/other.nii");
    EXPECT_NEAR(v.spacing_xyz()[0], 0.5 * scale, 1e-9 * scale);
    EXPECT_NEAR(v.spacing_xyz()[2], 0.5 * scale, 1e-9 * scale);
    EXPECT_NEAR(v.origin[1], 20 * scale, 1e-6 * scale);
  }
}

TEST(CtVolume, AThresholdBelowEveryVoxelIsRefusedInsteadOfGivingTheScanBox) {
  const GeneratedMandible& g = generated(MandibleVariant::kAtrophic);
  try {
    surface_from_volume(g.ct, -5000.0);
    ADD_FAILURE() << "a threshold below every voxel gave a surface";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("every voxel of the volume is at or above the threshold"),
              std::string::npos)
        << e.what();
  }
  // Voxels without a value (NaN) do not count as background nor as bone.
  VoxelVolume with_nan = g.ct;
  with_nan.values[0] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(surface_from_volume(with_nan, -5000.0), InputError);
  EXPECT_NO_THROW(surface_from_volume(with_nan, g.threshold));
}

// Two blocks of "bone" (1000) in soft tissue (0): a big one with a closed pocket inside and a
// small separate one.
VoxelVolume two_blocks_one_pocket() {
  VoxelVolume v;
  v.dims = {30, 16, 16};
  v.spacing = 1.0;
  v.values.assign(30 * 16 * 16, 0.0f);
  auto inside = [](int i, int j, int k, int lo_i, int hi_i, int lo, int hi) {
    return i >= lo_i && i <= hi_i && j >= lo && j <= hi && k >= lo && k <= hi;
  };
  for (int k = 0; k < 16; ++k)
    for (int j = 0; j < 16; ++j)
      for (int i = 0; i < 30; ++i) {
        const bool big = inside(i, j, k, 2, 13, 2, 13) && !inside(i, j, k, 6, 9, 6, 9);
        const bool small = inside(i, j, k, 20, 25, 5, 10);
        if (big || small) v.values[(static_cast<std::size_t>(k) * 16 + j) * 30 + i] = 1000.0f;
      }
  return v;
}

// Voxels without a value (NaN, infinities: outside some exporters' field of view) are background. Next to
// the bone they gave surface points with NaN coordinates, written with exit 0.
TEST(CtVolume, VoxelsWithoutAValueAreBackground) {
  VoxelVolume v = two_blocks_one_pocket();
  const TriSurface clean = surface_from_volume(v, 500.0);
  const auto at = [&](int i, int j, int k) -> float& {
    return v.values[(static_cast<std::size_t>(k) * 16 + j) * 30 + i];
  };
  at(1, 7, 7) = std::numeric_limits<float>::quiet_NaN();  // beside the big block's face at i = 2
  at(14, 8, 8) = std::numeric_limits<float>::infinity();
  at(7, 14, 7) = -std::numeric_limits<float>::infinity();
  const TriSurface s = surface_from_volume(v, 500.0);
  for (const Vec3& p : s.vertices)
    ASSERT_TRUE(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]));
  EXPECT_NEAR(enclosed_volume(s), enclosed_volume(clean), 1e-9);
}

TEST(CtVolume, DroppedPiecesAndFilledCavitiesAreReported) {
  CtExtraction dropped;
  const TriSurface s = surface_from_volume(two_blocks_one_pocket(), 500.0, &dropped);
  EXPECT_EQ(dropped.dropped_bodies, 1);
  EXPECT_EQ(dropped.dropped_cavities, 1);
  // Iso-surfaces halfway between voxel centres: the big block encloses 12^3, the small 6^3, the
  // pocket 4^3 mm^3.
  EXPECT_NEAR(dropped.kept_mm3, enclosed_volume(s), 1e-6 * dropped.kept_mm3);
  EXPECT_NEAR(dropped.kept_mm3, 12.0 * 12 * 12, 30.0);
  EXPECT_NEAR(dropped.largest_dropped_body_mm3, 6.0 * 6 * 6, 20.0);
  EXPECT_NEAR(dropped.largest_dropped_cavity_mm3, 4.0 * 4 * 4, 15.0);
  CtExtraction none;
  surface_from_volume(generated(MandibleVariant::kAtrophic).ct, 620.0, &none);
  EXPECT_EQ(none.dropped_bodies, 0);
  EXPECT_EQ(none.dropped_cavities, 0);
}

TEST(Cli, SurfaceFromCtWarnsAboutWhatItDrops) {
  const std::string dir = test::temp_dir();
  write_volume(dir + "/blocks.mha", two_blocks_one_pocket());
  const auto r = test::run_hexbite(
      {"surface", "from-ct", dir + "/blocks.mha", "--threshold", "500", "-o", dir + "/blocks.stl"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("hexbite: warning: '" + dir + "/blocks.mha': kept only the largest piece"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("dropped 1 separate piece(s)"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("filled 1 enclosed cavity"), std::string::npos) << r.err;
}

// `--units` overrides the unit a volume states (or, for a MetaImage, the mm it is read in); the surface is
// written in mm. A NIfTI whose header says metres where its numbers are millimetres gives a bone 1000 times
// too large: the warning names the unit to give and that it overrides the file's. An unknown unit is refused
// before anything is read or written.
TEST(Cli, SurfaceFromCtTakesAUnitThatOverridesTheVolumes) {
  const std::string dir = test::temp_dir();
  write_volume(dir + "/jaw.mha", generated(MandibleVariant::kAtrophic).ct);
  write_volume(dir + "/jaw.nii", generated(MandibleVariant::kAtrophic).ct);
  std::string in_metres = read_bytes(dir + "/jaw.nii");
  ASSERT_GT(in_metres.size(), 348u);
  in_metres[123] = static_cast<char>((in_metres[123] & ~0x07) | 1);  // xyzt_units: metre
  write_bytes(dir + "/metres.nii", in_metres);
  auto extent = [&](const std::vector<std::string>& args) {
    std::vector<std::string> command = {"-q", "surface", "from-ct"};
    command.insert(command.end(), args.begin(), args.end());
    command.insert(command.end(), {"--threshold", "620", "-o", dir + "/out.stl"});
    const auto r = test::run_hexbite(command);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
    return largest_extent(read_surface(dir + "/out.stl"));
  };
  const double mm = extent({dir + "/jaw.mha"});
  EXPECT_GT(mm, 50.0);
  EXPECT_NEAR(extent({dir + "/jaw.mha", "--units", "cm"}), 10 * mm, 1e-6 * mm);
  EXPECT_NEAR(extent({dir + "/jaw.nii", "--units", "cm"}), 10 * mm, 1e-6 * mm);
  EXPECT_NEAR(extent({dir + "/metres.nii", "--units", "mm"}), mm, 1e-6 * mm);

  auto r = test::run_hexbite(
      {"-q", "surface", "from-ct", dir + "/metres.nii", "--threshold", "620", "-o", dir + "/big.stl"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("hexbite: warning: '" + dir + "/metres.nii': the surface is "), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("with its coordinates read as m; a mandible is about 100 mm"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("give --units mm (it overrides the unit the file states, m)"), std::string::npos)
      << r.err;

  fs::remove(dir + "/out.stl");
  r = test::run_hexbite({"surface", "from-ct", dir + "/jaw.mha", "--units", "inch", "--threshold", "620",
                         "-o", dir + "/out.stl"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("unknown length unit 'inch': use one of mm, cm, m"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/out.stl"));
}

TEST(Cli, GenerateThenSurfaceFromCtReproducesTheVolume) {
  const std::string dir = test::temp_dir();
  const auto gen = test::run_hexbite({"generate", "mandible", "-o", dir + "/jaw.stl", "--landmarks",
                                      dir + "/jaw.landmarks.yaml", "--ct", dir + "/jaw.mha"});
  ASSERT_EQ(gen.exit_code, 0) << gen.err;
  EXPECT_NE(gen.out.find("triangles"), std::string::npos);
  EXPECT_NE(gen.out.find("gonial angle 122"), std::string::npos) << gen.out;
  const auto ct = test::run_hexbite(
      {"surface", "from-ct", dir + "/jaw.mha", "--threshold", "620", "-o", dir + "/from_ct.stl"});
  ASSERT_EQ(ct.exit_code, 0) << ct.err;
  EXPECT_EQ(ct.err.find("warning"), std::string::npos) << ct.err;
  const double v0 = enclosed_volume(read_surface(dir + "/jaw.stl"));
  const double v1 = enclosed_volume(read_surface(dir + "/from_ct.stl"));
  EXPECT_NEAR(v1, v0, 0.01 * v0);
  const Landmarks lm = read_landmarks(dir + "/jaw.landmarks.yaml");
  EXPECT_EQ(lm.muscles.size(), 18u);
  EXPECT_NE(test::read_file(dir + "/jaw.landmarks.yaml").find("+x = subject's left"), std::string::npos);
}

TEST(Cli, GenerateRejectsBadOptionsWithoutWritingAnything) {
  const std::string dir = test::temp_dir();
  const auto bad_variant =
      test::run_hexbite({"generate", "mandible", "-o", dir + "/jaw.stl", "--variant", "healthy"});
  EXPECT_EQ(bad_variant.exit_code, 2);
  EXPECT_NE(bad_variant.err.find("unknown mandible variant"), std::string::npos) << bad_variant.err;
  const auto bad_ct =
      test::run_hexbite({"generate", "mandible", "-o", dir + "/jaw.stl", "--ct", dir + "/jaw.png"});
  EXPECT_EQ(bad_ct.exit_code, 2);
  const auto bad_range =
      test::run_hexbite({"generate", "mandible", "-o", dir + "/jaw.stl", "--gonial-angle", "170"});
  EXPECT_EQ(bad_range.exit_code, 2);
  EXPECT_NE(bad_range.err.find("--gonial-angle"), std::string::npos) << bad_range.err;
  // An explicit 0 is out of range too (it was taken as "not given": the default 1 mm voxel, exit 0).
  for (const char* option : {"--voxel", "--arch-width"}) {
    const auto zero = test::run_hexbite({"generate", "mandible", "-o", dir + "/jaw.stl", option, "0"});
    EXPECT_EQ(zero.exit_code, 2) << option << "\n" << zero.err;
    EXPECT_NE(zero.err.find(std::string(option) + ": 0 is out of range: give a number from "),
              std::string::npos)
        << zero.err;
  }
  EXPECT_TRUE(fs::is_empty(dir));
}

// The outputs of generate are one set: a write that fails leaves none of them, and earlier files of those
// names as they were. Before, a CT that could not be written left the new surface and landmarks beside the
// old CT, exit 1; here the CT is the one output that does not fit (a 3 MB file-size limit, SIGXFSZ ignored
// so that the write fails as on a full disk: the 2.4 MB surface fits, the 4.4 MB NIfTI does not). A CT in a
// folder that takes no new files (/proc, also for root) is refused when the command line is read. And a
// surface that did not fit on the disk (500 kB) must be named by its own path, not by the stage it is
// written into, nor the NIfTI by its temporary name.
TEST(Cli, GenerateWritesAllItsOutputsOrNone) {
  const std::string dir = test::temp_dir();
  test::write_file(dir + "/jaw.stl", "an earlier surface");
  const std::map<std::string, std::string> before = test::files_under(dir);
  auto r = test::run_hexbite({"-q", "generate", "mandible", "-o", dir + "/jaw.stl", "--landmarks",
                              dir + "/jaw.yaml", "--ct", dir + "/jaw.nii"},
                             {"bash", "-c", "trap '' XFSZ; ulimit -f 3000; exec \"$@\"", "bash"});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("cannot write volume '" + dir + "/jaw.nii': Out of disk space;"), std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find(".tmp"), std::string::npos) << r.err;  // the temporary file is not the user's concern
  EXPECT_NE(r.err.find("none of the outputs was written"), std::string::npos) << r.err;
  test::expect_same_files(before, test::files_under(dir));
  r = test::run_hexbite(
      {"-q", "generate", "mandible", "-o", dir + "/jaw.stl", "--ct", "/proc/hexbite_no_such_ct.mha"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("no file can be made in '/proc'"), std::string::npos) << r.err;
  test::expect_same_files(before, test::files_under(dir));

  r = test::run_hexbite({"-q", "generate", "mandible", "-o", dir + "/jaw.stl", "--ct", dir + "/jaw.mha"},
                        {"bash", "-c", "trap '' XFSZ; ulimit -f 500; exec \"$@\"", "bash"});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(r.err,
            "hexbite: failed: cannot write '" + dir +
                "/jaw.stl': the disk is full or the file passed a size limit (ulimit -f): make room on the "
                "disk or choose another output folder; none of the outputs was written (files of "
                "those names are as they were)\n");
  test::expect_same_files(before, test::files_under(dir));
}

TEST(Cli, SurfaceFromCtBadInputsExitTwoWithoutOutput) {
  const std::string dir = test::temp_dir();
  write_volume(dir + "/jaw.nii.gz", generated(MandibleVariant::kAtrophic).ct);
  const std::string out = dir + "/out.stl";
  const auto missing =
      test::run_hexbite({"surface", "from-ct", dir + "/none.mha", "--threshold", "620", "-o", out});
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.err.find("does not exist"), std::string::npos) << missing.err;
  test::write_file(dir + "/jaw.dcm", "DICM");
  const auto unknown =
      test::run_hexbite({"surface", "from-ct", dir + "/jaw.dcm", "--threshold", "620", "-o", out});
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_NE(unknown.err.find("unknown volume format"), std::string::npos) << unknown.err;
  const auto high =
      test::run_hexbite({"surface", "from-ct", dir + "/jaw.nii.gz", "--threshold", "3000", "-o", out});
  EXPECT_EQ(high.exit_code, 2);
  EXPECT_NE(high.err.find("jaw.nii.gz': nothing in the volume exceeds"), std::string::npos) << high.err;
  // Values as written, not std::to_string's "3000.000000".
  EXPECT_NE(high.err.find("the threshold 3000 (values range from "), std::string::npos) << high.err;
  const auto low =
      test::run_hexbite({"surface", "from-ct", dir + "/jaw.nii.gz", "--threshold", "-3000", "-o", out});
  EXPECT_EQ(low.exit_code, 2);
  EXPECT_NE(low.err.find("jaw.nii.gz': every voxel of the volume is at or above the threshold"),
            std::string::npos)
      << low.err;
  // A threshold that is no finite number is an option error, read before the volume (it was blamed on the
  // file: "'jaw.nii.gz': the threshold must be a finite number").
  const auto nan =
      test::run_hexbite({"surface", "from-ct", dir + "/jaw.nii.gz", "--threshold", "nan", "-o", out});
  EXPECT_EQ(nan.exit_code, 2);
  EXPECT_NE(nan.err.find("--threshold: nan is out of range: give a number that is finite"), std::string::npos)
      << nan.err;
  EXPECT_FALSE(fs::exists(out));
  // A cut-off volume is one error line with the reason in it. Before, MetaIO's own lines (each twice) and
  // VTK's coloured multi-line log came first, and the reason began with the reader's address
  // ("vtkNIFTIImageReader (0x55...): NIFTI file is truncated").
  write_volume(dir + "/jaw.mha", generated(MandibleVariant::kAtrophic).ct);
  const std::string mha = test::read_file(dir + "/jaw.mha");
  test::write_file(dir + "/cut.mha", mha.substr(0, mha.find("ElementDataFile")));
  test::write_file(dir + "/cut.nii.gz", test::read_file(dir + "/jaw.nii.gz").substr(0, 3000));
  for (const std::string cut : {"cut.mha", "cut.nii.gz"}) {
    const auto r =
        test::run_hexbite({"surface", "from-ct", dir + "/" + cut, "--threshold", "620", "-o", out});
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_EQ(r.err.rfind("hexbite: error: cannot read volume '" + dir + "/" + cut + "': ", 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(r.err.find("(0x"), std::string::npos) << r.err;
  }
  EXPECT_NE(test::run_hexbite({"surface", "from-ct", dir + "/cut.mha", "--threshold", "620", "-o", out})
                .err.find("(MetaIO: "),
            std::string::npos);
  // Cut off in its voxel data, a MetaImage file was read without an error: half a bone, exit 0.
  test::write_file(dir + "/half.mha", mha.substr(0, mha.size() / 2));
  const auto half =
      test::run_hexbite({"surface", "from-ct", dir + "/half.mha", "--threshold", "620", "-o", out});
  EXPECT_EQ(half.exit_code, 2) << half.err;
  EXPECT_NE(half.err.find("hexbite: error: volume '" + dir +
                          "/half.mha' is cut off: it holds less voxel data than its header announces"),
            std::string::npos)
      << half.err;
  EXPECT_FALSE(fs::exists(out));
  const auto ok =
      test::run_hexbite({"surface", "from-ct", dir + "/jaw.nii.gz", "--threshold", "620", "-o", out});
  EXPECT_EQ(ok.exit_code, 0) << ok.err;
  EXPECT_TRUE(fs::exists(out));
}

}  // namespace
}  // namespace hexbite
