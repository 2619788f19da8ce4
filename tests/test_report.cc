// `hexbite report`: the HTML report of a finished run holds results.json's figures as documented
// (docs/reports.md), escapes the scenario's strings, embeds its pictures as PNG data, warns about weak
// supports, and refuses bad input with exit 2 before writing anything.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tests/test_util.h"

namespace hexbite {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::read_file;
using test::run_hexbite;
using test::temp_dir;
using test::write_file;

// A 20 mm cube pulled along x against a clamped face, meshed with a few hundred hexes and refined once.
// The name has HTML's special characters.
const std::string kCube = R"(name: "cube <b>& bite"
geometry:
  surface: {file: cube.obj}
mesh: {target_hexes: 300, validation_levels: 1}
muscles:
  - {name: pull, activation: 1, insertion: [20, 10, 10], radius_mm: 5, direction: [1, 0, 0], max_force_N: 100}
supports:
  - {name: nut, at: [0, 10, 10], radius_mm: 5, bite: true}
  - {name: floor_rest, at: [10, 10, 0], radius_mm: 4}
probes:
  - {name: far_corner, at: [20, 20, 20]}
)";

// Rendering needs an X display: the caller's, or a virtual one (scripts/test.sh provides one already).
std::vector<std::string> display_launcher() {
  return std::getenv("DISPLAY") != nullptr ? std::vector<std::string>{}
                                           : std::vector<std::string>{"xvfb-run", "-a"};
}

// `scenario` (text) with the cube next to it, run into DIR/run; returns DIR/run.
std::string run_cube(const std::string& scenario, const std::vector<std::string>& extra = {}) {
  const std::string dir = temp_dir();
  write_file(dir + "/cube.obj", test::cubes_obj(1));
  write_file(dir + "/cube.yaml", scenario);
  std::vector<std::string> args = {"-q", "run", dir + "/cube.yaml", "-o", dir + "/run"};
  args.insert(args.end(), extra.begin(), extra.end());
  const test::CommandResult r = run_hexbite(args);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return dir + "/run";
}

// kCube without its validation level and with everything from its supports on cut off, for a test to
// append its own supports (and materials).
std::string cube_without_levels_and_supports() {
  std::string text = kCube;
  text.replace(text.find("validation_levels: 1"), 20, "validation_levels: 0");
  return text.substr(0, text.find("supports:"));
}

// The part of `html` from the heading that starts with `heading` to the next heading.
std::string section(const std::string& html, const std::string& heading) {
  const std::size_t from = html.find("<h2>" + heading);
  if (from == std::string::npos) return "";
  return html.substr(from, html.find("<h2>", from + 4) - from);
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

std::string printf_number(const char* format, double v) {
  char text[64];
  std::snprintf(text, sizeof text, format, v);
  return text;
}

std::string base64_decode(const std::string& text) {
  static const std::string kDigits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  unsigned long group = 0;
  int bits = 0;
  for (char c : text) {
    const std::size_t d = kDigits.find(c);
    if (d == std::string::npos) break;  // '=' padding
    group = (group << 6) | d;
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out += static_cast<char>((group >> bits) & 0xff);
    }
  }
  return out;
}

// Nothing a printed or mailed report would have to fetch or run.
void expect_self_contained(const std::string& html) {
  for (const char* external : {"http://", "https://", "src=\"file", "<script", "<link"})
    EXPECT_EQ(html.find(external), std::string::npos) << external;
}

class Report : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    run_dir_ = new std::string(run_cube(kCube));
    results_ = new json(json::parse(read_file(*run_dir_ + "/results.json")));
  }
  static std::string* run_dir_;
  static json* results_;
};
std::string* Report::run_dir_ = nullptr;
json* Report::results_ = nullptr;

TEST_F(Report, HoldsTheFiguresOfResultsJsonFormattedAsDocumented) {
  const json& r = *results_;
  const std::string out = temp_dir() + "/report.html";
  const test::CommandResult c = run_hexbite({"report", *run_dir_, "-o", out, "--no-pictures"});
  ASSERT_EQ(c.exit_code, 0) << c.err;
  const std::string html = read_file(out);
  expect_self_contained(html);

  // The bite force with 1 decimal in its cell; the same cell with a number 0.1 N off is not there, so the
  // check tells a wrong figure from the right one.
  const double bite = r["bite_force_N"].get<double>();
  const std::string results = section(html, "Results");
  EXPECT_NE(results.find(">" + printf_number("%.1f", bite) + "<"), std::string::npos) << results;
  EXPECT_EQ(results.find(">" + printf_number("%.1f", bite + 0.1) + "<"), std::string::npos) << results;
  for (const auto& [name, reaction] : r["reactions"].items()) {
    EXPECT_NE(results.find("<td>" + name + "</td>"), std::string::npos) << name;
    EXPECT_NE(results.find(">" + printf_number("%.1f", reaction["magnitude_N"].get<double>()) + "<"),
              std::string::npos)
        << name;
  }

  // One row per level (and the header), with each level's bite force.
  const std::string validation = section(html, "Validation");
  const json& levels = r["validation"]["levels"];
  ASSERT_EQ(levels.size(), 2u);
  EXPECT_EQ(count(validation, "<tr>"), levels.size() + 1) << validation;
  for (const json& l : levels)
    EXPECT_NE(validation.find(">" + printf_number("%.1f", l["bite_force_N"].get<double>()) + "<"),
              std::string::npos)
        << validation;
  // The relative change between the two levels in percent with 2 decimals, as results.json has it.
  const double change = r["validation"]["relative_change"]["bite_force"].get<double>();
  EXPECT_NE(
      validation.find(">" + std::string(change > 0 ? "+" : "") + printf_number("%.2f", 100 * change) + " %<"),
      std::string::npos)
      << validation;

  // The quality table's minima (scaled Jacobian 3 decimals, condition number and Oddy 2).
  const std::string quality = section(html, "Mesh quality");
  const json& q = r["mesh"]["quality"];
  EXPECT_NE(quality.find(">" + printf_number("%.3f", q["scaled_jacobian"]["min"].get<double>()) + "<"),
            std::string::npos)
      << quality;
  EXPECT_EQ(
      quality.find(">" + printf_number("%.3f", q["scaled_jacobian"]["min"].get<double>() + 0.001) + "<"),
      std::string::npos);
  EXPECT_NE(quality.find(">" + printf_number("%.2f", q["condition"]["min"].get<double>()) + "<"),
            std::string::npos)
      << quality;
  EXPECT_NE(quality.find(">" + printf_number("%.2f", q["oddy"]["min"].get<double>()) + "<"),
            std::string::npos)
      << quality;
  const std::string probes = section(html, "Probes");
  EXPECT_NE(probes.find("<td>far_corner</td>"), std::string::npos);
  // The note follows the table: it was written inside it (before </table>), invalid HTML that browsers
  // show above the table.
  const std::size_t note = probes.find("<p class=\"note\">A probe outside the mesh");
  ASSERT_NE(note, std::string::npos) << probes;
  EXPECT_EQ(probes.rfind("</table>", note), note - 9) << probes;
  EXPECT_NE(section(html, "Pictures").find("no pictures"), std::string::npos);

  // The scenario's name escaped, in the title and the heading; never as markup.
  EXPECT_NE(html.find("<h1>cube &lt;b&gt;&amp; bite</h1>"), std::string::npos);
  EXPECT_EQ(html.find("<b>&"), std::string::npos);
}

// Patch areas and lengths with 3 significant digits, rounded before the form is chosen (reports.md, "How
// figures are written"): a patch of 0.4 mm2 read "0" and one of 1.19 mm2 "1" (rounded to whole mm2), a
// displacement of 12345.6 mm "12346", a strain energy of 10696.98 mJ "10697" and one of 999,999.7 mJ
// "1000000".
TEST_F(Report, AreasAndLargeFiguresHaveThreeSignificantDigits) {
  const std::string dir = temp_dir();
  json j = *results_;
  j["supports"][0]["patch_area_mm2"] = 0.4;
  j["muscles"][0]["patch_area_mm2"] = 1.1946187523303051;
  for (json* level : {&j, &j["validation"]["levels"][0]}) {  // the coarse level, as the run writes it twice
    (*level)["max_displacement_mm"] = 12345.6;
    (*level)["strain_energy_mJ"] = 999999.7;
  }
  j["validation"]["levels"][1]["strain_energy_mJ"] = 10696.979;
  write_file(dir + "/results.json", j.dump(1));
  const test::CommandResult c = run_hexbite({"-q", "report", dir, "-o", dir + "/r.html", "--no-pictures"});
  ASSERT_EQ(c.exit_code, 0) << c.err;
  const std::string html = read_file(dir + "/r.html");
  const std::string model = section(html, "Model");
  EXPECT_NE(model.find("<td>pull</td>"), std::string::npos) << model;
  EXPECT_NE(model.find("<td class=\"n\">1.19</td></tr>"), std::string::npos) << model;
  EXPECT_NE(model.find("<td>nut</td>"), std::string::npos) << model;
  EXPECT_NE(model.find("<td class=\"n\">0.400</td></tr>"), std::string::npos) << model;
  const std::string results = section(html, "Results");
  EXPECT_NE(results.find("<td class=\"n\">12300</td>"), std::string::npos) << results;
  EXPECT_NE(results.find("<td class=\"n\">1.00e+06</td>"), std::string::npos) << results;
  const std::string validation = section(html, "Validation");
  EXPECT_NE(validation.find("<td class=\"n\">10700</td>"), std::string::npos) << validation;
  EXPECT_EQ(html.find("1000000"), std::string::npos);
  EXPECT_EQ(html.find("12346"), std::string::npos);
}

TEST_F(Report, EmbedsThePicturesAsPngAndLeavesNoTemporaryFiles) {
  const std::string dir = temp_dir(), tmp = dir + "/tmp";
  fs::create_directories(tmp);
  // The pictures are rendered into a temporary folder under TMPDIR (after xvfb-run, which has its own).
  std::vector<std::string> launcher = display_launcher();
  launcher.insert(launcher.end(), {"env", "TMPDIR=" + tmp});
  const test::CommandResult c = run_hexbite(
      {"report", *run_dir_, "-o", dir + "/r.htm", "--title", "Cube & <i>nut</i>", "--json"}, launcher);
  ASSERT_EQ(c.exit_code, 0) << c.err;
  const json summary = json::parse(c.out);
  EXPECT_EQ(summary["report"], dir + "/r.htm");
  EXPECT_EQ(summary["pictures"].size(), 3u) << summary.dump();
  EXPECT_TRUE(summary["warnings"].is_array());

  const std::string html = read_file(dir + "/r.htm");
  expect_self_contained(html);
  EXPECT_NE(html.find("<h1>Cube &amp; &lt;i&gt;nut&lt;/i&gt;</h1>"), std::string::npos);
  // (std::regex would recurse once per character of a picture's 300 kB and overflow the stack.)
  const std::string prefix = "src=\"data:image/png;base64,";
  int pictures = 0;
  for (std::size_t at = html.find(prefix); at != std::string::npos; at = html.find(prefix, at + 1)) {
    const std::size_t from = at + prefix.size();
    const std::string png = base64_decode(html.substr(from, html.find('"', from) - from));
    EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
    EXPECT_GT(png.size(), 1000u);
    ++pictures;
  }
  EXPECT_EQ(pictures, 3);
  // Each caption gives its field's maximum, as the results table does.
  const std::string captions = section(html, "Pictures");
  EXPECT_NE(captions.find("the maximum is " +
                          printf_number("%.2f", (*results_)["von_mises_max_MPa"].get<double>()) + " MPa"),
            std::string::npos)
      << captions;
  EXPECT_TRUE(fs::is_empty(tmp)) << "the pictures' temporary folder was left behind";

  // TMPDIR naming a file gave the library's own text ("filesystem error: temp_directory_path: Not a
  // directory"); now it is named, with what to do (helper K). Bad input (exit 2) as for run and study, not
  // a failed run (exit 1), and so is a TMPDIR where no folder can be made.
  launcher = display_launcher();
  launcher.insert(launcher.end(), {"env", "TMPDIR=" + dir + "/r.htm"});
  test::CommandResult bad = run_hexbite({"report", *run_dir_, "-o", dir + "/bad.html"}, launcher);
  EXPECT_EQ(bad.exit_code, 2) << bad.err;
  EXPECT_NE(
      bad.err.find("hexbite: error: cannot make a temporary folder for the report's pictures: TMPDIR is '" +
                   dir +
                   "/r.htm' (Not a directory); point TMPDIR at a folder you can write to, or give "
                   "--no-pictures"),
      std::string::npos)
      << bad.err;
  launcher = display_launcher();
  launcher.insert(launcher.end(), {"env", "TMPDIR=/proc"});
  bad = run_hexbite({"report", *run_dir_, "-o", dir + "/bad.html"}, launcher);
  EXPECT_EQ(bad.exit_code, 2) << bad.err;
  EXPECT_NE(
      bad.err.find("hexbite: error: cannot make a temporary folder for the report's pictures in '/proc'"),
      std::string::npos)
      << bad.err;
  EXPECT_FALSE(fs::exists(dir + "/bad.html"));
}

// A display that answers but has no OpenGL (an X server without GLX, as many ssh -X and VNC servers are):
// VTK aborted (exit 134) and left the pictures' temporary folder behind. So did one with GLX where no context
// can be made (indirect GLX, LIBGL_ALWAYS_INDIRECT=1, which X servers refuse).
TEST_F(Report, ADisplayWithoutOpenGlIsRefusedAndLeavesNothing) {
  struct Case {
    std::vector<std::string> options;
    std::string environment, fragment;
  };
  for (const Case& c :
       {Case{{"-extension", "GLX"}, "", "has no OpenGL: its X server lacks the GLX extension"},
        Case{{}, "LIBGL_ALWAYS_INDIRECT=1", "has no usable OpenGL: no OpenGL context"}}) {
    const test::VirtualDisplay x(c.options);
    if (x.display().empty()) GTEST_SKIP() << "no X server for this test: " << x.problem();
    const std::string dir = temp_dir(), tmp = dir + "/tmp";
    fs::create_directories(tmp);
    std::vector<std::string> launcher = {"env", "DISPLAY=" + x.display(), "TMPDIR=" + tmp};
    if (!c.environment.empty()) launcher.push_back(c.environment);
    const test::CommandResult r = run_hexbite({"-q", "report", *run_dir_, "-o", dir + "/r.html"}, launcher);
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_NE(r.err.find("cannot draw the report's pictures: no X display (the X display '" + x.display() +
                         "' " + c.fragment),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("run the command under `xvfb-run -a`, or add --no-pictures"), std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(dir + "/r.html"));
    EXPECT_TRUE(fs::is_empty(tmp)) << "the pictures' temporary folder was left behind";
  }
}

// A TMPDIR that filled up while the pictures were drawn there was blamed on the report's folder ("make room
// on the disk or choose another output folder"). A file size limit fails the pictures' writes as a full disk
// does.
TEST_F(Report, AFullTmpdirIsNamedWithTheWayAroundIt) {
  const std::string dir = temp_dir(), tmp = dir + "/tmp";
  fs::create_directories(tmp);
  std::vector<std::string> launcher = display_launcher();
  launcher.insert(launcher.end(),
                  {"env", "TMPDIR=" + tmp, "bash", "-c", "trap '' XFSZ; ulimit -f 20; exec \"$@\"", "bash"});
  const test::CommandResult r = run_hexbite({"-q", "report", *run_dir_, "-o", dir + "/r.html"}, launcher);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(r.err,
            "hexbite: failed: cannot draw the report's pictures in TMPDIR '" + tmp +
                "': the disk is full or the file passed a size limit (ulimit -f); make room there, point "
                "TMPDIR at another folder, or give --no-pictures\n");
  EXPECT_FALSE(fs::exists(dir + "/r.html"));
  EXPECT_TRUE(fs::is_empty(tmp)) << "the pictures' temporary folder was left behind";
}

// Supports that leave a rotation to the extent of their patches (as in tests/test_run.cc, on the cube): a
// bite patch on the top face fixed in z and a "condyle" patch on it fixed in x and y let the cube turn
// about the axis along y through the bite. The report says so first.
TEST(ReportWarnings, WeakSupportsAreWarnedAboutFirst) {
  const std::string run = run_cube(cube_without_levels_and_supports() +
                                   "supports:\n"
                                   "  - {name: nut, at: [18, 10, 20], radius_mm: 3, fixed: [z], bite: true}\n"
                                   "  - {name: condyle, at: [2, 10, 20], radius_mm: 3, fixed: [x, y]}\n");
  const json hold = json::parse(read_file(run + "/results.json"))["support_hold"][0];
  ASSERT_TRUE(hold["weak"].get<bool>()) << hold.dump();
  const std::string out = temp_dir() + "/weak.html";
  const test::CommandResult c = run_hexbite({"-q", "report", run, "-o", out, "--no-pictures", "--json"});
  ASSERT_EQ(c.exit_code, 0) << c.err;
  const json summary = json::parse(c.out);
  ASSERT_GE(summary["warnings"].size(), 1u) << summary.dump();
  EXPECT_NE(summary["warnings"][0].get<std::string>().find("Weak supports"), std::string::npos);
  const std::string html = read_file(out);
  const std::string warnings = section(html, "Warnings");
  EXPECT_NE(warnings.find("against a rotation about the axis through"), std::string::npos) << warnings;
  EXPECT_LT(html.find("<h2>Warnings"), html.find("<h2>Results"));
  EXPECT_NE(c.err.find("hexbite: warning: Weak supports"), std::string::npos) << c.err;
}

// A run whose largest displacement broke the small-displacement check (E in GPa typed for MPa) exits 1 but
// keeps its files, and its report gave every figure as a result with "0 warnings". results.json now holds
// the check's limit, and the report says first that the figures are meaningless.
TEST(ReportWarnings, AFailedSmallDisplacementCheckIsWarnedAbout) {
  const std::string dir = temp_dir();
  write_file(dir + "/cube.obj", test::cubes_obj(1));
  write_file(dir + "/cube.yaml", cube_without_levels_and_supports() +
                                     "supports:\n  - {name: nut, at: [0, 10, 10], radius_mm: 5, bite: true}\n"
                                     "materials: {default: {E_MPa: 1}}\n");
  const test::CommandResult run = run_hexbite({"-q", "run", dir + "/cube.yaml", "-o", dir + "/run"});
  ASSERT_EQ(run.exit_code, 1) << run.err;
  ASSERT_NE(run.err.find("the largest displacement"), std::string::npos) << run.err;
  const json checks = json::parse(read_file(dir + "/run/results.json"))["checks"];
  EXPECT_FALSE(checks["passed"].get<bool>()) << checks.dump();
  EXPECT_NEAR(checks["max_displacement_limit_mm"].get<double>(), 0.1 * checks["bone_size_mm"].get<double>(),
              1e-12);
  EXPECT_NEAR(checks["bone_size_mm"].get<double>(), 20.0, 0.5);  // the cube's largest extent
  const std::string out = dir + "/failed.html";
  const test::CommandResult c =
      run_hexbite({"-q", "report", dir + "/run", "-o", out, "--no-pictures", "--json"});
  ASSERT_EQ(c.exit_code, 0) << c.err;
  const json summary = json::parse(c.out);
  ASSERT_GE(summary["warnings"].size(), 1u) << summary.dump();
  EXPECT_NE(summary["warnings"][0].get<std::string>().find("Small displacements: on level 0 the largest "
                                                           "displacement"),
            std::string::npos)
      << summary.dump();
  EXPECT_NE(section(read_file(out), "Warnings").find("every figure of this report is meaningless"),
            std::string::npos);
  // A run that passed says so, and its report has no such warning.
  const json passed = json::parse(read_file(run_cube(kCube) + "/results.json"))["checks"];
  EXPECT_TRUE(passed["passed"].get<bool>()) << passed.dump();
}

// What was simulated is in the report, from results.json alone: the materials with the hexes each takes, the
// muscle loads, and each support's condition (fixed components or a spring), centre and radius.
TEST(ReportModel, StatesTheMaterialsTheLoadsAndTheSupports) {
  const std::string run =
      run_cube(cube_without_levels_and_supports() +
               "materials:\n"
               "  default: {E_MPa: 11000, poisson: 0.3}\n"
               "  regions:\n"
               "    - {name: graft<1>, box: {min: [10, -1, -1], max: [21, 21, 21]}, E_MPa: 2200}\n"
               "supports:\n"
               "  - {name: nut, at: [0, 10, 10], radius_mm: 5, bite: true}\n"
               "  - {name: floor_rest, at: [10, 10, 0], radius_mm: 4, fixed: [y, z]}\n"
               "  - {name: pad, at: [10, 20, 10], radius_mm: 4.5, spring_N_per_mm3: 25}\n");
  const json r = json::parse(read_file(run + "/results.json"));
  const long graft = r["materials"]["regions"][0]["hexes"].get<long>();
  const long hexes = r["mesh"]["hexes"].get<long>();
  ASSERT_GT(graft, 0);
  ASSERT_LT(graft, hexes);
  EXPECT_EQ(r["supports"][1]["fixed"], json::parse(R"(["y", "z"])"));
  EXPECT_TRUE(r["supports"][2]["fixed"].empty());
  EXPECT_EQ(r["supports"][2]["spring_N_per_mm3"].get<double>(), 25.0);
  EXPECT_EQ(r["muscles"][0]["activation"].get<double>(), 1.0);

  const std::string out = temp_dir() + "/model.html";
  const test::CommandResult c = run_hexbite({"-q", "report", run, "-o", out, "--no-pictures"});
  ASSERT_EQ(c.exit_code, 0) << c.err;
  const std::string html = read_file(out);
  const std::string model = section(html, "Model");
  ASSERT_FALSE(model.empty()) << html;
  EXPECT_LT(html.find("<h2>Model"), html.find("<h2>Results"));
  EXPECT_NE(model.find("<td>bone (default)</td><td class=\"n\">11000</td><td class=\"n\">0.3</td><td "
                       "class=\"n\">" +
                       std::to_string(hexes - graft) + "</td>"),
            std::string::npos)
      << model;
  EXPECT_NE(model.find("<td>region graft&lt;1&gt;</td><td class=\"n\">2200</td><td class=\"n\">0.3</td><td "
                       "class=\"n\">" +
                       std::to_string(graft) + "</td>"),
            std::string::npos)
      << model;
  EXPECT_NE(model.find("<td>pull</td><td class=\"n\">1.00</td><td class=\"n\">100.0</td><td>(1.00, 0.00, "
                       "0.00)</td>"),
            std::string::npos)
      << model;
  EXPECT_NE(model.find("<td>nut</td><td>fixed x, y, z</td><td>(0.0, 10.0, 10.0)</td><td class=\"n\">5</td>"),
            std::string::npos)
      << model;
  EXPECT_NE(model.find("<td>floor_rest</td><td>fixed y, z</td>"), std::string::npos) << model;
  EXPECT_NE(model.find("<td>pad</td><td>spring, 25 N/mm<sup>3</sup></td><td>(10.0, 20.0, 10.0)</td><td "
                       "class=\"n\">4.5</td>"),
            std::string::npos)
      << model;
  EXPECT_NE(section(html, "What was run").find("run with hexbite "), std::string::npos);
}

// A figure that is not zero is never shown as zero (reports.md): an activation of 0.004 read "0.00", and a
// direction component of 1e-4 "0.00".
TEST(ReportModel, SmallFiguresAreNotShownAsZero) {
  std::string scenario = cube_without_levels_and_supports() +
                         "supports:\n  - {name: nut, at: [0, 10, 10], radius_mm: 5, bite: true}\n";
  scenario.replace(scenario.find("activation: 1,"), 14, "activation: 0.004,");
  scenario.replace(scenario.find("direction: [1, 0, 0]"), 20, "direction: [1, 0.0001, 0]");
  const std::string run = run_cube(scenario);
  const std::string out = temp_dir() + "/small.html";
  const test::CommandResult c = run_hexbite({"-q", "report", run, "-o", out, "--no-pictures"});
  ASSERT_EQ(c.exit_code, 0) << c.err;
  const std::string model = section(read_file(out), "Model");
  EXPECT_NE(model.find("<td>pull</td><td class=\"n\">4.00e-03</td><td class=\"n\">0.4</td><td>(1.00, "
                       "1.00e-04, 0.00)</td>"),
            std::string::npos)
      << model;
}

TEST_F(Report, BadInputIsRefusedWithExit2AndWritesNothing) {
  const std::string dir = temp_dir(), out = dir + "/r.html";
  const std::string results = read_file(*run_dir_ + "/results.json");
  // A run folder holding `text` as results.json (and no solution).
  const auto folder_with = [&](const std::string& name, const std::string& text) {
    fs::create_directories(dir + "/" + name);
    write_file(dir + "/" + name + "/results.json", text);
    return dir + "/" + name;
  };
  json no_key = *results_;
  no_key["validation"]["levels"][1].erase("hexes");
  json wrong_type = *results_;
  wrong_type["bite_force_N"] = "367.0";
  json no_reaction = *results_;  // the report left the support out without a word
  no_reaction["reactions"].erase("floor_rest");
  std::string overflow = results;
  overflow.replace(overflow.find("\"bite_force_N\": ") + 16, 1, "1e999,\"x\":");
  const std::string cut = results.substr(0, results.find("\"mesh\""));  // ends inside the object
  const int cut_line = static_cast<int>(count(cut, "\n")) + 1;
  write_file(dir + "/a_file", "x");
  fs::create_directories(dir + "/empty");
  // A study's output folder (study.json and a folder per variant), and a folder in the way of solution.vtu.
  fs::create_directories(dir + "/study/reference");
  write_file(dir + "/study/study.json", "{}");
  write_file(dir + "/study/reference/results.json", results);
  fs::create_directories(dir + "/vtu_folder/solution.vtu");
  write_file(dir + "/vtu_folder/results.json", results);
  struct Case {
    std::vector<std::string> args;
    std::string fragment;
  };
  const std::vector<Case> cases = {
      {{"report", dir + "/no_such", "-o", out}, "'" + dir + "/no_such' does not exist"},
      {{"report", dir + "/a_file", "-o", out}, "is a file, not a folder"},
      {{"report", dir + "/empty", "-o", out},
       "'" + dir + "/empty' holds no results.json, so no finished run: run `hexbite run SCENARIO -o"},
      {{"report", folder_with("cut", cut), "-o", out, "--no-pictures"},
       "cut/results.json':" + std::to_string(cut_line) + ":"},
      {{"report", folder_with("no_key", no_key.dump(1)), "-o", out, "--no-pictures"},
       "key 'validation.levels[1].hexes' is missing"},
      {{"report", folder_with("wrong_type", wrong_type.dump(1)), "-o", out, "--no-pictures"},
       "key 'bite_force_N' is a string, expected a number or null"},
      {{"report", folder_with("no_reaction", no_reaction.dump(1)), "-o", out, "--no-pictures"},
       "key 'reactions.floor_rest' is missing"},
      // A number beyond a double: nlohmann's own text, exit 1, no file named.
      {{"report", folder_with("overflow", overflow), "-o", out, "--no-pictures"},
       "overflow/results.json': number overflow parsing '1e999'; the run writes no such number"},
      {{"report", folder_with("no_vtu", results), "-o", out}, "`outputs: {vtu: false}`"},
      {{"report", folder_with("no_vtu2", results), "-o", out}, "add --no-pictures"},
      {{"report", *run_dir_, "-o", dir + "/r.txt"}, "this command writes .html or .htm"},
      {{"report", *run_dir_, "-o", dir + "/no_such/r.html"}, "folder '" + dir + "/no_such' does not exist"},
      {{"report", *run_dir_, "-o", dir}, "is a folder"},
      // Said "holds no results.json" and "does not exist".
      {{"report", dir + "/study", "-o", out},
       "is the output folder of a study (it holds study.json), and a report is of one run: give the folder "
       "of "
       "one of its variants, e.g. '" +
           dir + "/study/reference'"},
      {{"report", dir + "/vtu_folder", "-o", out}, "solution.vtu' is a folder, not the run's solution file"},
  };
  for (const Case& c : cases) {
    const test::CommandResult r = run_hexbite(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.args[1] << "\n" << r.err;
    EXPECT_NE(r.err.find(c.fragment), std::string::npos) << c.fragment << "\n" << r.err;
    EXPECT_FALSE(fs::exists(out)) << c.args[1];
    EXPECT_FALSE(fs::exists(dir + "/r.txt"));
  }
  // The not-JSON case says what is wrong at that line.
  EXPECT_NE(run_hexbite({"report", dir + "/cut", "-o", out, "--no-pictures"}).err.find("not JSON"),
            std::string::npos);
}

// A results.json without `checks` (hand-edited or cut) was reported without the small-displacement warning
// of a run that failed it; other hand-edited values that no run writes were printed as they were, and a
// blank --title fell back to the scenario's name or wrote an empty heading.
TEST_F(Report, ValuesNoRunWritesAndABlankTitleAreRefused) {
  const std::string dir = temp_dir(), out = dir + "/r.html";
  const auto edited = [&](const std::string& name, const std::function<void(json&)>& edit) {
    json j = *results_;
    edit(j);
    fs::create_directories(dir + "/" + name);
    write_file(dir + "/" + name + "/results.json", j.dump(1));
    return dir + "/" + name;
  };
  const std::vector<std::pair<std::string, std::string>> cases = {
      {edited("no_checks", [](json& j) { j.erase("checks"); }), "key 'checks' is missing"},
      {edited("passed", [](json& j) { j["checks"]["passed"] = "yes"; }),
       "key 'checks.passed' is a string, expected true or false"},
      {edited("limit", [](json& j) { j["checks"]["max_displacement_limit_mm"] = 0; }),
       "key 'checks.max_displacement_limit_mm' is 0, but a run writes a positive number"},
      {edited("hexes", [](json& j) { j["mesh"]["hexes"] = -5; }),
       "key 'mesh.hexes' is -5, but a run writes at least 1"},
      {edited("level", [](json& j) { j["validation"]["levels"][1]["level"] = 2; }),
       "key 'validation.levels[1].level' is 2, but validation.levels holds level 0 first and one more in "
       "each "
       "entry, so it must be 1"},
  };
  for (const auto& [folder, fragment] : cases) {
    const test::CommandResult r = run_hexbite({"report", folder, "-o", out, "--no-pictures"});
    EXPECT_EQ(r.exit_code, 2) << folder << "\n" << r.err;
    EXPECT_NE(r.err.find(fragment), std::string::npos) << fragment << "\n" << r.err;
    EXPECT_FALSE(fs::exists(out));
  }
  for (const char* title : {"", "   "}) {
    const test::CommandResult r =
        run_hexbite({"report", *run_dir_, "-o", out, "--no-pictures", "--title", title});
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find("--title"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("the title is blank"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out));
  }
  // A Latin-1 title made the report invalid UTF-8 (it declares utf-8), a control character invalid HTML.
  const std::vector<std::pair<std::string, std::string>> titles = {
      {"r\xe9sum\xe9", "--title: the title is not valid UTF-8 (byte 0xE9 at position 2): give it in UTF-8"},
      {"a\x01"
       "b",
       "--title: the title holds a control character (0x01); it is one line of printable text: remove it"},
      {"two\nlines", "--title: the title holds a control character (0x0A, a line break)"},
      // The C1 controls and the Unicode separators passed (helper AA).
      {"T\u009b2J", "--title: the title holds a control character (U+009B)"},
      {"two\u2028lines", "--title: the title holds a Unicode line separator (U+2028)"},
  };
  for (const auto& [title, message] : titles) {
    const test::CommandResult r =
        run_hexbite({"report", *run_dir_, "-o", out, "--no-pictures", "--title", title});
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out));
  }
}

// A .pvtu whose piece is missing was "cannot read 'solution.pvtu' ... (VTK: File for piece 0 cannot be
// read.)"; the missing piece is named.
TEST_F(Report, AMissingPieceOfTheSolutionIsNamed) {
  const std::string dir = temp_dir(), out = dir + "/r.html";
  write_file(dir + "/results.json", read_file(*run_dir_ + "/results.json"));
  write_file(dir + "/solution.pvtu",
             "<?xml version=\"1.0\"?>\n<VTKFile type=\"PUnstructuredGrid\" version=\"1.0\">\n"
             "  <PUnstructuredGrid GhostLevel=\"0\">\n    <PPoints>\n      <PDataArray type=\"Float64\" "
             "NumberOfComponents=\"3\"/>\n    </PPoints>\n    <Piece Source=\"solution_0.vtu\"/>\n"
             "  </PUnstructuredGrid>\n</VTKFile>\n");
  const test::CommandResult r = run_hexbite({"report", dir, "-o", out}, display_launcher());
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(
      r.err.find("'" + dir + "/solution_0.vtu' (piece 0 of '" + dir + "/solution.pvtu') does not exist"),
      std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(out));
}

// The pictures are of the run whose figures the report prints: a solution.vtu beside another run's
// results.json (a different mesh, or the same mesh with other loads) was drawn without a word.
TEST_F(Report, PicturesOfAnotherRunAreRefused) {
  const std::string dir = temp_dir(), out = dir + "/r.html";
  json other_mesh = *results_, other_loads = *results_;
  other_mesh["mesh"]["hexes"] = (*results_)["mesh"]["hexes"].get<long>() + 8;
  other_loads["max_displacement_mm"] = (*results_)["max_displacement_mm"].get<double>() * 1.5;
  const std::vector<std::pair<json, std::string>> cases = {
      {other_mesh, "hexes where results.json's coarse level has"},
      {other_loads, "has a largest displacement of"},
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const std::string folder = dir + "/run" + std::to_string(i);
    fs::create_directories(folder);
    fs::copy_file(*run_dir_ + "/solution.vtu", folder + "/solution.vtu");
    write_file(folder + "/results.json", cases[i].first.dump(1));
    const test::CommandResult r = run_hexbite({"report", folder, "-o", out}, display_launcher());
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find(cases[i].second), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("it is not the solution of the run that results.json describes"), std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(out));
  }
}

// Under mpirun the solution is written in pieces (solution.pvtu): the report draws its pictures from them
// (before, the renderer read only a single .vtu).
TEST(ReportMpi, PicturesOfARunUnderMpirunComeFromItsPieces) {
  const std::string dir = temp_dir();
  write_file(dir + "/cube.obj", test::cubes_obj(1));
  std::string text = kCube;
  text.replace(text.find("validation_levels: 1"), 20, "validation_levels: 0");
  write_file(dir + "/cube.yaml", text);
  const test::CommandResult run =
      run_hexbite({"-q", "run", dir + "/cube.yaml", "-o", dir + "/run"},
                  {HEXBITE_MPIEXEC, "-np", "2", "--allow-run-as-root", "--oversubscribe"});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  ASSERT_TRUE(fs::exists(dir + "/run/solution.pvtu"));
  ASSERT_FALSE(fs::exists(dir + "/run/solution.vtu"));
  const test::CommandResult c =
      run_hexbite({"report", dir + "/run", "-o", dir + "/r.html", "--json"}, display_launcher());
  ASSERT_EQ(c.exit_code, 0) << c.err;
  EXPECT_EQ(json::parse(c.out)["pictures"].size(), 3u) << c.out;
  const std::string html = read_file(dir + "/r.html");
  EXPECT_EQ(count(html, "src=\"data:image/png;base64,iVBORw0KGgo"), 3u);  // the PNG signature in base64
  EXPECT_NE(section(html, "What was run").find("<td>MPI ranks</td><td>2</td>"), std::string::npos);
  // `hexbite render` reads the pieces too (before: "unknown extension '.pvtu'").
  const test::CommandResult render =
      run_hexbite({"-q", "render", dir + "/run/solution.pvtu", "--field", "von_mises", "-o", dir + "/vm.png",
                   "--width", "320", "--height", "200"},
                  display_launcher());
  EXPECT_EQ(render.exit_code, 0) << render.err;
  EXPECT_EQ(read_file(dir + "/vm.png").substr(1, 3), "PNG");
}

// Without a display: the hint of `hexbite render` (exit 1, nothing written), unless --no-pictures.
TEST_F(Report, WithoutDisplayNeedsXvfbOrNoPictures) {
  const std::string dir = temp_dir();
  const test::CommandResult r =
      run_hexbite({"report", *run_dir_, "-o", dir + "/r.html"}, {"env", "-u", "DISPLAY"});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("no X display"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("xvfb-run -a"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--no-pictures"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/r.html"));
  EXPECT_EQ(run_hexbite({"-q", "report", *run_dir_, "-o", dir + "/r.html", "--no-pictures"},
                        {"env", "-u", "DISPLAY"})
                .exit_code,
            0);
  EXPECT_TRUE(fs::exists(dir + "/r.html"));
}

}  // namespace
}  // namespace hexbite
