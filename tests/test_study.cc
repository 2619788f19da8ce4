// hexbite study: a base scenario and its variants as one command. The comparison tables obey linear
// elasticity (half the Young's modulus, twice the displacements and strain energy, the same stresses and
// reactions on the same mesh), the three tables agree, a variant's run folder is what `hexbite run` writes,
// bad studies stop at the study's line before anything is written, and a failed variant leaves the output
// folder as it was. A 20 mm cube of a few hundred hexes keeps every solve well under a second.
#include <gtest/gtest.h>

#include <algorithm>
#include <csignal>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "common/error.h"
#include "postprocess/study_table.h"
#include "scenarios/study.h"
#include "tests/test_util.h"

namespace hexbite {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// The base scenario, in its own folder (base/cube.yaml beside base/cube.obj): a cube held at x = 0 (the
// "bite", so that there is a bite force) and pulled down at x = 20.
const std::string kBase = R"(name: cube_pull
geometry:
  surface: {file: cube.obj}
mesh: {target_hexes: 300, validation_levels: 0}
muscles:
  - {name: pull, activation: 1, insertion: [20, 10, 10], radius_mm: 6, direction: [0, 0, -1], max_force_N: 100}
supports:
  - {name: base, at: [0, 10, 10], radius_mm: 6, bite: true}
materials:
  default: {E_MPa: 11000, poisson: 0.28}
)";

const std::string kStudy = R"(name: stiffness what-if
base: base/cube.yaml
variants:
  - name: reference
  - name: soft
    set:
      materials.default.E_MPa: 5500
  - name: no_bite
    set:
      supports.base.bite: false
      outputs: {bite_force: false}
)";

// A fresh folder with base/cube.yaml, base/cube.obj and study.yaml holding `study`; returns the folder.
std::string study_folder(const std::string& study) {
  const std::string dir = test::temp_dir();
  fs::create_directories(dir + "/base");
  test::write_file(dir + "/base/cube.yaml", kBase);
  test::write_file(dir + "/base/cube.obj", test::cubes_obj(1));
  test::write_file(dir + "/study.yaml", study);
  return dir;
}

std::vector<std::string> split(const std::string& text, char separator) {
  std::vector<std::string> parts;
  std::stringstream in(text);
  for (std::string part; std::getline(in, part, separator);) parts.push_back(part);
  return parts;
}

// The cells of a CSV row; a row ending in ',' has an empty last cell, which getline drops.
std::vector<std::string> csv_cells(const std::string& row) {
  std::vector<std::string> cells = split(row, ',');
  if (!row.empty() && row.back() == ',') cells.emplace_back();
  return cells;
}

// kStudy run once for the tests that read its outputs.
class CubeStudy : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::string(study_folder(kStudy));
    const test::CommandResult r = test::run_hexbite({"study", *dir_ + "/study.yaml", "-o", *dir_ + "/out"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    out_ = new std::string(r.out);
    study_ = new json(json::parse(test::read_file(*dir_ + "/out/study.json")));
  }
  static const json& variant(const std::string& name) {
    for (const json& v : (*study_)["variants"])
      if (v["name"] == name) return v;
    throw std::runtime_error("no variant " + name);
  }
  static std::string* dir_;
  static std::string* out_;
  static json* study_;
};
std::string* CubeStudy::dir_ = nullptr;
std::string* CubeStudy::out_ = nullptr;
json* CubeStudy::study_ = nullptr;

TEST_F(CubeStudy, HalfTheModulusDoublesDisplacementAndEnergyAndKeepsStressesAndForces) {
  const json& ref = variant("reference");
  const json& soft = variant("soft");
  EXPECT_EQ(ref["hexes"], soft["hexes"]);  // the same mesh: the material does not change the meshing
  // Linear elasticity on one mesh with zero prescribed displacements: u scales with 1/E exactly, the
  // strains with it, the stresses and reactions not at all.
  const auto ratio = [&](const char* key) { return soft[key].get<double>() / ref[key].get<double>(); };
  EXPECT_NEAR(ratio("max_displacement_mm"), 2.0, 2e-6);
  EXPECT_NEAR(ratio("strain_energy_mJ"), 2.0, 2e-6);
  EXPECT_NEAR(ratio("von_mises_max_MPa"), 1.0, 1e-6);
  EXPECT_NEAR(ratio("von_mises_p99_MPa"), 1.0, 1e-6);
  EXPECT_NEAR(ratio("bite_force_N"), 1.0, 1e-6);
  EXPECT_NEAR(soft["reactions"]["base"].get<double>() / ref["reactions"]["base"].get<double>(), 1.0, 1e-6);
  // The muscle pulls 100 N; the only support takes all of it.
  EXPECT_NEAR(ref["bite_force_N"].get<double>(), 100.0, 1e-6);
  EXPECT_NEAR(soft["relative_to_reference"]["max_displacement_mm"].get<double>(), 1.0, 2e-6);
  EXPECT_NEAR(soft["relative_to_reference"]["von_mises_max_MPa"].get<double>(), 0.0, 1e-6);
  EXPECT_EQ(ref["relative_to_reference"]["strain_energy_mJ"].get<double>(), 0.0);
  EXPECT_EQ(soft["set"], json::parse(R"({"materials.default.E_MPa": "5500"})"));
}

TEST_F(CubeStudy, AVariantWithoutABiteHasNoBiteForceInAnyTable) {
  EXPECT_TRUE(variant("no_bite")["bite_force_N"].is_null());
  EXPECT_TRUE(variant("no_bite")["relative_to_reference"]["bite_force_N"].is_null());
  const std::vector<std::string> rows = split(test::read_file(*dir_ + "/out/study.csv"), '\n');
  ASSERT_EQ(rows.size(), 4u);
  const std::vector<std::string> header = csv_cells(rows[0]);
  const auto column = [&](const std::string& name) {
    return std::find(header.begin(), header.end(), name) - header.begin();
  };
  EXPECT_EQ(csv_cells(rows[3])[column("bite_force_N")], "");
  const std::string md = test::read_file(*dir_ + "/out/study.md");
  EXPECT_NE(md.find("| no_bite | `supports.base.bite: false; outputs: {bite_force: false}` | 0 |"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("| — |"), std::string::npos) << md;
}

TEST_F(CubeStudy, CsvMarkdownAndJsonAgree) {
  const std::vector<std::string> rows = split(test::read_file(*dir_ + "/out/study.csv"), '\n');
  ASSERT_EQ(rows.size(), 4u);
  const std::vector<std::string> header = csv_cells(rows[0]);
  const std::string md = test::read_file(*dir_ + "/out/study.md");
  for (std::size_t i = 1; i < rows.size(); ++i) {
    const std::vector<std::string> cells = csv_cells(rows[i]);
    ASSERT_EQ(cells.size(), header.size()) << rows[i];
    const json& v = (*study_)["variants"][i - 1];
    EXPECT_EQ(cells[0], v["name"].get<std::string>());
    for (const char* key :
         {"max_displacement_mm", "von_mises_max_MPa", "von_mises_p99_MPa", "strain_energy_mJ"}) {
      const auto at = std::find(header.begin(), header.end(), key) - header.begin();
      EXPECT_EQ(std::stod(cells[at]), v[key].get<double>()) << key;  // the same number, all its digits
    }
    const auto reaction = std::find(header.begin(), header.end(), "reaction_base_N") - header.begin();
    EXPECT_EQ(std::stod(cells[reaction]), v["reactions"]["base"].get<double>());
    // The Markdown row shows the figures rounded as hexbite run prints them.
    char displacement[64];
    std::snprintf(displacement, sizeof displacement, "%.5f", v["max_displacement_mm"].get<double>());
    EXPECT_NE(md.find("| " + v["name"].get<std::string>() + " |"), std::string::npos) << md;
    EXPECT_NE(md.find(displacement), std::string::npos) << displacement << '\n' << md;
  }
  EXPECT_NE(md.find("(+100.0 %)"), std::string::npos) << md;  // soft's displacement against the reference
  EXPECT_NE(out_->find(md), std::string::npos) << *out_;      // printed at the end
}

// A variant's folder is the run folder that `hexbite run` writes for the same scenario: the same files, the
// VTU files byte for byte, results.json apart from its timings.
TEST_F(CubeStudy, AVariantsFolderIsWhatHexbiteRunWrites) {
  const std::string run_dir = *dir_ + "/run_reference";
  const test::CommandResult r = test::run_hexbite({"-q", "run", *dir_ + "/base/cube.yaml", "-o", run_dir});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto study_files = test::files_under(*dir_ + "/out/reference");
  auto run_files = test::files_under(run_dir);
  const auto without_timings = [](const std::string& text) {
    json j = json::parse(text);
    j.erase("seconds");
    j.erase("study");  // the study's own record (tested below); `hexbite run` has none
    j["solver"].erase("seconds");
    for (json& level : j["validation"]["levels"]) level["solver"].erase("seconds");
    return j;
  };
  EXPECT_FALSE(json::parse(run_files["results.json"]).contains("study"));
  EXPECT_EQ(without_timings(study_files["results.json"]), without_timings(run_files["results.json"]));
  study_files.erase("results.json");
  run_files.erase("results.json");
  test::expect_same_files(run_files, study_files);
  EXPECT_EQ(json::parse(test::read_file(*dir_ + "/out/soft/results.json"))["max_displacement_mm"],
            variant("soft")["max_displacement_mm"]);
}

// scenario_file names the base scenario, so a variant's results.json says which study and which changes made
// it, and a report of the variant's folder says so too.
TEST_F(CubeStudy, AVariantsResultsAndReportNameTheStudyAndTheChanges) {
  const json soft = json::parse(test::read_file(*dir_ + "/out/soft/results.json"));
  EXPECT_EQ(soft["scenario_file"], *dir_ + "/base/cube.yaml");
  EXPECT_EQ(soft["study"],
            json::parse(R"({"name": "stiffness what-if", "file": ")" + *dir_ +
                        R"(/study.yaml", "variant": "soft", "set": {"materials.default.E_MPa": "5500"}})"));
  for (const auto& [name, says] :
       {std::pair<std::string, std::string>{"soft", "the scenario with materials.default.E_MPa: 5500"},
        {"reference", "the scenario as it is"}}) {
    const std::string html = *dir_ + "/" + name + ".html";
    const test::CommandResult r =
        test::run_hexbite({"-q", "report", *dir_ + "/out/" + name, "-o", html, "--no-pictures"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(test::read_file(html).find("variant " + name + " of study stiffness what-if (file " + *dir_ +
                                         "/study.yaml): " + says),
              std::string::npos)
        << name;
  }
}

// The report lists a variant's changes in the order they apply: it sorted them, and "supports.nut: {at:
// right}; supports.nut.at: left" read as a nut on the left for a run with it on the right (helper L).
TEST_F(CubeStudy, AReportListsAVariantsChangesInTheOrderTheyApply) {
  const std::string folder = *dir_ + "/ordered";
  fs::copy(*dir_ + "/out/soft", folder, fs::copy_options::recursive);
  nlohmann::ordered_json results = nlohmann::ordered_json::parse(test::read_file(folder + "/results.json"));
  results["study"]["set"] = nlohmann::ordered_json::object();
  results["study"]["set"]["materials.default.poisson"] = 0.3;
  results["study"]["set"]["materials.default.E_MPa"] = 5500;
  test::write_file(folder + "/results.json", results.dump(2));
  const std::string html = *dir_ + "/ordered.html";
  const test::CommandResult r = test::run_hexbite({"-q", "report", folder, "-o", html, "--no-pictures"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(test::read_file(html).find(
                "the scenario with materials.default.poisson: 0.3; materials.default.E_MPa: 5500"),
            std::string::npos);
}

// `--export inp` writes every variant's CalculiX deck, as `run --export inp` does; it was "not expected",
// and the way to get the decks (outputs.inp in every variant) was nowhere said (helper L).
TEST(Study, ExportInpWritesEveryVariantsDeck) {
  const std::string dir = study_folder(
      "name: decks\nbase: base/cube.yaml\nvariants:\n  - name: a\n  - name: b\n"
      "    set: {materials.default.E_MPa: 5500}\n");
  const test::CommandResult r =
      test::run_hexbite({"-q", "study", dir + "/study.yaml", "-o", dir + "/out", "--export", "inp"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* variant : {"a", "b"})
    for (const char* file : {"model.inp", "model_mesh.inp"})
      EXPECT_TRUE(fs::exists(dir + "/out/" + variant + "/" + file)) << variant << " " << file;
  EXPECT_NE(test::read_file(dir + "/out/b/model.inp").find("5500"), std::string::npos);
}

// Levels beyond the machine's memory were told to use "mpirun on several machines", which a study refuses.
TEST(Study, LevelsBeyondTheMemoryAdviseRunningTheVariantAlone) {
  const std::string dir = study_folder(
      "name: deep\nbase: base/cube.yaml\nvariants:\n  - name: q2\n    set: {mesh.target_hexes: 4000, "
      "mesh.validation_levels: 3, solver: {degree: 2}}\n");
  const test::CommandResult r = test::run_hexbite({"-q", "study", dir + "/study.yaml", "-o", dir + "/out"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(
      r.err.find("run this variant's scenario alone with mpirun hexbite run on several machines (a study "
                 "runs in one process)"),
      std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir + "/out"));
}

// A run that fails for a setting the study made was named at the base's `solver` line, with the study's
// note inside the parentheses of the value (helper L).
TEST(Study, ARunThatFailsForTheStudysSettingNamesTheStudysLine) {
  // On the shipped lateral bite: the cube of these tests converges in one iteration whatever the tolerance.
  const std::string dir =
      study_folder("name: cg\nbase: " + std::string(HEXBITE_SOURCE_DIR) +
                   "/scenarios/lateral_bite_hard_nut.yaml\nvariants:\n  - name: loose\n    "
                   "set:\n      solver.tolerance: 0.5\n      solver.linear_solver: cg_amg\n");
  const test::CommandResult r =
      test::run_hexbite({"-q", "study", dir + "/study.yaml", "-o", dir + "/out", "--levels", "0"});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find(dir + "/study.yaml:6:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("tighten solver.tolerance (0.5)"), std::string::npos) << r.err;
}

// A study that renames an item onto another's name was named at the base's line, where the item still had
// its old name (helper L).
TEST(Study, ARenameOntoAnotherNameIsNamedAtTheStudysLine) {
  std::string study = kStudy;
  study.replace(study.find("materials.default.E_MPa: 5500"), 29, "probes.b.name: a");
  const std::string dir = study_folder(study);
  std::string scenario = test::read_file(dir + "/base/cube.yaml");
  scenario += "probes:\n  - {name: a, at: [10, 10, 10]}\n  - {name: b, at: [12, 10, 10]}\n";
  test::write_file(dir + "/base/cube.yaml", scenario);
  // The study with its line 7 set to `set_line`: refused at that line with `message`.
  const auto expect_at_line_7 = [&](const std::string& set_line, const std::string& message) {
    study.replace(study.find("probes."), study.find('\n', study.find("probes.")) - study.find("probes."),
                  set_line);
    test::write_file(dir + "/study.yaml", study);
    const test::CommandResult r = test::run_hexbite({"-q", "study", dir + "/study.yaml", "-o", dir + "/out"});
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find(dir + "/study.yaml:7:"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
  };
  expect_at_line_7("probes.b.name: a", "probe 'a' is defined twice (first on line");
  // The renamed item first in the list: still the study's line (helper M).
  expect_at_line_7("probes.a.name: b", "probe 'b' is defined twice (first on line");
  // An empty probe name gets a probe's example, not a support's (helper M).
  expect_at_line_7("probes.a.name: \"\"", "probes[0].name is empty; write a name such as chin");
}

// Values a study set were named at the base's lines (helper M): a radius that selects no facet at the
// base's point, a `fixed` added to a base spring at the base's spring, a spring refused by --export inp at
// the base's support.
TEST(Study, SupportValuesTheStudySetAreNamedAtItsLines) {
  struct Case {
    std::string set, fragment;
    std::vector<std::string> extra;
    bool base_spring = false;  // the base gets a spring support 'elastic'
  };
  for (const Case& c : std::vector<Case>{
           {"supports.base.radius_mm: 0.5", "support 'base' selects no surface facets", {}},
           {"supports.elastic.fixed: [x, y, z]",
            "support 'elastic' has both 'fixed' and 'spring_N_per_mm3'",
            {},
            true},
           {"supports.base.spring_N_per_mm3: 40",
            "which the CalculiX export does not write",
            {"--export", "inp"}},
       }) {
    std::string study = kStudy;
    study.replace(study.find("materials.default.E_MPa: 5500"), 29, c.set);
    const std::string dir = study_folder(study);
    std::string base = test::read_file(dir + "/base/cube.yaml");
    if (c.base_spring)
      base.replace(base.find("materials:"), 0,
                   "  - {name: elastic, at: [20, 10, 10], radius_mm: 6, spring_N_per_mm3: 10}\n");
    test::write_file(dir + "/base/cube.yaml", base);
    std::vector<std::string> args = {"-q", "study", dir + "/study.yaml", "-o", dir + "/out"};
    args.insert(args.end(), c.extra.begin(), c.extra.end());
    const test::CommandResult r = test::run_hexbite(args);
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find(dir + "/study.yaml:7:"), std::string::npos) << c.set << "\n" << r.err;
    EXPECT_NE(r.err.find(c.fragment), std::string::npos) << r.err;
  }
}

// More values a study set were named at the base's lines (hunt R): a material region's sphere radius that
// holds no hex, a muscle's insertion radius that selects no facet, and a null that leaves no muscle.
TEST(Study, RadiiAndNullsTheStudySetAreNamedAtItsLines) {
  for (const auto& [set, fragment] : std::vector<std::pair<std::string, std::string>>{
           {"materials.regions.implant.sphere.radius_mm: 0.01", "material region 'implant' holds no hex"},
           {"muscles.pull.radius_mm: 0.5", "the insertion patch of muscle 'pull' selects no surface facets"},
           {"muscles: ~", "no muscle is active"},
       }) {
    std::string study = kStudy;
    study.replace(study.find("materials.default.E_MPa: 5500"), 29, set);
    const std::string dir = study_folder(study);
    std::string base = test::read_file(dir + "/base/cube.yaml");
    base +=
        "  regions:\n    - {name: implant, sphere: {center: [10.3, 10.7, 9.6], radius_mm: 6}, E_MPa: "
        "110000}\n";
    test::write_file(dir + "/base/cube.yaml", base);
    const test::CommandResult r = test::run_hexbite({"-q", "study", dir + "/study.yaml", "-o", dir + "/out"});
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find(dir + "/study.yaml:7:"), std::string::npos) << set << "\n" << r.err;
    EXPECT_NE(r.err.find(fragment), std::string::npos) << r.err;
  }
}

// The warning that the supports hold the bone weakly was named at the base's first support when the study
// had set the fixed components that made the hold weak.
TEST(Study, AWeakHoldTheStudyMadeIsNamedAtItsLine) {
  const std::string dir =
      study_folder("name: weak\nbase: " + std::string(HEXBITE_SOURCE_DIR) +
                   "/scenarios/lateral_bite_hard_nut.yaml\nvariants:\n  - name: weak\n    set:\n"
                   "      supports.nut.fixed: [z]\n      supports.right_condyle.fixed: [x, y]\n"
                   "      supports.left_condyle.fixed: [x, y]\n");
  const test::CommandResult r =
      test::run_hexbite({"study", dir + "/study.yaml", "-o", dir + "/out", "--levels", "0"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find(dir + "/study.yaml:6:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("the supports hold the bone only weakly"), std::string::npos) << r.err;
}

// A bad study exits with 2 before anything is written, naming the study file and `line`, and `message`.
void expect_refused(const std::string& study, int line, const std::string& message) {
  const std::string dir = study_folder(study);
  const test::CommandResult r = test::run_hexbite({"-q", "study", dir + "/study.yaml", "-o", dir + "/out"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find(dir + "/study.yaml:" + std::to_string(line) + ":"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/out")) << r.err;
}

// kStudy with its soft variant's set line replaced by `set_line`.
std::string soft_setting(const std::string& set_line) {
  std::string study = kStudy;
  study.replace(study.find("materials.default.E_MPa: 5500"), 29, set_line);
  return study;
}

// A contact released in a variant read as a measured 0.00 in study.md, study.csv and study.json, and a
// variant holding it showed no change against that 0. Now marked, with no relative change to or from it.
TEST(StudyTable, AReleasedContactIsMarkedNotAMeasuredZero) {
  StudyTable table;
  table.study = "contacts";
  for (const char* name : {"reference", "twosided"}) {
    StudyRow row;
    row.name = name;
    row.set = nlohmann::ordered_json::object();
    row.bite_force_N = 420.0;
    row.reactions = {{"molar", 420.0}, {"premolar", std::string(name) == "reference" ? 0.0 : 26.0}};
    if (std::string(name) == "reference") row.released = {"premolar"};
    table.rows.push_back(row);
  }
  const nlohmann::ordered_json study = study_json(table);
  EXPECT_EQ(study["variants"][0]["released"], nlohmann::ordered_json({"premolar"}));
  EXPECT_TRUE(study["variants"][1]["relative_to_reference"]["reactions"]["premolar"].is_null());
  EXPECT_EQ(study["variants"][1]["relative_to_reference"]["reactions"]["molar"], 0.0);
  const std::string md = study_markdown(study);
  EXPECT_NE(md.find("| 0 (released) |"), std::string::npos) << md;
  EXPECT_NE(md.find("| 26.00 (—) |"), std::string::npos) << md;  // no per cent against a released 0
  const std::string csv = study_csv(study);
  EXPECT_NE(csv.find(",released_contacts\n"), std::string::npos) << csv;
  EXPECT_NE(csv.find(",premolar\n"), std::string::npos) << csv;
}

// A line break in a value the study set (description: "a\nb") ended the study.md table row.
TEST(StudyTable, ALineBreakInAChangeStaysInItsRow) {
  nlohmann::ordered_json variant = {{"name", "a"},
                                    {"set", {{"description", "two\nlines"}}},
                                    {"level", 0},
                                    {"hexes", 8},
                                    {"bite_force_N", 1.0},
                                    {"max_displacement_mm", 1.0},
                                    {"von_mises_max_MPa", 1.0},
                                    {"von_mises_p99_MPa", 1.0},
                                    {"strain_energy_mJ", 1.0},
                                    {"reactions", nlohmann::ordered_json::object()},
                                    {"relative_to_reference", nlohmann::ordered_json::object()}};
  const nlohmann::ordered_json study = {{"variants", {variant}}};
  const std::string md = study_markdown(study);
  EXPECT_EQ(std::count(md.begin(), md.end(), '\n'), 3) << md;  // header, rule, one row
  EXPECT_NE(md.find("two lines"), std::string::npos) << md;
  // The CSV's set cell is on one line too (studies.md); it kept the break, quoted (helper L).
  StudyTable table;
  StudyRow row;
  row.name = "a";
  row.set = {{"description", "two\nlines\n"}};
  table.rows.push_back(row);
  const std::string csv = study_csv(study_json(table));
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 2) << csv;  // header, one row
  EXPECT_NE(csv.find(",description: two lines,"), std::string::npos) << csv;
}

// studies.md promises "—" for a relative change whose reference figure is missing or zero; study.md showed
// the variant's figure alone ("362.59"), as for the reference's own row.
TEST(StudyTable, AChangeWithoutAReferenceFigureIsADash) {
  StudyTable table;
  for (const char* name : {"reference", "variant"}) {
    StudyRow row;
    row.name = name;
    row.set = nlohmann::ordered_json::object();
    if (std::string(name) == "variant")
      row.bite_force_N = 362.59;  // the reference has outputs.bite_force off
    row.max_displacement_mm = 0.1;
    row.reactions = {{"nut", std::string(name) == "reference" ? 0.0 : 362.59}};  // a zero reference
    table.rows.push_back(row);
  }
  const std::string md = study_markdown(study_json(table));
  const std::vector<std::string> rows = split(md, '\n');
  ASSERT_EQ(rows.size(), 4u) << md;
  EXPECT_EQ(rows[2], "| reference | (none) | 0 | 0 | — | 0.10000 | 0.000 | 0.000 | 0.00000 | 0.00 |") << md;
  EXPECT_EQ(rows[3],
            "| variant | (none) | 0 | 0 | 362.59 (—) | 0.10000 (0.0 %) | 0.000 (—) | 0.000 (—) | 0.00000 (—) "
            "| 362.59 (—) |")
      << md;
}

// studies.md promises null for the reaction of a support that only some variants have (a support renamed by
// the study): study.json left the key out of the other variants' rows, while the CSV and study.md had its
// column, so a script reading it as documented failed with a KeyError.
TEST(StudyTable, ASupportOfOnlySomeVariantsIsNullInTheOthersRows) {
  StudyTable table;
  for (const std::string& name : {"reference", "renamed"}) {
    StudyRow row;
    row.name = name;
    row.set = nlohmann::ordered_json::object();
    row.reactions = {{name == "reference" ? "nut" : "bite", 361.5}, {"condyle", 220.0}};
    table.rows.push_back(row);
  }
  const nlohmann::ordered_json study = study_json(table);
  EXPECT_EQ(study["variants"][0]["reactions"],
            nlohmann::ordered_json({{"nut", 361.5}, {"condyle", 220.0}, {"bite", nullptr}}));
  EXPECT_EQ(study["variants"][1]["reactions"],
            nlohmann::ordered_json({{"nut", nullptr}, {"condyle", 220.0}, {"bite", 361.5}}));
  EXPECT_EQ(study["variants"][1]["relative_to_reference"]["reactions"],
            nlohmann::ordered_json({{"nut", nullptr}, {"condyle", 0.0}, {"bite", nullptr}}));
  EXPECT_EQ(study["variants"][0]["relative_to_reference"]["reactions"],
            nlohmann::ordered_json({{"nut", 0.0}, {"condyle", 0.0}, {"bite", nullptr}}));
}

// A control character of a value the study set (description: "a\tb\x1b[2Jc\x00d", which a scenario takes)
// went raw into study.csv, study.md and the table on the terminal: ESC[2J cleared the terminal, and a NUL
// made the tables binary files. A tab or a line separator is a space, as a line break is; the others are
// written as \xNN, as in messages. study.json keeps the value exactly.
TEST(StudyTable, AControlCharacterInAChangeIsWrittenVisibly) {
  StudyTable table;
  StudyRow row;
  row.name = "v";
  // With a NUL, and the C1 controls U+0085 (NEXT LINE, a line break) and U+009B (which a terminal takes as
  // ESC [), which were written raw (helper AA).
  const char description[] = "a\tb\x1b[2Jc\0d\x7f e\u2028f\u2029g\u0085h\u009b2J";
  row.set = {{"description", std::string(description, sizeof description - 1)}};
  table.rows.push_back(row);
  const nlohmann::ordered_json study = study_json(table);
  EXPECT_EQ(study["variants"][0]["set"], row.set);
  const std::string line = "description: a b\\x1b[2Jc\\x00d\\x7f e f g h\\u009b2J";
  EXPECT_EQ(study_changes(row.set, false), line);
  const std::string csv = study_csv(study);
  const std::string md = study_markdown(study);
  EXPECT_NE(csv.find("," + line + ","), std::string::npos) << csv;
  EXPECT_NE(md.find("| `" + line + "` |"), std::string::npos) << md;
  for (const std::string& text : {csv, md})
    EXPECT_TRUE(std::none_of(text.begin(), text.end(), [](char c) {
      return c != '\n' && (static_cast<unsigned char>(c) < 0x20 || c == 0x7f);
    })) << text;
  for (const std::string& text : {csv, md}) EXPECT_EQ(text.find("\xc2"), std::string::npos) << text;
}

// A backtick in a set value ended study.md's code span: the span is fenced by more backticks than it holds.
TEST(StudyTable, ABacktickInAChangeStaysInItsCodeSpan) {
  StudyTable table;
  for (const std::string& description : {std::string("uses `x` here"), std::string("``a``")}) {
    StudyRow row;
    row.name = "v";
    row.set = {{"description", description}};
    table.rows = {row};
    const std::string md = study_markdown(study_json(table));
    EXPECT_NE(md.find(description == "``a``" ? "| ``` description: ``a`` ``` |"
                                             : "| ``description: uses `x` here`` |"),
              std::string::npos)
        << md;
  }
}

TEST(Study, UnknownKeyOnThePathIsRefusedWithTheKeysThere) {
  expect_refused(
      soft_setting("materials.defualt.E_MPa: 5500"), 7,
      "variant 'soft': set 'materials.defualt.E_MPa': 'materials' has no key 'defualt' (a path may "
      "add only its last key); did you mean 'default'? (the keys there are 'default')");
}

TEST(Study, UnknownListItemIsRefusedWithTheNamesThere) {
  expect_refused(soft_setting("supports.bsae.at: [0, 10, 12]"), 7,
                 "'supports' has no item named 'bsae' (list items are addressed by their name); did you mean "
                 "'base'? (the names are 'base')");
}

TEST(Study, DuplicateVariantNameIsRefused) {
  std::string study = kStudy;
  study.replace(study.find("name: no_bite"), 13, "name: soft");
  expect_refused(study, 8, "variant 'soft' is defined twice (first on line 5)");
}

TEST(Study, InvalidOverriddenValueIsNamedAtTheStudysLine) {
  expect_refused(soft_setting("materials.default.E_MPa: -5"), 7,
                 "variant 'soft': materials.default.E_MPa is -5 MPa but Young's modulus must be positive");
}

// `mesh.core: ~` (a try to drop the base's core) was told "write a word such as left_condyle".
TEST(Study, AChoiceTheStudySetToNothingGetsTheValidChoices) {
  expect_refused(soft_setting("mesh.core: ~"), 7,
                 "variant 'soft': mesh.core must be text, found nothing; valid choices are 'grid', 'swept', "
                 "'auto'");
}

// An empty list the study set is named at the study's line (it was named at the base's `supports:` key).
TEST(Study, AnEmptyListTheStudySetIsNamedAtTheStudysLine) {
  expect_refused(soft_setting("supports: []"), 7, "the scenario has no supports");
  expect_refused(soft_setting("muscles: []"), 7, "no muscle is active");
}

// A contact that cannot push (fixed only along its patch's surface) is found when the variants are checked,
// before any solve: it was found when its variant was solved, after the variants before it.
TEST(Study, AContactThatCannotPushStopsTheStudyBeforeAnySolve) {
  const std::string dir =
      study_folder(kStudy +
                   "  - name: sliding\n    set:\n      supports:\n"
                   "        - {name: base, at: [0, 10, 10], radius_mm: 6, bite: true}\n"
                   "        - {name: slide, at: [10, 10, 0], radius_mm: 5, fixed: [x], contact: true}\n");
  const test::CommandResult r = test::run_hexbite({"study", dir + "/study.yaml", "-o", dir + "/out"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("contact support 'slide' fixes only components along its own surface"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("kept none of its files"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/out"));
}

// A point name is checked once the geometry exists, still before the first solve of any variant.
TEST(Study, UnknownPointOfTheLastVariantStopsTheStudyBeforeAnySolve) {
  std::string study = kStudy + "  - name: lost\n    set:\n      supports.base.at: nowhere\n";
  expect_refused(study, 14, "unknown point name 'nowhere'");
}

// A probe far outside the mesh was found only when its variant was solved, after the variants before it.
TEST(Study, AProbeFarOutsideTheMeshStopsTheStudyBeforeAnySolve) {
  const std::string dir =
      study_folder(kStudy + "  - name: lost\n    set:\n      probes: [{name: far, at: [0, 0, -200]}]\n");
  const test::CommandResult r = test::run_hexbite({"study", dir + "/study.yaml", "-o", dir + "/out"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find(dir + "/study.yaml:14:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("probe 'far' at (0.00, 0.00, -200.00) lies"), std::string::npos) << r.err;
  // Found while the variants are checked, before the output stage exists; after solves, the message would
  // go on to say that the study kept none of its files.
  EXPECT_EQ(r.err.find("kept none of its files"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/out"));
}

// A point the study set is named at its line in the study file: the patch that selects no facet was
// named at the support's line in the base scenario, which still reads as it should.
TEST(Study, APointTheStudySetIsNamedAtTheStudysLine) {
  expect_refused(soft_setting("supports.base.at: [0, 10, -300]"), 7, "support 'base'");
}

// A scenario given to `study`, and a study given to `run`: said "unknown key 'format_version' in the study"
// and "unknown key 'base' in the scenario; did you mean 'name'?".
TEST(Study, AScenarioAndAStudyGivenToTheOtherCommandAreNamed) {
  const std::string dir = study_folder(kStudy);
  auto r = test::run_hexbite({"study", dir + "/base/cube.yaml", "-o", dir + "/out"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("cube.yaml:1:1: this is a scenario file (it has no 'base' and no 'variants'), not a "
                       "study: run it with `hexbite run "),
            std::string::npos)
      << r.err;
  r = test::run_hexbite({"run", dir + "/study.yaml", "-o", dir + "/out"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("study.yaml:1:1: this is a study file (it has 'base' and 'variants'), not a scenario: "
                       "run it with `hexbite study "),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir + "/out"));
}

TEST(Study, UnknownKeyAndUnsafeVariantNameAreRefused) {
  expect_refused(kStudy + "varients: []\n", 12,
                 "unknown key 'varients' in the study; did you mean 'variants'?");
  std::string study = kStudy;
  study.replace(study.find("name: no_bite"), 13, "name: ../up");
  expect_refused(study, 8, "variant name '../up' is not a safe folder name");
  // An empty name was "must be text, found the quoted text \"\"; write a word such as left_condyle".
  study = kStudy;
  study.replace(study.find("name: no_bite"), 13, "name: \"\"");
  expect_refused(study, 8, "variants[2].name is empty; write a name such as soft_bone");
}

// Values the study set are named at the study's line and resolve paths from its folder; the rest of the
// variant is the base scenario's, named at its lines and resolving from its folder.
TEST(Study, PlacesAndRelativePathsFollowTheFileTheyWereWrittenIn) {
  std::string text = kStudy;
  text.replace(text.find("materials.default.E_MPa: 5500"), 29, "geometry.surface: {file: other.obj}");
  const std::string dir = study_folder(text);
  test::write_file(dir + "/other.obj", test::cubes_obj(1));
  const Study study = load_study(dir + "/study.yaml");
  ASSERT_EQ(study.variants.size(), 3u);
  EXPECT_EQ(study.base, dir + "/base/cube.yaml");
  EXPECT_EQ(study.variants[0].scenario.geometry.file, dir + "/base/cube.obj");
  EXPECT_EQ(study.variants[1].scenario.geometry.file, dir + "/other.obj");
  EXPECT_EQ(study.variants[0].scenario.supports[0].where.str(), dir +
                                                                    "/base/cube.yaml:8:5: variant "
                                                                    "'reference' of study " +
                                                                    dir + "/study.yaml");
  EXPECT_EQ(study.variants[2].scenario.supports[0].where.file, dir + "/base/cube.yaml");

  // Degree 1 with the base's Poisson ratio of 0.49: refused at the base's line of poisson (untouched),
  // naming the variant whose change made it wrong.
  std::string base = kBase;
  base.replace(base.find("poisson: 0.28}"), 14, "poisson: 0.49}\nsolver: {degree: 2}");
  test::write_file(dir + "/base/cube.yaml", base);
  text.replace(text.find("geometry.surface: {file: other.obj}"), 35, "solver.degree: 1");
  test::write_file(dir + "/study.yaml", text);
  const std::string error = test::message_of<InputError>([&] { load_study(dir + "/study.yaml"); });
  EXPECT_NE(error.find(dir + "/base/cube.yaml:10:"), std::string::npos) << error;
  EXPECT_NE(error.find("variant 'soft' of study " + dir + "/study.yaml: poisson 0.49 with solver.degree 1"),
            std::string::npos)
      << error;
}

// A whole number the study set is decimal in the variant: it meshed 1,024 hexes for `target_hexes: 02000`
// (octal). The tables record the change as written.
TEST(Study, WholeNumbersTheStudySetAreDecimal) {
  std::string text = kStudy;
  text.replace(text.find("materials.default.E_MPa: 5500"), 29, "mesh.target_hexes: 02000");
  const Study study = load_study(study_folder(text) + "/study.yaml");
  ASSERT_EQ(study.variants.size(), 3u);
  EXPECT_EQ(study.variants[1].scenario.mesh.target_hexes, 2000);
  EXPECT_EQ(study.variants[1].set.at("mesh.target_hexes"), "02000");
}

// The record of a variant's changes retyped its values as YAML reads plain scalars: `name: 007` (the text
// 007 in the run) was recorded as 7, `fixed: [x, y, z]` as ["x", true, "z"], `description: no` as false.
// Every scalar is now its text as written; study.md writes lists and mappings as the study does.
TEST(Study, TheChangesAreRecordedAsWritten) {
  std::string text = kStudy;
  text.replace(text.find("materials.default.E_MPa: 5500"), 29,
               "name: 007\n      supports.base.fixed: [x, y, z]\n      description: no\n"
               "      materials.default: {E_MPa: 5500}");
  const std::string dir = study_folder(text);
  const Study study = load_study(dir + "/study.yaml");
  EXPECT_EQ(study.variants[1].scenario.name, "007");
  EXPECT_EQ(study.variants[1].scenario.description, "no");
  const json expected = json::parse(R"({"name": "007", "supports.base.fixed": ["x", "y", "z"],
      "description": "no", "materials.default": {"E_MPa": "5500"}})");
  EXPECT_EQ(json(study.variants[1].set), expected);
  const test::CommandResult r = test::run_hexbite({"-q", "study", dir + "/study.yaml", "-o", dir + "/out"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(json::parse(test::read_file(dir + "/out/study.json"))["variants"][1]["set"], expected);
  EXPECT_EQ(json::parse(test::read_file(dir + "/out/soft/results.json"))["study"]["set"], expected);
  const std::string changes =
      "name: 007; supports.base.fixed: [x, y, z]; description: no; materials.default: {E_MPa: 5500}";
  EXPECT_NE(test::read_file(dir + "/out/study.md").find("| soft | `" + changes + "` |"), std::string::npos)
      << test::read_file(dir + "/out/study.md");
  EXPECT_NE(test::read_file(dir + "/out/study.csv").find("soft,\"" + changes + "\","), std::string::npos)
      << test::read_file(dir + "/out/study.csv");
  const test::CommandResult report =
      test::run_hexbite({"-q", "report", dir + "/out/soft", "-o", dir + "/soft.html", "--no-pictures"});
  ASSERT_EQ(report.exit_code, 0) << report.err;
  EXPECT_NE(test::read_file(dir + "/soft.html").find("the scenario with " + changes), std::string::npos);
}

// A study of the reference variant alone, run into DIR/out: the earlier study that a test then runs over.
struct EarlierStudy {
  std::string dir, out;
  std::map<std::string, std::string> files;  // files_under(out) after it
};
EarlierStudy reference_study_in_out() {
  std::string first = kStudy;
  first.erase(first.find("  - name: soft"));
  EarlierStudy earlier;
  earlier.dir = study_folder(first);
  earlier.out = earlier.dir + "/out";
  const test::CommandResult r =
      test::run_hexbite({"-q", "study", earlier.dir + "/study.yaml", "-o", earlier.out});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  earlier.files = test::files_under(earlier.out);
  return earlier;
}

// All or nothing: a variant whose displacements are absurd (a modulus in the wrong unit) fails the study
// after the others solved, and the folder keeps the earlier study's files byte for byte.
TEST(Study, AFailedVariantLeavesTheOutputFolderAsItWas) {
  const auto [dir, out, before] = reference_study_in_out();
  ASSERT_TRUE(before.count("reference/results.json"));
  ASSERT_TRUE(before.count("study.json"));

  test::write_file(dir + "/study.yaml", soft_setting("materials.default.E_MPa: 1.0e-6"));
  test::CommandResult r = test::run_hexbite({"-q", "study", dir + "/study.yaml", "-o", out});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("small displacements; the results of variant 'soft' are meaningless"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("the study kept none of its files and left '" + out + "' as it was"),
            std::string::npos)
      << r.err;
  test::expect_same_files(before, test::files_under(out));

  // Into a new folder: not created.
  r = test::run_hexbite({"-q", "study", dir + "/study.yaml", "-o", dir + "/new/out"});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/new")) << r.err;
}

// A variant that cannot be written (a file size limit) said "the run kept none of its files and did not
// create 'out/reference'" of a folder that an earlier study had made, and that stayed; the study's own
// clause says what became of the output folder.
TEST(Study, AVariantThatCannotBeWrittenSaysOnlyWhatTheStudyDid) {
  const auto [dir, out, before] = reference_study_in_out();
  ASSERT_FALSE(before.empty());
  const test::CommandResult r =
      test::run_hexbite({"-q", "study", dir + "/study.yaml", "-o", out},
                        {"bash", "-c", "trap '' XFSZ; ulimit -f 20; exec \"$@\"", "bash"});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(r.err.find("the run kept none of its files"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("did not create"), std::string::npos) << r.err;
  EXPECT_NE(
      r.err.find("/out/reference/mesh.vtu': the disk is full or the file passed a size limit (ulimit -f): "
                 "make room on the disk or choose another output folder; the study kept none of its files "
                 "and left '" +
                 out + "' as it was"),
      std::string::npos)
      << r.err;
  test::expect_same_files(before, test::files_under(out));
}

// A variant whose folder would replace a file in DIR (a variant named notes.txt beside your notes, or named
// after the base scenario studied into its own folder) was found only when the study was moved into DIR,
// after every variant had solved (exit 1). It is refused at the variant's line before anything is checked
// further, and the file stays.
TEST(Study, AFileWhereAVariantsFolderGoesIsRefusedAtTheVariantsLine) {
  for (const std::string& name : {"notes.txt", "cube.yaml"}) {
    std::string study = kStudy;
    study.replace(study.find("name: no_bite"), 13, "name: " + name);
    const std::string dir = study_folder(study);
    const std::string out = name == "cube.yaml" ? dir + "/base" : dir + "/out";
    if (name == "notes.txt") {
      fs::create_directories(out);
      test::write_file(out + "/notes.txt", "hi\n");
    }
    const auto before = test::files_under(out);
    const test::CommandResult r = test::run_hexbite({"study", dir + "/study.yaml", "-o", out});
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_EQ(r.err,
              "hexbite: error: " + dir + "/study.yaml:8:5: variant '" + name + "': its run folder '" + out +
                  "/" + name +
                  "' is a file, not a folder; rename the variant (its name names the folder), remove or "
                  "rename the file, or choose another output folder\n");
    EXPECT_EQ(r.out.find("variant 1"), std::string::npos) << r.out;
    test::expect_same_files(before, test::files_under(out));
  }
}

// A symbolic link where a variant's folder goes (a variant's folder linked to another disk) was called "a
// file, not a folder" and the user was told to remove "the file": the message says it is a link, and where it
// points or that its target does not exist.
TEST(Study, ALinkWhereAVariantsFolderGoesIsNamedALink) {
  std::string study = kStudy;
  study.resize(study.find("  - name: soft"));
  for (const std::string& target : {std::string("../elsewhere"), std::string("../nowhere")}) {
    const std::string dir = study_folder(study);
    fs::create_directories(dir + "/out");
    fs::create_directories(dir + "/elsewhere");
    fs::create_directory_symlink(target, dir + "/out/reference");
    const test::CommandResult r = test::run_hexbite({"study", dir + "/study.yaml", "-o", dir + "/out"});
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_EQ(r.err, "hexbite: error: " + dir + "/study.yaml:4:5: variant 'reference': its run folder '" +
                         dir + "/out/reference' is a symbolic link to '" + target + "'" +
                         (target == "../nowhere" ? ", which does not exist or loops" : "") +
                         ", not a folder; a variant's run folder must be a real folder: rename the variant "
                         "(its name names the folder), remove or rename the link, or choose another output "
                         "folder\n");
    EXPECT_TRUE(fs::is_symlink(dir + "/out/reference"));
    EXPECT_TRUE(fs::is_empty(dir + "/elsewhere"));
  }
}

// Into a file or a pipe, the lines that announce the variants waited in the buffer until something else
// flushed it (the first solve) or the study ended, and a kill (a batch system's time limit) lost them. The
// study is stopped as soon as its first line is in the file: while the variants are checked, not after.
TEST(Study, TheVariantsAreAnnouncedAtOnceIntoAFile) {
  const std::string dir = study_folder(kStudy);
  const test::CommandResult r =
      test::run_hexbite({"study", dir + "/study.yaml", "-o", dir + "/out", "--levels", "2"},
                        {"bash", "-c",
                         "\"$@\" & for i in $(seq 600); do [ -s /dev/stdout ] && break; sleep 0.1; done; "
                         "kill -TERM $!; wait $!",
                         "bash"});
  EXPECT_EQ(r.exit_code, 128 + SIGTERM) << "the study ended before its first line was in the file\n" << r.out;
  EXPECT_EQ(r.out.rfind("check variant 1 / 3: reference\n", 0), 0u) << r.out;
  EXPECT_EQ(r.out.find("\nvariant 1 / 3: reference"), std::string::npos) << "in the file only once solving:\n"
                                                                         << r.out;
}

// SIGTERM and SIGHUP while a study solved (its hidden stage in the output folder, for minutes) left the
// folder it created with the empty stage in it: MPI's start-up (PETSc) had reset their handlers, so the
// process died without cleaning up. Ctrl-C (SIGINT) did clean up.
TEST(Study, SigtermOrSighupWhileSolvingRemovesTheStageAndTheFolderItCreated) {
  for (const char* signal_name : {"TERM", "HUP"}) {
    const std::string dir = study_folder(kStudy), out = dir + "/out";
    const test::CommandResult r = test::run_hexbite(
        {"study", dir + "/study.yaml", "-o", out, "--levels", "2"},
        {"bash", "-c",
         std::string("\"$@\" & for i in $(seq 600); do compgen -G '") + out +
             "/.hexbite-stage-*' >/dev/null && break; sleep 0.1; done; kill -" + signal_name + " $!; wait $!",
         "bash"});
    EXPECT_EQ(r.exit_code, 128 + (std::string(signal_name) == "TERM" ? SIGTERM : SIGHUP)) << r.err;
    EXPECT_FALSE(fs::exists(out)) << signal_name << ": left " << out;
  }
}

// A variant that asked for the direct solver where the address space left (ulimit -v) cannot hold it was
// refused only at its solve, after the variants before it had solved, and named at the base's `solver` line
// (helper AA). It is refused with the memory check of the validation levels, at the study's line.
TEST(Study, ADirectSolverTheMemoryCannotHoldIsRefusedBeforeAnySolveAtTheStudysLine) {
  std::string study = kStudy;
  study.replace(study.find("      materials.default.E_MPa: 5500"), 35,
                "      solver: {linear_solver: direct}");
  const std::string dir = study_folder(study);
  const test::CommandResult r = test::run_hexbite({"study", dir + "/study.yaml", "-o", dir + "/out"},
                                                  {"prlimit", "--as=1200000000", "--"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find(dir + "/study.yaml:7:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("variant 'soft'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("solver.linear_solver direct, level 0 ("), std::string::npos) << r.err;
  EXPECT_EQ(r.out.find("\nvariant 1 / 3: reference"), std::string::npos) << "solved before the refusal:\n"
                                                                         << r.out;
  EXPECT_FALSE(fs::exists(dir + "/out"));
}

// A missing, empty or non-text base was told "write a word such as left_condyle", the hint for point names.
TEST(Study, ABaseThatIsNoPathAsksForTheBaseScenariosFile) {
  for (const char* base : {"base: \"\"", "base:", "base: [a]"}) {
    std::string study = kStudy;
    study.replace(study.find("base: base/cube.yaml"), 20, base);
    expect_refused(study, 2, "give the base scenario's file path, e.g. base: ../lateral_bite_hard_nut.yaml");
  }
}

// A study file named study.json (a JSON study is valid YAML), studied into its own folder, was replaced by
// the study's results with exit 0; so was a base named results.json inside a variant's folder. An input that
// an output would replace is refused before any work, and stays as it was.
TEST(Study, AnInputThatAnOutputWouldReplaceIsRefused) {
  for (const auto& [study_name, base] : std::vector<std::pair<std::string, std::string>>{
           {"study.json", "base/cube.yaml"}, {"study.yaml", "reference/results.json"}}) {
    const std::string dir = study_folder(kStudy);
    std::string study = kStudy;
    study.replace(study.find("base/cube.yaml"), 14, base);
    if (base != "base/cube.yaml") {
      fs::create_directories(dir + "/reference");
      test::write_file(dir + "/" + base, test::read_file(dir + "/base/cube.yaml"));
      test::write_file(dir + "/reference/cube.obj", test::cubes_obj(1));
    }
    test::write_file(dir + "/" + study_name, study);
    const test::CommandResult r = test::run_hexbite({"-q", "study", dir + "/" + study_name, "-o", dir});
    EXPECT_EQ(r.exit_code, 2) << r.err;
    const std::string replaced = study_name == "study.json" ? study_name : base;
    EXPECT_NE(r.err.find("it writes its own '" + replaced + "' into '" + dir + "'"), std::string::npos)
        << r.err;
    EXPECT_EQ(test::read_file(dir + "/" + study_name), study);
    EXPECT_FALSE(fs::exists(dir + "/soft"));
  }
}

}  // namespace
}  // namespace hexbite
