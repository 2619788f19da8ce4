// Scenario files: the shipped scenarios load and resolve, every validation error names the file, the
// line and the specific complaint, and patches select the right boundary facets.
#include "scenarios/scenario.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include "common/error.h"
#include "common/number_format.h"
#include "tests/test_util.h"

namespace hexbite {
namespace {

namespace fs = std::filesystem;

// Landmarks with the names the built-in mandible generator documents (mesher/mandible_generator.h):
// distinct coordinates, so that a point resolved to the wrong name would show.
Landmarks generator_landmarks() {
  Landmarks l;
  double offset = 0;
  for (const char* side : {"left", "right"}) {
    const double sign = std::string(side) == "left" ? 1 : -1;
    for (const char* point :
         {"condyle_tmj_point", "first_molar_bite_point", "premolar_bite_point", "coronoid_tip", "gonion"}) {
      offset += 1;
      l.points[std::string(side) + "_" + point] = {sign * (20 + offset), -offset, 40 + offset};
    }
  }
  l.points["incisal_point"] = {0, -45, 45};
  const std::pair<const char*, double> muscles[] = {
      {"superficial_masseter", 190.4},      {"deep_masseter", 81.6},
      {"medial_pterygoid", 174.8},          {"anterior_temporalis", 158.0},
      {"middle_temporalis", 95.6},          {"posterior_temporalis", 75.6},
      {"inferior_lateral_pterygoid", 66.9}, {"superior_lateral_pterygoid", 28.7},
      {"anterior_digastric", 40.0}};
  for (const char* side : {"left", "right"}) {
    const double sign = std::string(side) == "left" ? 1 : -1;
    for (const auto& [muscle, force] : muscles) {
      offset += 1;
      l.muscles.push_back(
          {std::string(side) + "_" + muscle, force, {sign * 45, offset, 30}, {sign * 55, offset - 10, 80}});
    }
  }
  return l;
}

std::string write_scenario(const std::string& text, const std::string& file_name = "bad.yaml") {
  const std::string path = test::temp_dir() + "/" + file_name;
  test::write_file(path, text);
  return path;
}

// A valid scenario; the tests below change one thing in it. Line numbers are those of this text.
const std::string kValid = R"(name: t
geometry:
  mandible: {variant: dentate}
muscles:
  - name: right_superficial_masseter
    activation: 0.5
supports:
  - {name: nut, at: right_first_molar_bite_point, radius_mm: 4, bite: true}
  - {name: right_condyle, at: right_condyle_tmj_point, radius_mm: 6}
  - {name: left_condyle, at: left_condyle_tmj_point, radius_mm: 6}
)";

std::string replace(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// The message of the InputError that loading (and, with `resolve`, resolving) `text` throws.
std::string error_of(const std::string& text, bool resolve = false) {
  const std::string path = write_scenario(text);
  try {
    Scenario s = load_scenario(path);
    if (resolve) resolve_points(s, generator_landmarks());
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError for:\n" << text;
  return "";
}

#define EXPECT_ERROR_AT(message, line, complaint)                                          \
  do {                                                                                     \
    const std::string m_ = (message);                                                      \
    EXPECT_NE(m_.find("bad.yaml:" + std::to_string(line) + ":"), std::string::npos) << m_; \
    EXPECT_NE(m_.find(complaint), std::string::npos) << m_;                                \
  } while (0)

TEST(Scenario, ValidBaseLoadsWithDefaults) {
  Scenario s = load_scenario(write_scenario(kValid));
  EXPECT_EQ(s.name, "t");
  EXPECT_EQ(s.geometry.source, GeometrySource::kMandible);
  EXPECT_EQ(s.mesh.method, MeshMethod::kGrid);
  EXPECT_EQ(s.mesh.target_hexes, 2500);
  EXPECT_EQ(s.mesh.validation_levels, 1);
  EXPECT_EQ(s.materials.default_material.E_MPa, 11000);
  EXPECT_EQ(s.materials.default_material.poisson, 0.28);
  EXPECT_EQ(s.solver.degree, 1);
  EXPECT_EQ(s.solver.linear_solver, LinearSolverChoice::kAuto);
  EXPECT_EQ(s.solver.tolerance, 1e-10);
  EXPECT_TRUE(s.outputs.vtu);
  EXPECT_FALSE(s.outputs.inp);
  ASSERT_EQ(s.muscles.size(), 1u);
  EXPECT_EQ(s.muscles[0].radius_mm, 10);
  EXPECT_EQ(s.muscles[0].where.line, 5);
  EXPECT_FALSE(s.muscles[0].insertion.resolved);
  ASSERT_EQ(s.supports.size(), 3u);
  EXPECT_EQ(s.supports[1].where.line, 9);
  EXPECT_EQ(s.supports[0].at.name, "right_first_molar_bite_point");
  EXPECT_EQ(s.supports[0].fixed, (std::array<bool, 3>{true, true, true}));

  const Landmarks l = generator_landmarks();
  resolve_points(s, l);
  const Muscle& m = s.muscles[0];
  EXPECT_EQ(*m.max_force_N, 190.4);
  const Vec3 force = muscle_force(m);
  EXPECT_NEAR(std::hypot(force[0], force[1], force[2]), 0.5 * 190.4, 1e-9);
  EXPECT_EQ(s.supports[0].at.xyz, l.points.at("right_first_molar_bite_point"));
  resolve_points(s, l);  // a second call changes nothing
  EXPECT_EQ(s.supports[0].at.xyz, l.points.at("right_first_molar_bite_point"));
}

TEST(Scenario, EveryShippedScenarioLoadsAndResolves) {
  const fs::path folder = fs::path(HEXBITE_SOURCE_DIR) / "scenarios";
  int count = 0;
  for (const auto& entry : fs::directory_iterator(folder)) {
    if (entry.path().extension() != ".yaml") continue;
    SCOPED_TRACE(entry.path().string());
    ++count;
    Scenario s = load_scenario(entry.path().string());
    EXPECT_EQ(s.name, entry.path().stem().string());
    resolve_points(s, generator_landmarks());
    for (const Muscle& m : s.muscles) {
      EXPECT_TRUE(m.insertion.resolved) << m.name;
      EXPECT_TRUE(m.max_force_N.has_value()) << m.name;
    }
    for (const Support& support : s.supports) EXPECT_TRUE(support.at.resolved) << support.name;
    for (const Probe& probe : s.probes) EXPECT_TRUE(probe.at.resolved) << probe.name;
  }
  EXPECT_GE(count, 3);
}

TEST(Scenario, LateralBiteHardNutIsThePapersSetUp) {
  Scenario s = load_scenario(std::string(HEXBITE_SOURCE_DIR) + "/scenarios/lateral_bite_hard_nut.yaml");
  EXPECT_EQ(s.geometry.source, GeometrySource::kMandible);
  EXPECT_EQ(s.materials.default_material.E_MPa, 11000);
  EXPECT_EQ(s.materials.default_material.poisson, 0.28);
  ASSERT_EQ(s.muscles.size(), 18u);
  auto activation = [&](const std::string& name) {
    for (const Muscle& m : s.muscles)
      if (m.name == name) return m.activation;
    ADD_FAILURE() << "no muscle " << name;
    return -1.0;
  };
  EXPECT_EQ(activation("right_superficial_masseter"), 0.56);
  EXPECT_EQ(activation("left_superficial_masseter"), 0.20);
  EXPECT_EQ(activation("right_anterior_temporalis"), 0.65);
  EXPECT_EQ(activation("left_anterior_temporalis"), 0.51);
  EXPECT_EQ(activation("right_medial_pterygoid"), 0.97);
  EXPECT_EQ(activation("left_medial_pterygoid"), 0.47);
  EXPECT_EQ(activation("right_inferior_lateral_pterygoid"), 0.50);
  EXPECT_EQ(activation("left_inferior_lateral_pterygoid"), 0.36);
  EXPECT_EQ(activation("left_anterior_digastric"), 0.0);
  int bites = 0;
  for (const Support& support : s.supports) {
    if (!support.bite) continue;
    ++bites;
    EXPECT_EQ(support.at.name, "right_first_molar_bite_point");
    EXPECT_EQ(support.fixed, (std::array<bool, 3>{true, true, true}));
    EXPECT_FALSE(support.spring_N_per_mm3);
  }
  EXPECT_EQ(bites, 1);
  std::vector<std::string> supported;
  for (const Support& support : s.supports) supported.push_back(support.at.name);
  EXPECT_NE(std::find(supported.begin(), supported.end(), "left_condyle_tmj_point"), supported.end());
  EXPECT_NE(std::find(supported.begin(), supported.end(), "right_condyle_tmj_point"), supported.end());
}

TEST(Scenario, RealJawRightMolarResolvesAgainstItsLandmarkFile) {
  const std::string jaw = test::shared_data("jaw/jaw_smooth.stl");
  const std::string landmarks = test::shared_data("jaw/landmarks.yaml");
  const std::string path = write_scenario(R"(name: real_jaw_right_molar
geometry:
  surface: {file: )" + jaw + R"(, units: mm}
landmarks: {file: )" + landmarks + R"(}
activation_pattern:
  superficial_masseter: {right: 0.56, left: 0.20}
  deep_masseter: {right: 0.56, left: 0.20}
  anterior_temporalis: {right: 0.65, left: 0.51}
  middle_temporalis: {right: 0.65, left: 0.51}
  posterior_temporalis: {right: 0.65, left: 0.51}
  medial_pterygoid: {right: 0.97, left: 0.47}
  inferior_lateral_pterygoid: {right: 0.50, left: 0.36}
  superior_lateral_pterygoid: {right: 0.50, left: 0.36}
  anterior_digastric: 0
supports:
  - {name: bite, at: right_first_molar_bite_point, radius_mm: 4, bite: true}
  - {name: right_tmj, at: right_condyle_tmj_point, radius_mm: 6}
  - {name: left_tmj, at: left_condyle_tmj_point, radius_mm: 6}
)",
                                          "real_jaw_right_molar.yaml");
  Scenario s = load_scenario(path);
  EXPECT_EQ(s.geometry.source, GeometrySource::kSurface);
  EXPECT_EQ(s.landmarks.file, fs::path(landmarks).lexically_normal().string());
  resolve_points(s, read_landmarks(s.landmarks.file, s.landmarks.scale_to_mm));
  EXPECT_NEAR(s.supports[0].at.xyz[0], -24.80, 1e-9);
  for (const Muscle& m : s.muscles) {
    if (m.name == "right_medial_pterygoid") {
      EXPECT_NEAR(*m.max_force_N, 174.8, 1e-9);
    }
  }
}

TEST(Scenario, RelativeFilesAreResolvedAgainstTheScenarioFolder) {
  const std::string dir = test::temp_dir();
  fs::create_directories(dir + "/data");
  test::write_file(dir + "/data/jaw.stl", "solid x\nendsolid x\n");
  test::write_file(dir + "/s.yaml", replace(kValid, "mandible: {variant: dentate}",
                                            "surface: {file: data/jaw.stl, units: cm}"));
  const Scenario s = load_scenario(dir + "/s.yaml");
  EXPECT_EQ(s.geometry.file, (fs::path(dir) / "data/jaw.stl").string());
  EXPECT_EQ(s.geometry.scale_to_mm, 10.0);
  EXPECT_EQ(s.landmarks.scale_to_mm, 10.0);  // a landmark file shares the surface's unit by default

  EXPECT_ERROR_AT(error_of(replace(kValid, "mandible: {variant: dentate}", "surface: {file: missing.stl}")),
                  3, "surface file 'missing.stl'");
  // A path that resolves to itself is not repeated (before: "'/x/missing.stl' (resolved to
  // '/x/missing.stl')").
  const std::string absolute = dir + "/missing.stl";
  const std::string message =
      error_of(replace(kValid, "mandible: {variant: dentate}", "surface: {file: " + absolute + "}"));
  EXPECT_NE(message.find("surface file '" + absolute + "' does not exist"), std::string::npos) << message;
  EXPECT_EQ(message.find("resolved to"), std::string::npos) << message;

  // A CT volume may be a folder (a DICOM series); a surface may not.
  fs::create_directories(dir + "/data/ct_series");
  test::write_file(dir + "/ct.yaml", replace(kValid, "mandible: {variant: dentate}",
                                             "ct: {file: data/ct_series, threshold: 400}"));
  EXPECT_EQ(load_scenario(dir + "/ct.yaml").geometry.file, (fs::path(dir) / "data/ct_series").string());
  test::write_file(dir + "/ct3.yaml", replace(kValid, "mandible: {variant: dentate}",
                                              "ct: {file: data/ct_series, threshold: 400, series: 3}"));
  EXPECT_EQ(load_scenario(dir + "/ct3.yaml").geometry.dicom_series, "3");
  EXPECT_ERROR_AT(
      error_of(replace(kValid, "mandible: {variant: dentate}", "surface: {file: " + dir + "/data}")), 3,
      "does not exist or is not a file; give a path");
}

TEST(Scenario, ActivationPatternExpandsToBothSides) {
  Scenario s = load_scenario(
      write_scenario(replace(kValid, "muscles:\n  - name: right_superficial_masseter\n    activation: 0.5\n",
                             "activation_pattern:\n  deep_masseter: 0.3\n"
                             "  medial_pterygoid: {right: 0.97}\n")));
  ASSERT_EQ(s.muscles.size(), 3u);
  EXPECT_EQ(s.muscles[0].name, "left_deep_masseter");
  EXPECT_EQ(s.muscles[1].name, "right_deep_masseter");
  EXPECT_EQ(s.muscles[1].activation, 0.3);
  EXPECT_EQ(s.muscles[2].name, "right_medial_pterygoid");
  EXPECT_EQ(s.muscles[2].where.line, 6);
  resolve_points(s, generator_landmarks());
  EXPECT_EQ(*s.muscles[2].max_force_N, 174.8);
}

// Mistakes in an activation_pattern are named as the pattern's: a key with its side
// ("right_superficial_masseter: 0.5") and a misspelt key were reported as the muscles
// 'left_right_superficial_masseter' or 'left_superficial_maseter', which the user never wrote, with the
// advice to give their insertion, origin and max_force_N (which a pattern cannot); "key: {}" added no
// muscle without a word.
TEST(ScenarioErrors, ActivationPatternMistakesAreNamedAsThePatterns) {
  const std::string base =
      replace(kValid, "muscles:\n  - name: right_superficial_masseter\n    activation: 0.5\n", "");
  const std::string prefixed = error_of(base + "activation_pattern:\n  right_superficial_masseter: 0.5\n");
  EXPECT_ERROR_AT(
      prefixed, 9,
      "activation_pattern key 'right_superficial_masseter' starts with 'right_', but a pattern key "
      "is a muscle name without its side");
  EXPECT_ERROR_AT(prefixed, 9,
                  "write superficial_masseter: {right: 0.5}, or list 'right_superficial_masseter'");
  EXPECT_EQ(prefixed.find("left_right_"), std::string::npos) << prefixed;

  const std::string misspelt =
      error_of(base + "activation_pattern:\n  superficial_maseter: {right: 0.5}\n", /*resolve=*/true);
  EXPECT_ERROR_AT(
      misspelt, 9,
      "activation_pattern key 'superficial_maseter' is no muscle of the landmarks "
      "(right_superficial_maseter is unknown); the closest pattern keys are 'superficial_masseter'");
  EXPECT_EQ(misspelt.find("give all three"), std::string::npos) << misspelt;

  EXPECT_ERROR_AT(error_of(base + "activation_pattern:\n  superficial_masseter: {}\n  deep_masseter: 0.5\n"),
                  9, "activation_pattern.superficial_masseter gives no side");
}

// A landmark set with the left muscle only: the pattern's key was called "no muscle of the landmarks" and
// the closest pattern key suggested was the same key. The missing side is named, and the side that exists
// suggested with its activation.
TEST(ScenarioErrors, ActivationPatternOfAMuscleWithOneSideInTheLandmarksNamesTheSide) {
  Landmarks landmarks = generator_landmarks();
  landmarks.muscles.erase(std::remove_if(landmarks.muscles.begin(), landmarks.muscles.end(),
                                         [](const MuscleLine& m) { return m.name == "right_deep_masseter"; }),
                          landmarks.muscles.end());
  Scenario s = load_scenario(write_scenario(kValid + "activation_pattern:\n  deep_masseter: 0.5\n"));
  const std::string err = test::message_of<InputError>([&] { resolve_points(s, landmarks); });
  EXPECT_NE(err.find("activation_pattern key 'deep_masseter' makes right_deep_masseter, but the landmarks "
                     "have left_deep_masseter only; activate that side alone (deep_masseter: {left: 0.5}), "
                     "or add right_deep_masseter to the landmark file"),
            std::string::npos)
      << err;
  EXPECT_EQ(err.find("closest pattern keys"), std::string::npos) << err;
}

// A landmark file may give a muscle 0 N; an active muscle of 0 N loads nothing (alone, the run solved a
// zero load and reported a bite force of 0 N with exit 0).
TEST(ScenarioErrors, ActiveMuscleWithoutForceInTheLandmarks) {
  Landmarks landmarks = generator_landmarks();
  for (MuscleLine& m : landmarks.muscles)
    if (m.name == "right_superficial_masseter") m.max_force_N = 0;
  Scenario s = load_scenario(write_scenario(kValid));
  try {
    resolve_points(s, landmarks);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_ERROR_AT(std::string(e.what()), 5,
                    "muscle 'right_superficial_masseter' is active (0.5) but its max_force_N from the "
                    "landmarks is 0 N");
  }
  // Its own max_force_N, or activation 0, is fine.
  Scenario own = load_scenario(
      write_scenario(replace(kValid, "activation: 0.5", "activation: 0.5\n    max_force_N: 100")));
  EXPECT_NO_THROW(resolve_points(own, landmarks));
}

TEST(Scenario, MaterialRegionsOverrideTheDefault) {
  Scenario s = load_scenario(write_scenario(kValid + R"(materials:
  default: {E_MPa: 12000}
  regions:
    - {name: implant, sphere: {center: incisal_point, radius_mm: 5}, E_MPa: 110000, poisson: 0.33}
    - {name: block, box: {min: [-1, -1, -1], max: [1, 1, 1]}, poisson: 0.3}
)"));
  resolve_points(s, generator_landmarks());
  EXPECT_EQ(material_at(s.materials, {0, -45, 46}).E_MPa, 110000);
  EXPECT_EQ(material_at(s.materials, {0, 0, 0}).E_MPa, 12000);
  EXPECT_EQ(material_at(s.materials, {0, 0, 0}).poisson, 0.3);
  EXPECT_EQ(material_at(s.materials, {50, 50, 50}).poisson, 0.28);
}

// ----- one test per validation error -----

TEST(ScenarioErrors, UnknownKeySuggestsTheClosest) {
  EXPECT_ERROR_AT(error_of(replace(kValid, "    activation: 0.5", "    activaton: 0.5")), 6,
                  "unknown key 'activaton' in muscles[0]; did you mean 'activation'?");
  EXPECT_ERROR_AT(error_of(replace(kValid, "supports:", "suports:")), 7, "did you mean 'supports'?");
  EXPECT_ERROR_AT(error_of(replace(kValid, "variant: dentate", "variant: dentat")), 3,
                  "did you mean 'dentate'?");
}

// A choice given nothing, a list or a mapping (mesh.core: ~, a study's first try to drop the base's core)
// was told "write a word such as left_condyle", the hint for point names; it gets the valid choices, as a
// wrong word does.
TEST(ScenarioErrors, AChoiceThatIsNoWordGetsTheValidChoices) {
  EXPECT_ERROR_AT(error_of(kValid + "mesh: {core: ~}\n"), 11,
                  "mesh.core must be text, found nothing; valid choices are 'grid', 'swept', 'auto'");
  EXPECT_ERROR_AT(error_of(kValid + "solver: {linear_solver: [direct]}\n"), 11,
                  "solver.linear_solver must be text, found a list; valid choices are 'auto', 'cg_amg', "
                  "'direct'");
  EXPECT_ERROR_AT(error_of(replace(kValid, "variant: dentate", "variant: {a: b}")), 3,
                  "geometry.mandible.variant must be text, found a mapping; valid choices are 'dentate', "
                  "'edentulous', 'atrophic'");
  EXPECT_ERROR_AT(error_of(kValid + "mesh: {method: \"\"}\n"), 11,
                  "mesh.method is empty; valid choices are 'grid', 'sheets'");
}

// A file or a DICOM series given nothing or a list was told to "write a word such as left_condyle" too.
TEST(ScenarioErrors, AFileThatIsNoTextAsksForTheFilesPath) {
  EXPECT_ERROR_AT(
      error_of(replace(kValid, "mandible: {variant: dentate}", "surface: {file: ~}")), 3,
      "geometry.surface.file must be text, found nothing; give the surface file's path, e.g. file: "
      "jaw.stl");
  EXPECT_ERROR_AT(
      error_of(replace(kValid, "mandible: {variant: dentate}", "ct: {file: [a], threshold: 400}")), 3,
      "found a list; give the CT volume file's path, e.g. file: jaw.mha");
  EXPECT_ERROR_AT(error_of(kValid + "landmarks: {file: ~}\n"), 11,
                  "found nothing; give the landmark file's path, e.g. file: landmarks.yaml");
}

// A name is one line of printable text: "incisal\n*HEADING" split model.inp's comment line, and the rest of
// the name became a CalculiX keyword line.
TEST(ScenarioErrors, NamesWithControlCharactersAreRefusedAtTheirLine) {
  EXPECT_ERROR_AT(error_of(replace(kValid, "name: t", "name: \"incisal\\n*HEADING\\nbite\"")), 1,
                  "name holds a control character (0x0A, a line break)");
  EXPECT_ERROR_AT(error_of(replace(kValid, "name: right_superficial_masseter", "name: \"right\\tmasseter\"")),
                  5, "muscles[0].name holds a control character (0x09)");
  EXPECT_ERROR_AT(error_of(replace(kValid, "{name: nut,", "{name: \"n\\x01ut\",")), 8,
                  "supports[0].name holds a control character (0x01)");
  EXPECT_ERROR_AT(error_of(kValid + "probes:\n  - {name: \"chin\\r\", at: incisal_point}\n"), 12,
                  "probes[0].name holds a control character (0x0D)");
  // The C1 controls and the Unicode separators passed (helper AA): U+0085 is NEXT LINE, YAML's "\N".
  EXPECT_ERROR_AT(error_of(replace(kValid, "name: t", "name: \"ab\\u0085cd\"")), 1,
                  "name holds a control character (U+0085, a line break)");
  EXPECT_ERROR_AT(error_of(replace(kValid, "{name: nut,", "{name: \"n\\u009but\",")), 8,
                  "supports[0].name holds a control character (U+009B)");
  EXPECT_ERROR_AT(error_of(replace(kValid, "{name: nut,", "{name: \"n\\u2028ut\",")), 8,
                  "supports[0].name holds a Unicode line separator (U+2028)");
}

// mesh.fit_volume (the boundary nodes moved off the surface until the volume matches) is read for both
// methods, and is false by default.
TEST(Scenario, FitVolumeIsReadForBothMethods) {
  EXPECT_FALSE(load_scenario(write_scenario(kValid)).mesh.fit_volume);
  EXPECT_TRUE(load_scenario(write_scenario(kValid + "mesh: {fit_volume: true}\n")).mesh.fit_volume);
  const Scenario sheets =
      load_scenario(write_scenario(kValid + "mesh:\n  method: sheets\n  fit_volume: true\n"));
  EXPECT_TRUE(sheets.mesh.fit_volume);
  EXPECT_EQ(sheets.mesh.method, MeshMethod::kSheets);
  EXPECT_ERROR_AT(error_of(kValid + "mesh: {fit_volume: maybe}\n"), 11,
                  "mesh.fit_volume must be true or false");
}

// mesh.grid_frame (axes or arch) is read for the grid method and refused for the sheets method.
TEST(Scenario, GridFrameIsReadForTheGridMethodOnly) {
  EXPECT_FALSE(load_scenario(write_scenario(kValid)).mesh.arch_frame);
  EXPECT_TRUE(load_scenario(write_scenario(kValid + "mesh: {grid_frame: arch}\n")).mesh.arch_frame);
  EXPECT_FALSE(load_scenario(write_scenario(kValid + "mesh: {grid_frame: axes}\n")).mesh.arch_frame);
  EXPECT_ERROR_AT(error_of(kValid + "mesh: {grid_frame: curved}\n"), 11, "'curved'");
  EXPECT_ERROR_AT(error_of(kValid + "mesh:\n  method: sheets\n  grid_frame: arch\n"), 13,
                  "mesh.grid_frame lays the overlay grid of method grid, but mesh.method is sheets");
}

// mesh.core (grid, swept or auto) is read for the grid method only; swept implies the arch frame and
// contradicts an explicit grid_frame: axes; auto leaves the grid core's frame to grid_frame.
TEST(Scenario, SweptCoreIsReadForTheGridMethodAndImpliesTheArchFrame) {
  EXPECT_EQ(load_scenario(write_scenario(kValid)).mesh.core, MeshCore::kGrid);
  const Scenario swept = load_scenario(write_scenario(kValid + "mesh: {core: swept}\n"));
  EXPECT_EQ(swept.mesh.core, MeshCore::kSwept);
  EXPECT_TRUE(swept.mesh.arch_frame);
  EXPECT_EQ(load_scenario(write_scenario(kValid + "mesh: {core: grid}\n")).mesh.core, MeshCore::kGrid);
  const Scenario automatic = load_scenario(write_scenario(kValid + "mesh: {core: auto, grid_frame: axes}\n"));
  EXPECT_EQ(automatic.mesh.core, MeshCore::kAuto);
  EXPECT_FALSE(automatic.mesh.arch_frame);
  EXPECT_ERROR_AT(error_of(kValid + "mesh: {core: octree}\n"), 11, "'octree'");
  EXPECT_ERROR_AT(error_of(kValid + "mesh:\n  method: sheets\n  core: swept\n"), 13,
                  "mesh.core chooses the core of method grid, but mesh.method is sheets");
  EXPECT_ERROR_AT(error_of(kValid + "mesh:\n  grid_frame: axes\n  core: swept\n"), 13,
                  "mesh.core swept sweeps the core across the dental arch, but mesh.grid_frame is axes");
}

TEST(ScenarioErrors, RepeatedKey) {
  EXPECT_ERROR_AT(
      error_of(replace(kValid, "    activation: 0.5", "    activation: 0.5\n    activation: 0.6")), 7,
      "key 'activation' appears twice in muscles[0] (first on line 6)");
}

TEST(ScenarioErrors, MissingRequiredFields) {
  EXPECT_ERROR_AT(error_of(replace(kValid, "name: t\n", "description: no name\n")), 1,
                  "the scenario has no 'name', which is required");
  EXPECT_ERROR_AT(error_of(replace(kValid, "    activation: 0.5", "    radius_mm: 8")), 5,
                  "muscles[0] has no 'activation', which is required");
  EXPECT_ERROR_AT(error_of(replace(kValid, ", radius_mm: 6}\n  - {name: left", "}\n  - {name: left")), 9,
                  "supports[1] has no 'radius_mm'");
  EXPECT_ERROR_AT(error_of(replace(kValid, "geometry:\n  mandible: {variant: dentate}\n", "")), 1,
                  "has no 'geometry'");
}

// Whole numbers are decimal, as YAML 1.2 reads them: `target_hexes: 04000` was read as octal (2048 hexes,
// exit 0), and `2e3` was "not a whole number".
TEST(Scenario, WholeNumbersAreDecimalAndMayBeWrittenInScientificNotation) {
  for (const auto& [text, hexes] : std::vector<std::pair<std::string, int>>{
           {"04000", 4000}, {"2e3", 2000}, {"2.0e3", 2000}, {"+3000", 3000}, {"3000.0", 3000}}) {
    const Scenario s = load_scenario(write_scenario(kValid + "mesh: {target_hexes: " + text + "}\n"));
    EXPECT_EQ(s.mesh.target_hexes, hexes) << text;
  }
  EXPECT_EQ(load_scenario(write_scenario(kValid + "mesh: {validation_levels: 02}\n")).mesh.validation_levels,
            2);
}

TEST(ScenarioErrors, IllTypedFields) {
  EXPECT_ERROR_AT(error_of(replace(kValid, "activation: 0.5", "activation: high")), 6,
                  "muscles[0].activation must be a number, found 'high'");
  EXPECT_ERROR_AT(
      error_of(replace(kValid, "activation: 0.5", "activation: \"0.5\"")), 6,
      "must be a number, found the quoted text \"0.5\"; write it as a plain number, without quotes: 0.5");
  EXPECT_ERROR_AT(error_of(replace(kValid, "activation: 0.5", "activation: \"high\"")), 6,
                  "; write a plain finite number such as 2.5");
  EXPECT_ERROR_AT(error_of(replace(kValid, "activation: 0.5", "activation: !!str 0.5")), 6,
                  "must be a number, found the quoted text \"0.5\"");
  EXPECT_ERROR_AT(error_of(kValid + "mesh: {target_hexes: 2.5}\n"), 11,
                  "mesh.target_hexes must be a whole number");
  // Hexadecimal and octal are refused; a whole number in scientific notation is not "not whole".
  EXPECT_ERROR_AT(error_of(kValid + "mesh: {target_hexes: 0x1000}\n"), 11,
                  "mesh.target_hexes must be a whole number, found '0x1000'; write it in decimal digits");
  EXPECT_ERROR_AT(error_of(kValid + "mesh: {target_hexes: 0o7640}\n"), 11, "write it in decimal digits");
  // Whole numbers beyond an int are out of range, not "not whole" (1e10 was "must be a whole number").
  EXPECT_ERROR_AT(error_of(kValid + "mesh: {target_hexes: 1e10}\n"), 11,
                  "mesh.target_hexes is 10000000000 but must be from 8 to 5000000");
  EXPECT_ERROR_AT(error_of(kValid + "mesh: {validation_levels: 2147483648}\n"), 11,
                  "mesh.validation_levels is 2147483648 but must be from 0 (none) to 3");
  EXPECT_ERROR_AT(error_of(kValid + "solver: {max_iterations: 1e12}\n"), 11,
                  "solver.max_iterations is 1000000000000 but must be from 1 to 2147483647");
  EXPECT_ERROR_AT(error_of(kValid + "description: [a, b]\n"), 11,
                  "description must be text, found a list; write it as one line of text");
  EXPECT_ERROR_AT(error_of(kValid + "outputs: {vtu: maybe}\n"), 11, "outputs.vtu must be true or false");
  EXPECT_ERROR_AT(error_of(kValid + "probes: {name: x}\n"), 11, "probes must be a list");
  EXPECT_ERROR_AT(error_of(replace(kValid, "at: right_condyle_tmj_point", "at: [1, 2]")), 9,
                  "supports[1].at must be three numbers [x, y, z]");
  EXPECT_ERROR_AT(error_of(replace(kValid, "at: right_condyle_tmj_point", "at: 12")), 9,
                  "supports[1].at must be a point");
}

// A mandible dimension outside the generator's range loaded (the loader checked only > 0, and the angle
// against (90, 180)) and stopped generation with "--voxel 3 is outside the accepted range 0.25 to 1.5": a
// command-line option, no file line. Now the loader checks the generator's ranges at the parameter's line,
// with the range and the variant's default; the ends of the ranges are accepted.
TEST(ScenarioErrors, MandibleDimensionsOutsideTheGeneratorsRange) {
  const auto mandible = [](const std::string& keys) {
    return replace(kValid, "mandible: {variant: dentate}", "mandible:\n    " + keys);
  };
  std::string m = error_of(mandible("voxel_mm: 3"));
  EXPECT_ERROR_AT(m, 4, "geometry.mandible.voxel_mm is 3 mm");
  EXPECT_NE(m.find("0.25 to 1.5 mm"), std::string::npos) << m;
  EXPECT_NE(m.find("default 1 mm"), std::string::npos) << m;
  EXPECT_EQ(m.find("--voxel"), std::string::npos) << m;
  m = error_of(mandible("variant: edentulous\n    gonial_angle_deg: 100"));
  EXPECT_ERROR_AT(m, 5, "geometry.mandible.gonial_angle_deg is 100 deg");
  EXPECT_NE(m.find("105 to 140 deg"), std::string::npos) << m;
  EXPECT_NE(m.find("default 124 deg"), std::string::npos) << m;  // the edentulous variant's
  m = error_of(mandible("arch_width_mm: 200\n    variant: atrophic"));
  EXPECT_ERROR_AT(m, 4, "geometry.mandible.arch_width_mm is 200 mm");
  EXPECT_NE(m.find("75 to 120 mm"), std::string::npos) << m;
  EXPECT_NE(m.find("default 96 mm"), std::string::npos) << m;
  EXPECT_ERROR_AT(error_of(mandible("body_height_mm: 5")), 4, "8 to 40 mm");
  EXPECT_ERROR_AT(error_of(mandible("ramus_width_mm: 0")), 4, "22 to 40 mm");
  EXPECT_ERROR_AT(error_of(mandible("body_thickness_mm: -12")), 4, "8 to 20 mm");
  // The ends of the ranges load.
  const Scenario s =
      load_scenario(write_scenario(mandible("{voxel_mm: 1.5, gonial_angle_deg: 105, ramus_height_mm: 75}")));
  EXPECT_EQ(s.geometry.mandible.voxel_mm, 1.5);
  EXPECT_EQ(s.geometry.mandible.gonial_angle_deg, 105);
  EXPECT_EQ(s.geometry.mandible.ramus_height_mm, 75);
}

TEST(ScenarioErrors, YoungsModulusMustBePositive) {
  EXPECT_ERROR_AT(error_of(kValid + "materials:\n  default: {E_MPa: 0}\n"), 12,
                  "materials.default.E_MPa is 0 MPa but Young's modulus must be positive");
  EXPECT_ERROR_AT(error_of(kValid + "materials:\n  regions:\n    - {name: r, sphere: {center: [0, 0, 0], "
                                    "radius_mm: 2}, E_MPa: -5}\n"),
                  13, "materials.regions[0].E_MPa is -5 MPa");
  // A modulus in Pa left the stresses right and made the displacements a million times too small.
  EXPECT_ERROR_AT(error_of(kValid + "materials:\n  default: {E_MPa: 1.1e10}\n"), 12,
                  "materials.default.E_MPa is 1.1e+10 MPa, stiffer than any material");
  // 1e-300 gave a non-finite solution blamed on the supports, 4.9e-324 a deal.II exception with a stack
  // trace: softer than any solid, refused at the line like a modulus in Pa.
  EXPECT_ERROR_AT(error_of(kValid + "materials:\n  default: {E_MPa: 1e-300}\n"), 12,
                  "materials.default.E_MPa is 1e-300 MPa, below 1e-06 MPa: softer than any solid");
  EXPECT_ERROR_AT(error_of(kValid + "materials:\n  regions:\n    - {name: r, sphere: {center: [0, 0, 0], "
                                    "radius_mm: 2}, E_MPa: 4.9e-324}\n"),
                  13, "materials.regions[0].E_MPa is 4.94066e-324 MPa, below 1e-06 MPa");
  // The bound itself is allowed.
  EXPECT_NO_THROW(load_scenario(write_scenario(kValid + "materials:\n  default: {E_MPa: 1e-6}\n")));
}

TEST(ScenarioErrors, PoissonOutsideItsRange) {
  EXPECT_ERROR_AT(error_of(kValid + "materials:\n  default: {poisson: 0.5}\n"), 12,
                  "Poisson's ratio must lie strictly between -1 and 0.5");
  EXPECT_ERROR_AT(error_of(kValid + "materials:\n  default: {poisson: -1}\n"), 12,
                  "materials.default.poisson is -1");
}

// poisson 0.4999 with Q1 gave a tenth of the displacement (volumetric locking) with exit 0.
TEST(ScenarioErrors, NearlyIncompressibleMaterialNeedsDegreeTwo) {
  EXPECT_ERROR_AT(error_of(kValid + "materials:\n  default: {poisson: 0.4999}\n"), 12,
                  "poisson 0.4999 with solver.degree 1: linear hexes lock");
  EXPECT_ERROR_AT(error_of(kValid + "materials:\n  regions:\n    - {name: pdl, sphere: {center: [0, 0, 0], "
                                    "radius_mm: 2}, poisson: 0.49}\n"),
                  13, "write solver: {degree: 2} for a Poisson's ratio above 0.45");
  EXPECT_NO_THROW(load_scenario(write_scenario(kValid + "materials:\n  default: {poisson: 0.45}\n")));
  EXPECT_NO_THROW(load_scenario(
      write_scenario(kValid + "materials:\n  default: {poisson: 0.49}\nsolver: {degree: 2}\n")));
}

TEST(ScenarioErrors, ActivationOutsideZeroOne) {
  EXPECT_ERROR_AT(error_of(replace(kValid, "activation: 0.5", "activation: 1.5")), 6,
                  "muscles[0].activation is 1.5 but an activation must lie in [0, 1]");
  EXPECT_ERROR_AT(error_of(kValid + "activation_pattern:\n  deep_masseter: {left: -0.1}\n"), 12,
                  "activation_pattern.deep_masseter.left is -0.1");
}

TEST(ScenarioErrors, NegativeRadiusOrForce) {
  EXPECT_ERROR_AT(error_of(replace(kValid, "    activation: 0.5", "    activation: 0.5\n    radius_mm: -3")),
                  7, "muscles[0].radius_mm is -3 but must be positive (it is negative)");
  EXPECT_ERROR_AT(
      error_of(replace(kValid, "    activation: 0.5", "    activation: 0.5\n    max_force_N: -10")), 7,
      "muscles[0].max_force_N is -10 but must be positive");
  EXPECT_ERROR_AT(error_of(replace(kValid, "radius_mm: 4", "radius_mm: -4")), 8,
                  "supports[0].radius_mm is -4");
}

// A support of 1000 mm ran: it held the whole bone (and a muscle patch that large loaded all of it). Patch
// radii are at most 50 mm; the message names the line, the key, the value, the range and what to do.
TEST(ScenarioErrors, AbsurdPatchRadius) {
  EXPECT_ERROR_AT(
      error_of(replace(kValid, "radius_mm: 4", "radius_mm: 1000")), 8,
      "supports[0].radius_mm is 1000 mm but must be greater than 0 and at most 50 mm: a patch is an "
      "insertion "
      "or contact area, and a mandible is about 100 mm across, so 1000 mm would take in most or all of the "
      "bone; give the support patch radius in mm, e.g. 5, and check that the value is not in another unit");
  EXPECT_ERROR_AT(
      error_of(replace(kValid, "    activation: 0.5", "    activation: 0.5\n    radius_mm: 50.5")), 7,
      "muscles[0].radius_mm is 50.5 mm but must be greater than 0 and at most 50 mm");
  // The bound itself is allowed.
  EXPECT_NO_THROW(load_scenario(write_scenario(replace(kValid, "radius_mm: 4", "radius_mm: 50"))));
}

TEST(ScenarioErrors, ImplausibleForceTargetOrCoordinates) {
  // 1e30 N gave absurd figures with exit 0 and 1e300 N a "not finite" failure blaming the supports.
  EXPECT_ERROR_AT(
      error_of(replace(kValid, "    activation: 0.5", "    activation: 0.5\n    max_force_N: 1e30")), 7,
      "muscles[0].max_force_N is 1e+30 N, more than 10000 N");
  // 1 reached the grid mesher, whose message had no scenario line; 2e9 ran out of memory.
  EXPECT_ERROR_AT(error_of(kValid + "mesh: {target_hexes: 1}\n"), 11,
                  "mesh.target_hexes is 1 but must be from 8 to 5000000");
  EXPECT_ERROR_AT(error_of(kValid + "mesh: {target_hexes: 2000000000}\n"), 11,
                  "mesh.target_hexes is 2000000000");
  // A probe at 1e308 mm crashed the run (SIGFPE in the exact predicates); a direction of 1e200 mm
  // normalized to zero, so the muscle pulled with no force.
  EXPECT_ERROR_AT(error_of(kValid + "probes:\n  - {name: far, at: [1e308, 0, 0]}\n"), 12,
                  "probes[0].at[0] is 1e+308, beyond 1e+06 mm");
  EXPECT_ERROR_AT(
      error_of(replace(kValid, "    activation: 0.5", "    activation: 0.5\n    direction: [0, 1e200, 0]")),
      7, "muscles[0].direction[1] is 1e+200");
}

// Values just past a limit were quoted rounded to 6 digits, and so read as the limit they broke: "poisson
// 0.45 with solver.degree 1 ... use at most 0.45" for 0.4500001, "1e+07 MPa" for 10000001.
TEST(ScenarioErrors, AValueJustPastItsLimitIsQuotedWithItsOwnDigits) {
  EXPECT_ERROR_AT(error_of(kValid + "materials:\n  default: {poisson: 0.4500001}\n"), 12,
                  "poisson 0.4500001 with solver.degree 1");
  EXPECT_ERROR_AT(error_of(kValid + "materials:\n  default: {poisson: 0.49999999}\n"), 12,
                  "poisson 0.49999999 with solver.degree 1");
  EXPECT_ERROR_AT(error_of(kValid + "materials:\n  default: {E_MPa: 10000001}\n"), 12,
                  "materials.default.E_MPa is 10000001 MPa, stiffer");
  EXPECT_ERROR_AT(error_of(replace(kValid, "activation: 0.5", "activation: 1.0000001")), 6,
                  "muscles[0].activation is 1.0000001 but an activation must lie in [0, 1]");
  EXPECT_ERROR_AT(
      error_of(replace(kValid, "    activation: 0.5", "    activation: 0.5\n    max_force_N: 10000.0001")), 7,
      "muscles[0].max_force_N is 10000.0001 N, more than 10000 N");
  EXPECT_ERROR_AT(error_of(replace(kValid, "radius_mm: 4", "radius_mm: 50.00001")), 8,
                  "supports[0].radius_mm is 50.00001 mm but must be greater than 0 and at most 50 mm");
  // Values of few digits, and the limits, read as before.
  EXPECT_EQ(format_significant(0.45), "0.45");
  EXPECT_EQ(format_significant(1e7), "1e+07");
  EXPECT_EQ(format_significant(96), "96");
  EXPECT_EQ(format_significant(0.1 + 0.2), "0.30000000000000004");  // not the 0.3 it is not
  // A computed figure keeps 6 digits: its further ones are round-off.
  EXPECT_EQ(format_rounded(0.1 + 0.2), "0.3");
}

TEST(ScenarioErrors, ASecondYamlDocumentIsRefused) {
  EXPECT_ERROR_AT(error_of(kValid + "---\nname: other\n"), 12, "a second YAML document starts here");
  EXPECT_NO_THROW(load_scenario(write_scenario(kValid + "---\n")));  // an empty one changes nothing
  // After a document end marker the message named only '---'.
  EXPECT_ERROR_AT(error_of(kValid + "...\nprobes: []\n"), 12, "(after a '---' or '...' line)");
}

// yaml-cpp does not resolve merge keys: `<<: *anchor` was "unknown key '<<' in supports[1]".
TEST(ScenarioErrors, AMergeKeyIsNamed) {
  const std::string merged =
      replace(replace(kValid, "  - {name: right_condyle, at: right_condyle_tmj_point, radius_mm: 6}",
                      "  - &c {name: right_condyle, at: right_condyle_tmj_point, radius_mm: 6}"),
              "  - {name: left_condyle, at: left_condyle_tmj_point, radius_mm: 6}",
              "  - {<<: *c, name: left_condyle, at: left_condyle_tmj_point}");
  EXPECT_ERROR_AT(error_of(merged), 10, "YAML merge keys ('<<: *anchor') are not read in supports[2]");
}

TEST(ScenarioErrors, ZeroLineOfAction) {
  EXPECT_ERROR_AT(
      error_of(replace(kValid, "    activation: 0.5", "    activation: 0.5\n    direction: [0, 0, 0]")), 7,
      "muscle 'right_superficial_masseter' has a zero line of action");
  EXPECT_ERROR_AT(
      error_of(replace(kValid, "    activation: 0.5", "    activation: 0.5\n    direction: [0, 0, 1e-13]")),
      7, "has a zero line of action (direction [0, 0, 1e-13])");
  // Only known once the names are resolved: the origin is the insertion's own landmark.
  EXPECT_ERROR_AT(error_of(replace(kValid, "    activation: 0.5",
                                   "    activation: 0.5\n    origin: right_superficial_masseter.insertion"),
                           true),
                  7, "has a zero line of action: its origin equals its insertion");
  EXPECT_ERROR_AT(
      error_of(
          replace(kValid, "    activation: 0.5",
                  "    activation: 0.5\n    origin: right_deep_masseter.origin\n    direction: [0, 0, 1]")),
      8, "has both 'origin' and 'direction'");
}

TEST(ScenarioErrors, NoSupportIsSingular) {
  const std::string no_supports = kValid.substr(0, kValid.find("supports:"));
  EXPECT_ERROR_AT(error_of(no_supports), 1, "no supports");
  EXPECT_ERROR_AT(error_of(no_supports), 1, "singular");
  EXPECT_ERROR_AT(error_of(no_supports + "supports: []\n"), 7, "the problem is singular");
  EXPECT_ERROR_AT(
      error_of(no_supports +
               "supports:\n  - {name: a, at: incisal_point, radius_mm: 3, fixed: [z], bite: true}\n"),
      7, "no support holds the mandible along x");
}

TEST(ScenarioErrors, NoBiteSupportWhenTheBiteForceIsReported) {
  const std::string no_bite = replace(kValid, ", bite: true}", "}");
  EXPECT_ERROR_AT(error_of(no_bite), 7, "no support is marked 'bite: true'");
  EXPECT_NO_THROW(load_scenario(write_scenario(no_bite + "outputs: {bite_force: false}\n")));
}

TEST(ScenarioErrors, NoActiveMuscle) {
  EXPECT_ERROR_AT(error_of(replace(kValid, "activation: 0.5", "activation: 0")), 4, "no muscle is active");
}

TEST(ScenarioErrors, DuplicateNames) {
  EXPECT_ERROR_AT(error_of(replace(kValid, "{name: left_condyle", "{name: right_condyle")), 10,
                  "support 'right_condyle' is defined twice (first on line 9)");
  EXPECT_ERROR_AT(error_of(kValid + "activation_pattern:\n  superficial_masseter: 0.2\n"), 12,
                  "muscle 'right_superficial_masseter' is defined twice (first on line 5)");
  // The pattern written above the list: the list's entry is the second one (it used to be named as the
  // first, "first on line 7", at the pattern's line 5).
  EXPECT_ERROR_AT(
      error_of(replace(kValid, "muscles:", "activation_pattern:\n  superficial_masseter: 0.2\nmuscles:")), 7,
      "muscle 'right_superficial_masseter' is defined twice (first on line 5)");
  EXPECT_ERROR_AT(
      error_of(kValid + "probes:\n  - {name: p, at: incisal_point}\n  - {name: p, at: [0, 0, 0]}\n"), 13,
      "probe 'p' is defined twice");
  EXPECT_ERROR_AT(error_of(kValid + "landmarks:\n  points:\n    incisal_point: [0, 0, 0]\n", true), 13,
                  "extra point 'incisal_point' has the name of a landmark");
}

TEST(ScenarioErrors, FixedAndSpringTogether) {
  EXPECT_ERROR_AT(error_of(replace(kValid, "radius_mm: 6}\n  - {name: left",
                                   "radius_mm: 6, fixed: [x, y, z], spring_N_per_mm3: 50}\n  - {name: left")),
                  9, "support 'right_condyle' has both 'fixed' and 'spring_N_per_mm3'");
}

TEST(ScenarioErrors, UnknownPointNameListsTheClosestNames) {
  const std::string message =
      error_of(replace(kValid, "at: right_first_molar_bite_point", "at: right_molar_bite"), true);
  EXPECT_ERROR_AT(message, 8,
                  "unknown point name 'right_molar_bite'; the closest known names are "
                  "'right_first_molar_bite_point'");
  EXPECT_ERROR_AT(error_of(replace(kValid, "right_superficial_masseter", "right_superficial_maseter"), true),
                  5,
                  "muscle 'right_superficial_maseter' is not a muscle of the landmarks (closest: "
                  "'right_superficial_masseter'");
}

TEST(ScenarioErrors, GeometryNeedsExactlyOneSource) {
  const std::string dir = test::temp_dir();
  test::write_file(dir + "/jaw.stl", "solid x\nendsolid x\n");
  test::write_file(dir + "/bad.yaml", replace(kValid, "mandible: {variant: dentate}",
                                              "mandible: {}\n  surface: {file: jaw.stl}"));
  try {
    load_scenario(dir + "/bad.yaml");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_ERROR_AT(std::string(e.what()), 4, "geometry has both 'mandible' and 'surface'");
  }
}

// An unclosed '[' or '{' was reported where yaml-cpp noticed it, the line after (or several lines later);
// now at the bracket itself, with where the parser noticed it. Brackets in comments, quoted text and plain
// text do not count.
TEST(ScenarioErrors, UnclosedBracketIsReportedWhereItOpens) {
  const std::string message = error_of("name: t\ngeometry: {mandible: [1, 2\n");
  EXPECT_NE(
      message.find("/bad.yaml:2:22: YAML syntax error: this '[' is not closed (end of sequence flow not "
                   "found, noticed at line 3, column 1); add the ']' that closes it, and check the commas "
                   "between its entries"),
      std::string::npos)
      << message;
  const std::string text =
      "name: t\n"
      "description: see [1 # and [2\n"
      "geometry: {mandible: {variant: \"a [b\"}}  # [c\n"
      "supports:\n"
      "  - {name: nut, at: [1, 2, 3, radius_mm: 4, bite: true\n"
      "  - {name: b, at: x, radius_mm: 4}\n"
      "probes: []\n";
  EXPECT_ERROR_AT(error_of(text), 5,
                  "this '[' is not closed (end of sequence flow not found, noticed at line 6");
  EXPECT_NE(error_of(text).find("bad.yaml:5:21:"), std::string::npos) << error_of(text);
  EXPECT_ERROR_AT(error_of("name: t\nsupports: [{name: a}, {name: 'it''s [', at: x\n"), 2,
                  "this '{' is not closed (end of map flow not found, noticed at line 3");
  EXPECT_NE(error_of("name: t\nsupports: [{name: a}, {name: 'it''s [', at: x\n").find("bad.yaml:2:23:"),
            std::string::npos);
  // Other syntax errors keep yaml-cpp's place.
  EXPECT_ERROR_AT(error_of("name: t\nsupports:\n  - {name: nut, at: [1, 2, 3, radius_mm: 4}\n"), 3,
                  "YAML syntax error: illegal flow end");
}

// A tab in the indentation: yaml-cpp said only "illegal map value" at the colon after it (line 3,
// column 10 here), which does not name the tab.
TEST(ScenarioErrors, TabInTheIndentationIsNamed) {
  EXPECT_ERROR_AT(error_of("name: t\ngeometry:\n\tmandible: {}\n"), 3,
                  "YAML syntax error: this line is indented with a tab, which YAML does not allow");
  EXPECT_NE(error_of("name: t\ngeometry:\n\tmandible: {}\n").find("bad.yaml:3:1:"), std::string::npos);
  EXPECT_ERROR_AT(error_of("name: t\ngeometry:\n  \tmandible: {}\n"), 3, "indent with spaces");
  // A tab elsewhere (after the indentation) is not blamed.
  EXPECT_EQ(error_of("name:\tt\ngeometry: {mandible: [1, 2\n").find("tab"), std::string::npos);
}

TEST(ScenarioErrors, YamlSyntaxAndEmptyFiles) {
  EXPECT_ERROR_AT(error_of("name: t\ngeometry: {mandible: [1, 2\n"), 2, "YAML syntax error");
  EXPECT_ERROR_AT(
      error_of(""), 1,
      "the scenario file is empty; it needs at least 'name', 'geometry', 'supports' and the muscle "
      "forces ('muscles' or 'activation_pattern')");
  EXPECT_THROW(load_scenario("/nonexistent/scenario.yaml"), InputError);
}

// ----- patches -----

QuadSurface unit_cube() {
  QuadSurface cube;
  cube.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  cube.quads = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  return cube;
}

TEST(Patches, SelectFacetsWhoseCentreIsWithinTheRadius) {
  const QuadSurface cube = unit_cube();
  EXPECT_EQ(select_patch_quads(cube, {0.5, 0.5, 1.1}, 0.2), (std::vector<int>{1}));
  EXPECT_EQ(select_patch_quads(cube, {0.5, 0.5, 0.5}, 0.5), (std::vector<int>{0, 1, 2, 3, 4, 5}));
  EXPECT_TRUE(select_patch_quads(cube, {0.5, 0.5, 0.5}, 0.4).empty());
  EXPECT_TRUE(select_patch_quads(cube, {5, 5, 5}, 1).empty());
}

TEST(Patches, AnEmptyPatchIsReportedAtItsScenarioLine) {
  Scenario s = load_scenario(write_scenario(kValid));
  resolve_points(s, generator_landmarks());
  const Support& nut = s.supports[0];
  try {
    require_patch_quads(unit_cube(), nut.at.xyz, nut.radius_mm, nut.where, "support '" + nut.name + "'");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_ERROR_AT(std::string(e.what()), 8, "support 'nut' selects no surface facets");
    // The molar point is some 58 mm from the unit cube: no radius up to the largest (50 mm) would reach
    // it, so the message no longer advises a larger one (it said "increase radius_mm beyond that").
    EXPECT_ERROR_AT(std::string(e.what()), 8, "farther than any patch reaches (radius_mm is at most 50 mm)");
    EXPECT_ERROR_AT(std::string(e.what()), 8, "check its coordinates and their unit");
    EXPECT_EQ(std::string(e.what()).find("increase radius_mm"), std::string::npos) << e.what();
  }
  // A near miss: a larger radius is the remedy.
  try {
    require_patch_quads(unit_cube(), {0.5, 0.5, 2}, 0.5, nut.where, "support '" + nut.name + "'");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_ERROR_AT(std::string(e.what()), 8, "the nearest is 1 mm away; increase radius_mm");
  }
  EXPECT_EQ(require_patch_quads(unit_cube(), {0.5, 0.5, 1}, 0.1, nut.where, "support"),
            (std::vector<int>{1}));
}

}  // namespace
}  // namespace hexbite
