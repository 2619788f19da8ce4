// The hexbite command line as a user meets it: help and version, usage errors, `hexbite surface check` on
// good and bad input (exit codes, messages, no output file on failure), and --json output that is JSON alone.
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include <pwd.h>
#include <sys/stat.h>
#include <unistd.h>

#include "tests/test_util.h"

namespace hexbite {
namespace {

using test::read_file;
using test::run_hexbite;
using test::shared_data;
using test::temp_dir;
using test::write_file;

namespace fs = std::filesystem;

// A unit cube as OBJ text: vertex i has x = bit 0, y = bit 1, z = bit 2 (1-based in the file),
// twelve outward triangles. The bad-input cases below are small edits of it.
const char* const kCubeVertices = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n";
const char* const kCubeFaces[12] = {"f 1 3 4\n", "f 1 4 2\n", "f 5 6 8\n", "f 5 8 7\n",
                                    "f 1 2 6\n", "f 1 6 5\n", "f 3 7 8\n", "f 3 8 4\n",
                                    "f 1 5 7\n", "f 1 7 3\n", "f 2 4 8\n", "f 2 8 6\n"};

std::string cube_obj(int skip_face = -1, const std::string& extra = "") {
  std::string text = kCubeVertices;
  for (int i = 0; i < 12; ++i)
    if (i != skip_face) text += kCubeFaces[i];
  return text + extra;
}

// The cube with sides of `side` (in the file's unit), for the unit warnings.
std::string cube_obj_of_side(double side) {
  std::string text;
  for (int v = 0; v < 8; ++v)
    text += "v " + std::to_string(side * (v & 1)) + " " + std::to_string(side * ((v >> 1) & 1)) + " " +
            std::to_string(side * ((v >> 2) & 1)) + "\n";
  for (const char* f : kCubeFaces) text += f;
  return text;
}

std::string write_case(const std::string& name, const std::string& contents) {
  const std::string path = temp_dir() + "/" + name;
  write_file(path, contents);
  return path;
}

// Runs `surface check FILE -o OUT [extra...]` and expects exit code 2, the message fragment on
// standard error and no output file.
void expect_rejected(const std::string& file, const std::string& fragment,
                     const std::vector<std::string>& extra = {}) {
  const std::string out = temp_dir() + "/repaired.stl";
  std::vector<std::string> args = {"surface", "check", file, "-o", out};
  args.insert(args.end(), extra.begin(), extra.end());
  const auto r = run_hexbite(args);
  EXPECT_EQ(r.exit_code, 2) << file << "\n" << r.err;
  EXPECT_NE(r.err.find("hexbite: error: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(fragment), std::string::npos) << "stderr lacks '" << fragment << "':\n" << r.err;
  EXPECT_FALSE(fs::exists(out)) << "output written despite the error";
  // Nothing else either: no temporary file left next to the output.
  EXPECT_TRUE(fs::is_empty(fs::path(out).parent_path()));
}

TEST(Cli, HelpAndVersion) {
  auto r = run_hexbite({"--help"});
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("surface"), std::string::npos) << r.out;
  r = run_hexbite({"--version"});
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.out.rfind("hexbite ", 0), 0u) << r.out;
  r = run_hexbite({"surface", "check", "--help"});
  EXPECT_EQ(r.exit_code, 0);
  for (const char* option : {"FILE", "--json", "--units", "-o"})
    EXPECT_NE(r.out.find(option), std::string::npos) << option << " missing in\n" << r.out;
  // mesh --units scales the --landmarks file too; its help said "of the surface file" only.
  r = run_hexbite({"mesh", "--help"});
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("Length unit of the surface and landmark files"), std::string::npos) << r.out;
}

TEST(Cli, UsageErrorsExitTwo) {
  EXPECT_EQ(run_hexbite({}).exit_code, 2);
  EXPECT_EQ(run_hexbite({"--no-such-option"}).exit_code, 2);
  EXPECT_EQ(run_hexbite({"no-such-command"}).exit_code, 2);
  EXPECT_EQ(run_hexbite({"surface"}).exit_code, 2);
  const auto r = run_hexbite({"surface", "check"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("FILE"), std::string::npos) << r.err;
  // The missing argument is named as in the docs (MESH.vtu), not "mesh is required", which reads like the
  // mesh command.
  for (const char* command : {"quality", "reorder", "refine"}) {
    const auto missing = run_hexbite({command});
    EXPECT_EQ(missing.exit_code, 2) << command;
    EXPECT_NE(missing.err.find("MESH is required"), std::string::npos) << command << ": " << missing.err;
  }
}

TEST(Cli, RealJawChecksCleanAsJson) {
  const auto r = run_hexbite({"surface", "check", shared_data("jaw/jaw_smooth.stl"), "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  for (const char* key : {"file",
                          "triangles",
                          "vertices",
                          "components",
                          "closed",
                          "open_edges",
                          "non_manifold_edges",
                          "non_manifold_vertices",
                          "consistently_oriented",
                          "outward",
                          "self_intersections",
                          "degenerate_triangles",
                          "euler_characteristic",
                          "genus",
                          "bbox",
                          "volume_mm3",
                          "min_angle_deg",
                          "min_angle_histogram",
                          "repairs",
                          "problems",
                          "usable"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["triangles"], 41760);
  EXPECT_EQ(j["vertices"], 20882);
  EXPECT_EQ(j["components"], 1);
  EXPECT_EQ(j["closed"], true);
  EXPECT_EQ(j["outward"], true);
  EXPECT_EQ(j["genus"], 0);
  EXPECT_NEAR(j["volume_mm3"].get<double>(), 57600.0, 288.0);
  EXPECT_EQ(j["bbox"]["min"].size(), 3u);
  EXPECT_EQ(j["min_angle_histogram"].size(), 12u);
  EXPECT_TRUE(j["problems"].empty());
  EXPECT_EQ(j["usable"], true);
}

TEST(Cli, TextReportAndQuiet) {
  const std::string cube = write_case("cube.obj", cube_obj());
  auto r = run_hexbite({"surface", "check", cube});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  for (const char* line :
       {"triangles             12", "closed                yes", "genus 0", "1.0 mm^3", "usable: yes"})
    EXPECT_NE(r.out.find(line), std::string::npos) << line << " missing in\n" << r.out;
  r = run_hexbite({"--quiet", "surface", "check", cube});
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_TRUE(r.out.empty()) << r.out;
}

// A 20 mm cube exported in metres and read without --units is a usable 0.02 mm cube: nothing in the
// report was wrong, but every later length, stress and volume would be off by 1000. Warned about.
TEST(Cli, SurfaceInMetresWithoutUnitsIsWarnedAbout) {
  const std::string path = write_case("metres.obj", cube_obj_of_side(0.02));
  auto r = run_hexbite({"surface", "check", path});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("hexbite: warning: '" + path + "': the surface is only 0.02 mm across"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("give --units m"), std::string::npos) << r.err;
  r = run_hexbite({"surface", "check", path, "--units", "m"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
  // The unit cube of the other tests is small but plausible: no warning.
  r = run_hexbite({"surface", "check", write_case("cube.obj", cube_obj())});
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
  // The grid mesher meshes it just as well (the mesh is fine, in the wrong unit), so it warns too.
  const std::string mesh = temp_dir() + "/metres.vtu";
  r = run_hexbite({"mesh", path, "--method", "grid", "--target-hexes", "8", "-o", mesh});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("hexbite: warning: '" + path + "': the surface is only 0.02 mm across"),
            std::string::npos)
      << r.err;
  // So do the other commands that read a surface: surface clean, and refine with --surface.
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"surface", "clean", path, "-o", temp_dir() + "/clean.stl"},
        std::vector<std::string>{"refine", mesh, "--surface", path, "-o", temp_dir() + "/fine.vtu"}}) {
    r = run_hexbite(args);
    EXPECT_NE(r.err.find("hexbite: warning: '" + path + "': the surface is only 0.02 mm across"),
              std::string::npos)
        << args[0] << ": " << r.err;
  }
}

// The other way round: a 100 mm cube read with --units m is 100 m across. The warning used to suggest
// micrometres whatever the unit given; it names the unit that gives a plausible size instead.
TEST(Cli, SurfaceInMillimetresReadAsMetresIsToldToUseMillimetres) {
  const std::string path = write_case("mm.obj", cube_obj_of_side(100));
  auto r = run_hexbite({"surface", "check", path, "--units", "m"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("hexbite: warning: '" + path +
                       "': the surface is 1e+05 mm across (the largest side of its bounding box) with its "
                       "coordinates read as m; a mandible is about 100 mm. If the file's coordinates are in "
                       "mm (100 mm across), give --units mm"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("micrometres"), std::string::npos) << r.err;
  r = run_hexbite({"surface", "check", path});
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
}

TEST(Cli, RepairedSurfaceIsWrittenInMillimetres) {
  // An inward cube in cm: flipped, scaled to mm and written; the written file checks clean.
  std::string inward = kCubeVertices;
  for (const char* f : kCubeFaces) {
    int a, b, c;
    ASSERT_EQ(std::sscanf(f, "f %d %d %d", &a, &b, &c), 3);
    inward += "f " + std::to_string(a) + " " + std::to_string(c) + " " + std::to_string(b) + "\n";
  }
  const std::string in = write_case("inward.obj", inward);
  const std::string out = temp_dir() + "/outward.ply";
  auto r = run_hexbite({"surface", "check", in, "--units", "cm", "-o", out, "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["repairs"].size(), 1u);
  EXPECT_NE(j["repairs"][0].get<std::string>().find("reversed the orientation"), std::string::npos);
  EXPECT_NEAR(j["volume_mm3"].get<double>(), 1000.0, 1e-9);
  EXPECT_EQ(j["output"], out);
  ASSERT_TRUE(fs::exists(out));

  r = run_hexbite({"surface", "check", out, "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j["repairs"].empty()) << j["repairs"];
  EXPECT_EQ(j["outward"], true);
  EXPECT_NEAR(j["volume_mm3"].get<double>(), 1000.0, 1e-9);
}

TEST(Cli, SurfaceWhoseComponentsFaceDifferentWaysHasNoVolume) {
  // The unit cube and, beside it, a copy facing inward: refused, with the copy named and no volume.
  std::string text = cube_obj();
  for (int v = 0; v < 8; ++v)
    text += "v " + std::to_string(3 + (v & 1)) + " " + std::to_string((v >> 1) & 1) + " " +
            std::to_string((v >> 2) & 1) + "\n";
  for (const char* f : kCubeFaces) {
    int a, b, c;
    ASSERT_EQ(std::sscanf(f, "f %d %d %d", &a, &b, &c), 3);
    text += "f " + std::to_string(a + 8) + " " + std::to_string(c + 8) + " " + std::to_string(b + 8) + "\n";
  }
  const std::string path = write_case("one_inward.obj", text);
  auto r = run_hexbite({"surface", "check", path, "--json"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j["volume_mm3"].is_null()) << j["volume_mm3"];
  EXPECT_NE(
      r.err.find("component 1 of 12 triangles (the first is triangle 12) from (3, 0, 0) to (4, 1, 1), an "
                 "outer shell facing inward"),
      std::string::npos)
      << r.err;
  r = run_hexbite({"surface", "check", path});
  EXPECT_NE(r.out.find("enclosed volume       undefined (the components are oriented inconsistently"),
            std::string::npos)
      << r.out;
}

// Under an address-space limit (ulimit -v) OpenBLAS's threads, started when it is loaded, retried their 128
// MB buffers forever: at 600 MB `hexbite --version` printed and never ended, and an out-of-memory mesh said
// "std::bad_alloc" and then hung the same way. Each command is given 60 s (they take about 1-3 s).
TEST(Cli, UnderATightAddressSpaceLimitCommandsEndAndOutOfMemoryIsSaidPlainly) {
  const std::vector<std::string> limit = {"timeout", "60", "prlimit", "--as=600000000", "--"};
  test::CommandResult r = run_hexbite({"--version"}, limit);
  EXPECT_EQ(r.exit_code, 0) << r.err;  // 124: timeout had to end it
  EXPECT_EQ(r.out.rfind("hexbite ", 0), 0u) << r.out;
  // A value OpenBLAS does not take as a count (helper AA) is no choice of one.
  for (const char* value : {"", "0", "abc"}) {
    std::vector<std::string> with_value = {"env", std::string("OPENBLAS_NUM_THREADS=") + value};
    with_value.insert(with_value.end(), limit.begin(), limit.end());
    EXPECT_EQ(run_hexbite({"--version"}, with_value).exit_code, 0)
        << "OPENBLAS_NUM_THREADS='" << value << "'";
  }

  const std::string dir = temp_dir();
  ASSERT_EQ(run_hexbite({"-q", "generate", "mandible", "-o", dir + "/m.stl"}).exit_code, 0);
  r = run_hexbite({"-q", "mesh", dir + "/m.stl", "--target-hexes", "20000", "-o", dir + "/m.vtu"}, limit);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("hexbite: failed: out of memory: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("address-space limit (ulimit -v)"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/m.vtu"));
}

TEST(CliBadInput, MissingFile) {
  expect_rejected(temp_dir() + "/nowhere.stl", "does not exist");
}

TEST(CliBadInput, EmptyFile) {
  expect_rejected(write_case("empty.stl", ""), "is empty (0 bytes)");
}

TEST(CliBadInput, TruncatedBinaryStl) {
  std::string bytes(84 + 50 * 3, '\0');
  bytes[80] = 10;  // announces 10 triangles, holds 3
  expect_rejected(write_case("cut.stl", bytes), "truncated or corrupt binary STL");
  expect_rejected(write_case("cut2.stl", bytes), "84 + 50 x 10 = 584 bytes, but the file has 234 bytes");
}

TEST(CliBadInput, NanCoordinate) {
  expect_rejected(write_case("nan.stl",
                             "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
                             "vertex 0 NaN 0\nendloop\nendfacet\nendsolid x\n"),
                  "line 6: the y coordinate is NaN");
}

TEST(CliBadInput, InfiniteCoordinate) {
  std::string text = cube_obj();
  text.replace(text.find("v 1 1 1"), 7, "v 1 inf 1");
  expect_rejected(write_case("inf.obj", text), "line 8 (vertex 8): the y coordinate is infinite");
}

TEST(CliBadInput, OpenSurface) {
  expect_rejected(write_case("open.obj", cube_obj(5)), "3 open edges");
}

TEST(CliBadInput, NonManifoldEdge) {
  // A fin: a third triangle on the cube's edge 1-2.
  expect_rejected(write_case("fin.obj", cube_obj(-1, "v 0.5 -1 -1\nf 1 2 9\n")),
                  "1 non-manifold edge (shared by more than two triangles)");
}

// A triangle repeated with the same orientation (an STL export artefact) is dropped as a safe repair; before,
// it made its three edges "non-manifold" and the surface unusable. A copy in the opposite orientation is
// not a duplicate and stays a problem.
TEST(Cli, DuplicatedTriangleIsRemovedAsARepair) {
  const std::string out = temp_dir() + "/repaired.stl";
  const auto r =
      run_hexbite({"surface", "check", write_case("dup.obj", cube_obj(-1, "f 4 2 1\n")), "-o", out});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(
      r.out.find("removed 1 duplicated triangle (the same three vertices in the same order as an earlier "
                 "one; the first was triangle 12 of the file)"),
      std::string::npos)
      << r.out;
  EXPECT_TRUE(fs::exists(out));
  expect_rejected(write_case("flipped.obj", cube_obj(-1, "f 1 2 4\n")), "3 non-manifold edges");
}

TEST(CliBadInput, InconsistentOrientation) {
  std::string text = cube_obj();
  text.replace(text.find("f 3 8 4"), 7, "f 3 4 8");
  expect_rejected(write_case("inconsistent.obj", text), "inconsistent orientation: 3 edges");
}

TEST(CliBadInput, UnknownExtension) {
  expect_rejected(write_case("cube.xyz", cube_obj()),
                  "unknown extension '.xyz'; accepted surface formats are .stl");
}

TEST(CliBadInput, UnknownUnit) {
  expect_rejected(write_case("cube.obj", cube_obj()), "unknown length unit 'inch'", {"--units", "inch"});
}

TEST(CliBadInput, OutOfRangeIndexAndMalformedLine) {
  expect_rejected(write_case("index.obj", cube_obj(-1, "f 1 2 42\n")),
                  "line 21: face index 42 is out of range");
  expect_rejected(write_case("bad.off", "OFF\n3 1 0\n0 0 0\n1 0 0 \n0 one 0\n3 0 1 2\n"),
                  "line 5: malformed OFF line '0 one 0'");
}

// Output paths are checked while the command line is parsed, before any work: a folder, a missing folder or
// a name whose extension the command does not write is exit 2 with the reason, and nothing is written
// (before, `mesh -o x.txt` wrote a VTU into x.txt and `mesh -o /tmp` meshed and then failed with "Success").
TEST(CliBadInput, OutputPathsAreCheckedBeforeAnyWork) {
  const std::string dir = temp_dir();
  const std::string cube = write_case("cube.obj", cube_obj());
  struct Case {
    std::vector<std::string> args;
    std::string fragment;
  };
  const std::vector<Case> cases = {
      {{"mesh", cube, "-o", dir}, "is a folder: give a file name in it"},
      {{"mesh", cube, "-o", dir + "/mesh.txt"}, "this command writes .vtu"},
      {{"mesh", cube, "-o", dir + "/none/mesh.vtu"}, "folder '" + dir + "/none' does not exist"},
      {{"quad", "from-mandible", cube, "-o", dir + "/q.vtp"}, "this command writes .obj"},
      {{"surface", "clean", cube, "-o", dir + "/c.xyz"}, "writes .stl, .obj, .ply, .off or .vtp"},
      {{"generate", "mandible", "-o", dir + "/g.stl", "--ct", dir + "/g.raw"},
       "writes .mha, .mhd, .nii or .nii.gz"},
      {{"run", "scenario.yaml", "-o", cube}, "is a file, not a folder"},
      // Both used to mesh and solve first and then fail with exit 1 ("Invalid argument", "Not a directory").
      {{"run", "scenario.yaml", "-o", ""}, "the output folder is an empty name"},
      {{"study", "study.yaml", "-o", cube + "/sub/out"}, "'" + cube + "' is a file, not a folder"},
      // /proc takes no new folders, also for root (as a read-only file system): both used to mesh and
      // solve first and then fail with exit 1.
      {{"run", "scenario.yaml", "-o", "/proc/hexbite-out"},
       "cannot create the output folder '/proc/hexbite-out': no folder can be made in '/proc'"},
      {{"study", "study.yaml", "-o", "/proc/hexbite-out/study"}, "give a folder you can write to"},
      // Names longer than the file system allows (255 bytes) were found only when the outputs were
      // written, after the work (exit 1, "File name too long").
      {{"mesh", cube, "-o", dir + "/" + std::string(300, 'm') + ".vtu"},
       "a name in it is 304 bytes long, more than the 255 that its file system allows; give a shorter name"},
      {{"run", "scenario.yaml", "-o", dir + "/new/" + std::string(256, 'r') + "/out"},
       "cannot create the output folder '" + dir + "/new/" + std::string(256, 'r') +
           "/out': a name in it is 256 bytes long"},
  };
  for (const Case& c : cases) {
    const auto r = run_hexbite(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.args[0] << "\n" << r.err;
    EXPECT_NE(r.err.find(c.fragment), std::string::npos) << r.err;
  }
  // No output and no temporary file.
  EXPECT_TRUE(fs::is_empty(dir));
  // A dangling link as the output folder passed, and `run` and `study` failed after all their work (exit
  // 1, "File exists"); the default landmark path of `generate` (a folder in the way, a name too long) was
  // not checked at all until the mandible was made (helper K).
  const std::string links = temp_dir();
  fs::create_symlink(links + "/nowhere", links + "/dangling");
  fs::create_directories(links + "/g.landmarks.yaml");
  for (const Case& c : std::vector<Case>{
           {{"run", "scenario.yaml", "-o", links + "/dangling"},
            "'" + links + "/dangling' is a link to '" + links + "/nowhere', which does not exist"},
           {{"study", "study.yaml", "-o", links + "/dangling/sub"}, "is a link to"},
           {{"generate", "mandible", "-o", links + "/g.stl", "--dicom", links + "/dangling"}, "is a link to"},
           {{"generate", "mandible", "-o", links + "/g.stl"},
            "is a folder: give a file name in it, e.g. '" + links +
                "/g.landmarks.yaml/out.yaml' (the landmark file's default name, from -o); give --landmarks "
                "another path"},
       }) {
    const auto r = run_hexbite(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.args[0] << "\n" << r.err;
    EXPECT_NE(r.err.find(c.fragment), std::string::npos) << r.err;
  }
  EXPECT_EQ(std::distance(fs::directory_iterator(links), fs::directory_iterator()), 2);
  // Any case of the extension is fine.
  EXPECT_EQ(run_hexbite({"surface", "check", cube, "-o", dir + "/copy.STL"}).exit_code, 0);
  // A name of 255 bytes is written (its temporary name, the name with ".tmpPID" added, used to be too long).
  const std::string longest = dir + "/" + std::string(251, 'c') + ".stl";
  const auto r = run_hexbite({"surface", "check", cube, "-o", longest});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(longest));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 2);
}

// An output in a folder that takes no new files (/proc, also for root) is refused when the command line is
// read (exit 2); one whose write fails on the way (a full disk, here a file size limit with SIGXFSZ ignored)
// is a failed run (exit 1) that names the file and why, and leaves no file. Before: a .vtp said "cannot
// write '/proc/x.vtp': Success" (VTK's writer reported success, and the error code of the rename was cleared
// by the clean-up), the other formats named only the temporary file ("cannot open '/proc/.x.tmp123.stl' for
// writing"), and a .vtp on a full disk was an empty file with exit 0 (VTK's writer did not notice).
TEST(CliBadInput, AnOutputThatCannotBeCreatedIsNamed) {
  const std::string cube = write_case("cube.obj", cube_obj());
  const std::string dir = temp_dir();
  for (const char* ext : {".stl", ".vtp", ".obj"}) {
    const std::string in_proc = std::string("/proc/hexbite_no_such_output") + ext;
    auto r = run_hexbite({"surface", "check", cube, "-o", in_proc});
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find("cannot write '" + in_proc +
                         "': no file can be made in '/proc' (No such file or directory)"),
              std::string::npos)
        << r.err;

    // The real jaw's 41,760 triangles do not fit in 1 kB; the one-line message on standard error does.
    const std::string out = dir + "/full" + ext;
    r = run_hexbite(
        {"-q", "surface", "check", std::string(HEXBITE_SHARED_DATA) + "/jaw/jaw_smooth.stl", "-o", out},
        {"bash", "-c", "ulimit -f 1; exec \"$@\"", "bash"});  // SIGXFSZ killed it (exit 153, no word)
    EXPECT_EQ(r.exit_code, 1) << ext << " " << r.err;
    EXPECT_EQ(r.err, "hexbite: failed: cannot write '" + out +
                         "': the disk is full or the file passed a size limit (ulimit -f): make room on the "
                         "disk or choose another output folder\n")
        << r.err;
    EXPECT_TRUE(fs::is_empty(dir)) << ext;
  }
}

// Under a file size limit MPI_Init aborted `run --help` and every run with 16 lines of PMIx errors (exit 1),
// and a TMPDIR where no folder can be made with "orte_init failed" (helper P). Help needs no MPI, a run
// under the limit writes what fits, and the TMPDIR is named.
TEST(Cli, RunAndStudyStartUnderAFileSizeLimitAndNameAnUnusableTmpdir) {
  const std::vector<std::string> limited = {"bash", "-c", "ulimit -f 2000; exec \"$@\"", "bash"};
  for (const char* command : {"run", "study"}) {
    const test::CommandResult help = run_hexbite({command, "--help"}, limited);
    EXPECT_EQ(help.exit_code, 0) << help.err;
    EXPECT_NE(help.out.find("Output folder"), std::string::npos) << help.out;
    EXPECT_EQ(help.err.find("PMIX"), std::string::npos) << help.err;
  }
  const std::string dir = temp_dir();
  test::CommandResult r = run_hexbite({"run", dir + "/none.yaml", "-o", dir + "/out"}, limited);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("scenario file '" + dir + "/none.yaml' does not exist"), std::string::npos) << r.err;
  r = run_hexbite({"run", dir + "/none.yaml", "-o", dir + "/out"}, {"env", "TMPDIR=/proc"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(r.err,
            "hexbite: error: no folder can be made in TMPDIR '/proc' (No such file or directory), where "
            "MPI keeps its session files: point TMPDIR at a folder you can write to\n");
}

// A relative TMPDIR passed hexbite's own check, but MPI's helper process read it from '/': a run printed
// "Impossible to open the file /t/ompi.../contact.txt" and an ORTE error, even under -q. It is taken from
// the current folder now, and only hexbite's own message is printed.
TEST(Cli, RunAndStudyTakeARelativeTmpdirFromTheCurrentFolder) {
  const std::string dir = temp_dir();
  fs::create_directories(dir + "/t");
  for (const char* command : {"run", "study"}) {
    const test::CommandResult r = run_hexbite({"-q", command, "none.yaml", "-o", "out"},
                                              {"bash", "-c", "cd \"$0\" && TMPDIR=t exec \"$@\"", dir});
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_EQ(r.err.rfind("hexbite: error: ", 0), 0u) << r.err;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "more than hexbite's own line:\n" << r.err;
  }
  EXPECT_FALSE(fs::exists(dir + "/out"));
}

// With HOME unset, a user id without a passwd entry (a container run under an arbitrary uid) crashed Open
// MPI as it started: a segmentation fault in pmix_home_directory, a page of its text, exit 1. Taking on such
// a uid needs root (setpriv).
TEST(Cli, RunAndStudyStartWithoutHomeUnderAUidWithoutAPasswdEntry) {
  const std::string uid = "12345";
  if (geteuid() != 0) GTEST_SKIP() << "needs root to run as a uid without a passwd entry";
  if (getpwuid(std::stoi(uid)) != nullptr) GTEST_SKIP() << "uid " << uid << " has a passwd entry here";
  // A folder that uid can write to, for TMPDIR and the files (the tests' own folders are root's alone).
  std::string tmp = (fs::temp_directory_path() / "hexbite-uid-XXXXXX").string();
  ASSERT_NE(mkdtemp(tmp.data()), nullptr);
  fs::permissions(tmp, fs::perms::all);
  const std::vector<std::string> as_stranger = {
      "setpriv", "--reuid=" + uid, "--regid=" + uid, "--clear-groups", "env", "-u", "HOME", "TMPDIR=" + tmp};
  if (run_hexbite({"--version"}, as_stranger).exit_code != 0) {  // --version starts no MPI
    fs::remove_all(tmp);
    GTEST_SKIP() << "no setpriv, or the program is out of reach of uid " << uid;
  }
  for (const auto& [command, file] :
       std::vector<std::pair<std::string, std::string>>{{"run", "scenario"}, {"study", "study"}}) {
    const test::CommandResult r =
        run_hexbite({"-q", command, tmp + "/none.yaml", "-o", tmp + "/out"}, as_stranger);
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_EQ(r.err, "hexbite: error: " + file + " file '" + tmp +
                         "/none.yaml' does not exist: check the path and the spelling\n");
  }
  std::error_code ec;  // MPI's helper may still be removing its session folder
  fs::remove_all(tmp, ec);
}

// Level counts are counts like --target-hexes: `--levels 1.0` was "not in range 0 to 3", an empty value too,
// and `--levels 0x1` ran one level. Hexadecimal is refused for every count.
TEST(CliBadInput, LevelCountsAreWholeDecimalNumbers) {
  const std::string dir = temp_dir();
  struct Case {
    std::vector<std::string> args;
    std::string fragment;
  };
  const std::vector<Case> cases = {
      {{"run", "s.yaml", "-o", dir + "/o", "--levels", "0x1"},
       "--levels: 0x1 is not a number: give a whole number from 0 to 3"},
      {{"run", "s.yaml", "-o", dir + "/o", "--levels", ""},
       "is not a number: give a whole number from 0 to 3"},
      {{"run", "s.yaml", "-o", dir + "/o", "--levels", "4"},
       "--levels: 4 is out of range: give a whole number from 0 to 3"},
      {{"study", "s.yaml", "-o", dir + "/o", "--levels", "1.5"}, "--levels: 1.5 is not a whole number"},
      {{"refine", "m.vtu", "-o", dir + "/f.vtu", "--levels", "9"},
       "--levels: 9 is out of range: give a whole number from 1 to 4"},
      {{"mesh", "m.stl", "-o", dir + "/m.vtu", "--target-hexes", "0x1000"}, "0x1000 is not a number"},
  };
  for (const Case& c : cases) {
    const auto r = run_hexbite(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.args[0] << "\n" << r.err;
    EXPECT_NE(r.err.find(c.fragment), std::string::npos) << r.err;
  }
  EXPECT_TRUE(fs::is_empty(dir));
}

// Not-a-number and infinite values of real-valued options are input errors (exit 2) that give the range, and
// nothing is written: `mesh --margin nan` crashed (segmentation fault; CLI::Range lets NaN through) and
// `--refine-at nan,0,0` stopped on a floating-point exception.
TEST(CliBadInput, NonFiniteNumbersAreRefused) {
  const std::string dir = temp_dir();
  const std::string cube = write_case("cube.obj", cube_obj());
  struct Case {
    std::vector<std::string> args;
    std::string fragment;
  };
  const std::vector<Case> cases = {
      {{"mesh", cube, "--margin", "nan", "-o", dir + "/m.vtu"},
       "--margin: nan is out of range: give a number from -0.8 to 2"},
      {{"mesh", cube, "--margin", "-inf", "-o", dir + "/m.vtu"}, "--margin: -inf is out of range"},
      {{"mesh", cube, "--margin", "0.1x", "-o", dir + "/m.vtu"}, "--margin: 0.1x is not a number"},
      {{"quad", "from-mandible", cube, "--refine-at", "nan,0,0", "-o", dir + "/q.obj"},
       "--refine-at 'nan,0,0' is not a point: X, Y and Z must be finite numbers in mm"},
      {{"mesh", cube, "--method", "sheets", "--refine-at", "0,inf,0", "-o", dir + "/m.vtu"},
       "--refine-at '0,inf,0' is not a point"},
      // CLI::Range said "Value abc not in range 1.000000 to 30.000000", and something else of nan.
      {{"mesh", cube, "--method", "sheets", "--refine-at", "0,0,0", "--refine-radius", "abc", "-o",
        dir + "/m.vtu"},
       "--refine-radius: abc is not a number: give a number from 1 to 30 (mm)"},
      {{"mesh", cube, "--method", "sheets", "--refine-at", "0,0,0", "--refine-radius", "nan", "-o",
        dir + "/m.vtu"},
       "--refine-radius: nan is out of range: give a number from 1 to 30 (mm)"},
      {{"quad", "from-mandible", cube, "--refine-at", "0,0,0", "--refine-radius", "40", "-o", dir + "/q.obj"},
       "--refine-radius: 40 is out of range: give a number from 1 to 30 (mm)"},
      {{"quad", "from-mandible", cube, "--refine-at", "0,0,0", "--refine-radius", "inf", "-o",
        dir + "/q.obj"},
       "--refine-radius: inf is out of range"},
  };
  for (const Case& c : cases) {
    const auto r = run_hexbite(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.args[2] << "\n" << r.err;
    EXPECT_NE(r.err.find(c.fragment), std::string::npos) << r.err;
  }
  EXPECT_TRUE(fs::is_empty(dir));  // no output and no temporary file
}

// A plate 1 mm thick and 40 x 40 mm across cannot be meshed with about 64 hexes (its cells reach across the
// plate whatever their size): the mesh is written, and a warning says how far its count is from the target
// (before: only "target 64" after the count, silently 5 times off). The JSON is unchanged and alone.
TEST(Cli, HexCountFarFromTheTargetIsWarnedAbout) {
  std::string plate;
  for (int v = 0; v < 8; ++v)
    plate += "v " + std::to_string(40 * (v & 1)) + " " + std::to_string(40 * ((v >> 1) & 1)) + " " +
             std::to_string((v >> 2) & 1) + "\n";
  for (const char* f : kCubeFaces) plate += f;
  const std::string path = write_case("plate.obj", plate);
  const std::string mesh = temp_dir() + "/plate.vtu";
  auto r = run_hexbite({"mesh", path, "--target-hexes", "64", "-o", mesh, "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const long hexes = j["hexes"];
  EXPECT_GT(hexes, 2 * 64);
  EXPECT_NE(r.err.find("hexbite: warning: the mesh has " + std::to_string(hexes) + " hexes, "),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find(" times --target-hexes 64: no cell size tried came closer"), std::string::npos)
      << r.err;
  EXPECT_TRUE(fs::exists(mesh));
  // A mesh near its target (the unit cube at 100 hexes gets 81) has no such warning.
  r = run_hexbite({"mesh", write_case("cube.obj", cube_obj()), "--target-hexes", "100", "-o", mesh});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
}

// --method sheets turns --target-hexes into a quad count for the mandible template (at most 200,000 quads):
// a count that asks for more is named as --target-hexes with the largest one that works, not as
// "--target-quads 206362 is out of range" (an option of quad from-mandible that was never given).
TEST(CliBadInput, SheetsTargetBeyondTheTemplateIsNamedInHexes) {
  const std::string dir = temp_dir();
  const std::string cube = write_case("cube.obj", cube_obj());
  for (const std::string& target : {"5e6", "4770603"}) {
    const auto r =
        run_hexbite({"mesh", cube, "--method", "sheets", "--target-hexes", target, "-o", dir + "/m.vtu"});
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(
        r.err.find("quads, more than the 200,000 of the mandible template: give at most 4770602 hexes with "
                   "--method sheets, or use --method grid"),
        std::string::npos)
        << r.err;
    EXPECT_EQ(r.err.find("--target-quads"), std::string::npos) << r.err;
  }
  // One fewer is a count the template takes: the next check (this unit cube is no mandible) speaks.
  const auto r =
      run_hexbite({"mesh", cube, "--method", "sheets", "--target-hexes", "4770602", "-o", dir + "/m.vtu"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("the mandible template places on mandibles 30 to 300 mm across"), std::string::npos)
      << r.err;
  EXPECT_TRUE(fs::is_empty(dir));
}

// A surface too large for the mandible template was told "check the unit (--units m or cm)" also when read
// in cm, where mm gives a mandible's size, and `quad from-mandible`, which has no --method, to "use --method
// grid".
TEST(CliBadInput, SheetsSizeAdviceNamesTheUnitThatFits) {
  const std::string dir = temp_dir();
  const std::string cube = write_case("cube50.obj", cube_obj_of_side(50));
  const auto mesh = run_hexbite({"mesh", cube, "--method", "sheets", "--units", "cm", "-o", dir + "/m.vtu"});
  EXPECT_EQ(mesh.exit_code, 2) << mesh.err;
  EXPECT_NE(
      mesh.err.find("the surface is 500 mm across (the largest side of its bounding box) with its "
                    "coordinates read as cm, but the mandible template places on mandibles 30 to 300 mm "
                    "across: if the file's coordinates are in mm (50 mm across), give --units mm; or use "
                    "--method grid"),
      std::string::npos)
      << mesh.err;
  const auto quad = run_hexbite({"quad", "from-mandible", cube, "--units", "cm", "-o", dir + "/q.obj"});
  EXPECT_EQ(quad.exit_code, 2) << quad.err;
  EXPECT_NE(quad.err.find("give --units mm; or use hexbite mesh --method grid"), std::string::npos)
      << quad.err;
  // In mm a 5 m cube fits no unit.
  const auto big = run_hexbite(
      {"quad", "from-mandible", write_case("cube5000.obj", cube_obj_of_side(5000)), "-o", dir + "/q.obj"});
  EXPECT_EQ(big.exit_code, 2) << big.err;
  EXPECT_NE(big.err.find("no unit of mm, cm or m gives such a size: scale the file to millimetres first"),
            std::string::npos)
      << big.err;
  EXPECT_TRUE(fs::is_empty(dir));
}

// One hexahedron, the unit cube, as a Gmsh 2.2 mesh: enough for the commands that read a hex mesh.
const char* const kCubeMsh =
    "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n8\n1 0 0 0\n2 1 0 0\n3 1 1 0\n4 0 1 0\n5 0 0 1\n"
    "6 1 0 1\n7 1 1 1\n8 0 1 1\n$EndNodes\n$Elements\n1\n1 5 0 1 2 3 4 5 6 7 8\n$EndElements\n";

// --quiet leaves standard output empty for every command's text report (the exit code tells): `quality`
// printed its whole table under --quiet, unlike surface check, reorder, mesh, refine and run.
TEST(Cli, QuietLeavesStandardOutputEmpty) {
  const std::string dir = temp_dir();
  const std::string cube = write_case("cube.obj", cube_obj());
  const std::string hex = dir + "/cube.msh";
  write_file(hex, kCubeMsh);
  const std::vector<std::vector<std::string>> commands = {
      {"surface", "check", cube},
      {"quality", hex},
      {"quality", hex, "--worst", "1"},
      {"reorder", hex, "-o", dir + "/ordered.vtu"},
      {"quad", "from-mesh", hex, "-o", dir + "/quads.obj"},
      {"quad", "check", dir + "/quads.obj"},
  };
  for (std::vector<std::string> args : commands) {
    args.insert(args.begin(), "--quiet");
    const auto r = run_hexbite(args);
    EXPECT_EQ(r.exit_code, 0) << args[1] << "\n" << r.err;
    EXPECT_TRUE(r.out.empty()) << args[1] << " printed under --quiet:\n" << r.out.substr(0, 400);
  }
}

// A reader that closed standard output early (`| head -1`) killed the program with SIGPIPE: exit 141 and
// no word. The write fails now, and the program says so, as for a full disk behind `> file`.
TEST(Cli, StandardOutputClosedByItsReaderIsAFailedRunThatSaysSo) {
  const std::string dir = temp_dir();
  const std::string hex = dir + "/cube.msh";
  write_file(hex, kCubeMsh);
  // The program starts when the reader (true) has gone.
  const test::CommandResult r = run_hexbite(
      {"quality", hex}, {"bash", "-c", "{ sleep 1; exec \"$@\"; } | true; exit ${PIPESTATUS[0]}", "bash"});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(
      r.err.find("hexbite: failed: cannot write to standard output (a full disk, or the output closed)"),
      std::string::npos)
      << r.err;
}

// On a terminal, a step that failed drew its progress bar at 100 % right above the error ("surface check
// [####...####] 100%", then "hexbite: error: ... truncated"). The bar of a failed step is wiped now; a step
// that completes still ends at 100 %. script(1) gives the program a terminal.
TEST(Cli, AFailedStepDoesNotShowAFullProgressBar) {
  if (std::system("script --version >/dev/null 2>&1") != 0) GTEST_SKIP() << "no script(1) to give a terminal";
  const std::string dir = temp_dir();
  auto on_terminal = [&](const std::string& file) {
    const std::string log = dir + "/log";
    const std::string command = "script -qec \"'" + std::string(HEXBITE_EXE) + "' surface check '" + file +
                                "'\" /dev/null >'" + log + "' 2>&1";
    const int status = std::system(command.c_str());
    return std::make_pair(WIFEXITED(status) ? WEXITSTATUS(status) : -1, read_file(log));
  };
  const auto [bad_code, bad] = on_terminal(write_case("cut.stl", std::string(1000, '\x01')));
  EXPECT_EQ(bad_code, 2) << bad;
  EXPECT_NE(bad.find("hexbite: error: "), std::string::npos) << bad;
  EXPECT_EQ(bad.find("100%"), std::string::npos) << bad;
  const auto [good_code, good] = on_terminal(write_case("cube.obj", cube_obj()));
  EXPECT_EQ(good_code, 0) << good;
  EXPECT_NE(good.find("100%"), std::string::npos) << good;
}

// A progress line that is redrawn wraps on a narrow terminal, and "\r\033[K" clears only its last row: every
// redraw left a row behind (helper K, 50 columns). Redrawn lines are cut to the terminal's width; a
// finished step's line (ending in a newline) is left whole.
TEST(Cli, RedrawnProgressLinesFitANarrowTerminal) {
  if (std::system("script --version >/dev/null 2>&1") != 0) GTEST_SKIP() << "no script(1) to give a terminal";
  const std::string dir = temp_dir();
  const std::string log = dir + "/log";
  const std::string command = "script -qec \"stty cols 50; '" + std::string(HEXBITE_EXE) + "' mesh '" +
                              write_case("cube.obj", cube_obj()) + "' --target-hexes 500 -o '" + dir +
                              "/m.vtu'\" /dev/null >'" + log + "' 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0) << read_file(log);
  const std::string text = read_file(log);
  int redrawn = 0;
  for (std::size_t at = text.find("\r\033[K"); at != std::string::npos; at = text.find("\r\033[K", at + 1)) {
    const std::size_t from = at + 4, to = text.find_first_of("\r\n", from);
    if (to == std::string::npos || text[to] == '\n' || text.compare(to, 2, "\r\n") == 0) continue;  // final
    ++redrawn;
    EXPECT_LE(to - from, 49u) << text.substr(from, to - from);
  }
  EXPECT_GT(redrawn, 0) << text;
}

// With --json, standard output is one JSON document, also without --quiet: `hexbite run ... --json | jq`
// broke on the informational lines (the run's "not resolved: ..." parts) printed before the JSON. Every
// command that has --json, on a small generated mandible and the shipped default scenario.
TEST(Cli, JsonOutputIsOnlyJsonWithoutQuiet) {
  const std::string dir = temp_dir();
  const std::string jaw = dir + "/jaw.stl", landmarks = dir + "/jaw.yaml";
  auto r = run_hexbite({"generate", "mandible", "-o", jaw, "--landmarks", landmarks, "--voxel", "1.5"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // The quad template folds over the coarse (1.5 mm voxel) mandible's ramus (123 pairs of crossing quads,
  // a failed run): the quad commands get the default one.
  const std::string fine = dir + "/fine.stl", fine_landmarks = dir + "/fine.yaml";
  r = run_hexbite({"generate", "mandible", "-o", fine, "--landmarks", fine_landmarks});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::vector<std::vector<std::string>> commands = {
      {"surface", "check", jaw},
      {"surface", "clean", jaw, "-o", dir + "/clean.stl"},
      {"mesh", jaw, "--landmarks", landmarks, "--target-hexes", "1000", "-o", dir + "/grid.vtu"},
      {"quality", dir + "/grid.vtu"},
      {"refine", dir + "/grid.vtu", "--surface", jaw, "-o", dir + "/fine.vtu"},
      {"reorder", dir + "/grid.vtu", "-o", dir + "/ordered.vtu"},
      {"quad", "from-mandible", fine, "--landmarks", fine_landmarks, "-o", dir + "/quads.obj"},
      {"quad", "check", dir + "/quads.obj"},
      {"run", std::string(HEXBITE_SOURCE_DIR) + "/scenarios/lateral_bite_hard_nut.yaml", "-o", dir + "/run",
       "--levels", "0"},
  };
  for (std::vector<std::string> args : commands) {
    args.push_back("--json");
    r = run_hexbite(args);
    EXPECT_EQ(r.exit_code, 0) << args[0] << "\n" << r.err;
    EXPECT_TRUE(nlohmann::json::accept(r.out)) << args[0] << ": standard output is not one JSON document:\n"
                                               << r.out.substr(0, 400);
  }
  // The run's informational lines went to standard error instead.
  EXPECT_NE(r.err.find("mesh.core auto: the swept core"), std::string::npos) << r.err;
}

// File names need not be UTF-8 (Linux allows any bytes, e.g. Latin-1 'é' = 0xe9), but JSON text must be:
// --json failed with nlohmann's "invalid UTF-8 byte" exception (exit 1) after the output was written. The
// bytes are now written as U+FFFD.
TEST(Cli, JsonOutputOfANameThatIsNotUtf8) {
  const std::string dir = temp_dir(), latin1 = dir + "/cube\xe9.obj";
  test::write_file(latin1, cube_obj());
  auto r = run_hexbite({"surface", "check", latin1, "--json"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  ASSERT_TRUE(nlohmann::json::accept(r.out)) << r.out;
  EXPECT_EQ(nlohmann::json::parse(r.out)["file"], dir + "/cube\xef\xbf\xbd.obj");
  r = run_hexbite({"surface", "clean", latin1, "-o", dir + "/clean\xe9.stl", "--json"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(nlohmann::json::accept(r.out)) << r.out;
}

// An option of one value given twice stopped with CLI11's "--levels: At Most 1 required but received 2",
// which names neither what is wrong nor what to do. Now, for every command: which option, and to give it
// once.
TEST(CliBadInput, OptionOfOneValueGivenTwiceIsNamed) {
  const std::string dir = temp_dir();
  const std::string cube = write_case("cube.obj", cube_obj());
  struct Case {
    std::vector<std::string> args;
    std::string message;
  };
  const std::vector<Case> cases = {
      {{"run", dir + "/s.yaml", "-o", dir + "/out", "--levels", "1", "--levels", "2"},
       "--levels was given 2 times; it takes one value: give it once"},
      {{"mesh", cube, "-o", dir + "/a.vtu", "--output", dir + "/b.vtu"},
       "-o,--output was given 2 times; it takes one value: give it once"},
      {{"mesh", cube, "-o", dir + "/a.vtu", "--target-hexes", "100", "--target-hexes", "200",
        "--target-hexes", "300"},
       "--target-hexes was given 3 times; it takes one value: give it once"},
      {{"surface", "check", cube, "--units", "mm", "--units", "m"},
       "--units was given 2 times; it takes one value: give it once"},
  };
  for (const Case& c : cases) {
    const auto r = run_hexbite(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.args[0] << "\n" << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("At Most"), std::string::npos) << r.err;
  }
  EXPECT_TRUE(fs::is_empty(dir));
}

// `--export inp` given twice (a script adding it to a command line that has it) stopped with CLI11's
// "--export: At Most 1 required but received 2". The exports are a set: a repeat is accepted, a format other
// than inp is still refused with what is allowed.
TEST(CliBadInput, RepeatedExportIsAcceptedAndAnUnknownFormatNamed) {
  const std::string dir = temp_dir();
  const std::string missing = dir + "/missing.yaml";
  auto r = run_hexbite({"run", missing, "-o", dir + "/out", "--export", "inp", "--export", "inp"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(r.err.find("At Most"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(missing), std::string::npos) << r.err;  // parsed; the scenario is what is missing
  r = run_hexbite({"run", missing, "-o", dir + "/out", "--export", "inp", "--export", "vtk"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--export"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("unknown format 'vtk': the one format is inp (CalculiX)"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("inp"), std::string::npos) << r.err;
  // The scenario is not taken as a second format.
  r = run_hexbite({"run", "--export", "inp", missing, "-o", dir + "/out"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find(missing), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("not in"), std::string::npos) << r.err;
}

// A mistyped command said only "A subcommand is required". Now the unknown word is named, with the
// commands of that level and where to read about them.
TEST(CliBadInput, MistypedCommandIsNamed) {
  auto r = run_hexbite({"rnu", "x.yaml"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("unknown command 'rnu'"), std::string::npos) << r.err;
  for (const char* command : {"surface", "generate", "mesh", "run", "quality", "refine"})
    EXPECT_NE(r.err.find(command), std::string::npos) << command << " missing in\n" << r.err;
  EXPECT_NE(r.err.find("(hexbite --help)"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("A subcommand is required"), std::string::npos) << r.err;

  r = run_hexbite({"surface", "nosuch"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("unknown command 'surface nosuch'"), std::string::npos) << r.err;
  for (const char* command : {"check", "clean", "from-ct"})
    EXPECT_NE(r.err.find(command), std::string::npos) << command << " missing in\n" << r.err;
  EXPECT_NE(r.err.find("(hexbite surface --help)"), std::string::npos) << r.err;

  // Options before the word do not hide it; no word at all still asks for a command.
  r = run_hexbite({"--quiet", "mseh"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("unknown command 'mseh'"), std::string::npos) << r.err;
  r = run_hexbite({});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("hexbite --help"), std::string::npos) << r.err;
  // An option where the command should be: its value is no command.
  r = run_hexbite({"surface", "--units", "m"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("a command is required before '--units'"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("unknown command"), std::string::npos) << r.err;
}

// --help after a mistyped command printed the top-level help, exit 0, as if the command existed; the help
// of a command that exists, and of a level without its command, is still printed.
TEST(CliBadInput, MistypedCommandIsNamedWithHelpToo) {
  auto r = run_hexbite({"rnu", "--help"});
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("unknown command 'rnu'; the commands are: surface,"), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "");
  r = run_hexbite({"surface", "nosuch", "--help"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("unknown command 'surface nosuch'"), std::string::npos) << r.err;
  for (const std::vector<std::string>& args :
       std::vector<std::vector<std::string>>{{"--help"}, {"surface", "--help"}, {"run", "--help"}}) {
    r = run_hexbite(args);
    EXPECT_EQ(r.exit_code, 0) << args.front() << "\n" << r.err;
    EXPECT_NE(r.out.find("Usage"), std::string::npos) << r.out;
  }
}

// A file whose name starts with '-' was read as an option: "MESH is required". The message names the file
// and how to give it; the same word that is no file is still an unknown option.
TEST(CliBadInput, AFileNamedLikeAnOptionIsNamed) {
  const std::string dir = temp_dir();
  write_file(dir + "/-m.vtu", "x");
  const std::vector<std::string> in_dir = {"bash", "-c", "cd \"$0\" && exec \"$@\"", dir};
  auto r = run_hexbite({"quality", "-m.vtu"}, in_dir);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("'-m.vtu' was read as an option, but it is a file: give it as './-m.vtu', or put "
                       "'--' before it"),
            std::string::npos)
      << r.err;
  r = run_hexbite({"quality", "-n.vtu"}, in_dir);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(r.err.find("was read as an option"), std::string::npos) << r.err;
  // A name that starts like a short option of the command was split into it (helper U): `refine
  // -out.vtu -o f.vtu` read -o 'ut.vtu' and said "-o,--output was given 2 times"; `surface check -old.stl`
  // said "FILE is required"; `mesh -old.stl -o m.vtu` said "--output: 'ld.stl': this command writes ...".
  write_file(dir + "/-out.vtu", "x");
  write_file(dir + "/-old.stl", "x");
  for (const std::vector<std::string>& args : {std::vector<std::string>{"refine", "-out.vtu", "-o", "f.vtu"},
                                               std::vector<std::string>{"surface", "check", "-old.stl"},
                                               std::vector<std::string>{"mesh", "-old.stl", "-o", "m.vtu"}}) {
    r = run_hexbite(args, in_dir);
    EXPECT_EQ(r.exit_code, 2) << args[0] << ": " << r.err;
    EXPECT_NE(
        r.err.find("'" + args[args[0] == "surface" ? 2 : 1] + "' was read as an option, but it is a file"),
        std::string::npos)
        << args[0] << ": " << r.err;
  }
  // The value of an option that takes one is no such file: the unknown option is what is wrong.
  r = run_hexbite({"mesh", "./-old.stl", "-o", "-out.vtu", "--bogus"}, in_dir);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--bogus"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("was read as an option"), std::string::npos) << r.err;
}

// Inputs that are no regular file: a named pipe or /dev/zero was read without end (the memory grew by
// hundreds of MB a second, or the command hung), and a folder or a pipe got the wrong message ("no such
// file", "cannot read scenario file", a damaged file). Each reader now says what the input is, at once;
// `timeout` ends the old behaviour as a failure.
TEST(CliBadInput, InputsThatAreNoRegularFileAreRefusedAtOnce) {
  const std::string dir = temp_dir();
  const std::string cube = dir + "/cube.obj";
  write_file(cube, cube_obj());
  ASSERT_EQ(run_hexbite({"-q", "mesh", cube, "--target-hexes", "8", "-o", dir + "/m.vtu"}).exit_code, 0);
  for (const char* name : {"p.vtu", "p.yaml", "p.mha", "p.stl"})
    ASSERT_EQ(::mkfifo((dir + "/" + name).c_str(), 0600), 0) << name;
  for (const char* name : {"z.msh", "z.yaml", "z.mha"}) fs::create_symlink("/dev/zero", dir + "/" + name);
  fs::create_directories(dir + "/rz");
  fs::create_symlink("/dev/zero", dir + "/rz/results.json");
  for (const char* name : {"d.vtu", "d.yaml"}) fs::create_directories(dir + "/" + name);
  const std::string fifo = "is a named pipe (a FIFO, or a shell's <(...)), not a regular file";
  const std::string device = "is a device, not a regular file: give a file";
  const std::string folder = "is a folder, not a file: give a file";
  struct Case {
    std::vector<std::string> args;
    std::string fragment;
  };
  const std::string out = dir + "/out";
  const std::vector<Case> cases = {
      {{"quality", dir + "/p.vtu"}, "hex mesh file '" + dir + "/p.vtu' " + fifo},
      {{"quality", dir + "/z.msh"}, "Gmsh mesh file '" + dir + "/z.msh' " + device},
      {{"refine", dir + "/z.msh", "-o", out + ".vtu"}, device},
      {{"reorder", dir + "/p.vtu", "-o", out + ".vtu"}, fifo},
      {{"run", dir + "/p.yaml", "-o", out}, "scenario file '" + dir + "/p.yaml' " + fifo},
      {{"run", dir + "/z.yaml", "-o", out}, device},
      {{"run", dir + "/d.yaml", "-o", out}, "scenario file '" + dir + "/d.yaml' " + folder},
      {{"study", dir + "/p.yaml", "-o", out}, "study file '" + dir + "/p.yaml' " + fifo},
      {{"study", dir + "/z.yaml", "-o", out}, device},
      {{"report", dir + "/rz", "-o", out + ".html", "--no-pictures"},
       "results file '" + dir + "/rz/results.json' " + device},
      {{"reorder", dir + "/m.vtu", "--landmarks", dir + "/p.yaml", "-o", out + ".vtu"},
       "landmark file '" + dir + "/p.yaml' " + fifo},
      {{"mesh", cube, "--landmarks", dir + "/p.yaml", "-o", out + ".vtu"}, fifo},
      {{"quad", "from-mandible", cube, "--landmarks", dir + "/p.yaml", "-o", out + ".obj"}, fifo},
      {{"surface", "from-ct", dir + "/z.mha", "--threshold", "600", "-o", out + ".stl"},
       "volume file '" + dir + "/z.mha' " + device},
      {{"surface", "from-ct", dir + "/p.mha", "--threshold", "600", "-o", out + ".stl"}, fifo},
      {{"surface", "check", dir + "/p.stl"}, "surface file '" + dir + "/p.stl' " + fifo},
      {{"render", dir + "/d.vtu", "-o", out + ".png"}, "mesh file '" + dir + "/d.vtu' " + folder},
  };
  for (const Case& c : cases) {
    const auto r = run_hexbite(c.args, {"timeout", "20"});
    EXPECT_EQ(r.exit_code, 2) << c.args[0] << " " << c.args[1] << "\n" << r.err;
    EXPECT_NE(r.err.find(c.fragment), std::string::npos) << c.args[0] << "\n" << r.err;
  }
  EXPECT_FALSE(fs::exists(out));
}

// An output path with a file where a folder is needed said "folder 'm.vtu' does not exist; create it
// first", and a path longer than the system takes (PATH_MAX) said the folder does not exist, or failed after
// the whole run ("File name too long"): both are named when the command line is read.
TEST(CliBadInput, OutputPathsThroughAFileOrTooLongAreNamed) {
  const std::string dir = temp_dir();
  const std::string cube = dir + "/cube.obj";
  write_file(cube, cube_obj());
  std::string deep = dir;
  for (int i = 0; i < 20; ++i) deep += "/" + std::string(240, 'd');
  struct Case {
    std::vector<std::string> args;
    std::string fragment;
  };
  const std::vector<Case> cases = {
      {{"reorder", dir + "/m.vtu", "-o", cube + "/x.vtu"}, "'" + cube + "' is a file, not a folder"},
      {{"mesh", cube, "-o", cube + "/sub/m.vtu"}, "'" + cube + "' is a file, not a folder"},
      {{"generate", "mandible", "-o", cube + "/g.stl"}, "'" + cube + "' is a file, not a folder"},
      {{"reorder", dir + "/m.vtu", "-o", deep + "/x.vtu"}, "a path may have (PATH_MAX): give a shorter path"},
      {{"run", "scenario.yaml", "-o", deep}, "a path may have (PATH_MAX): give a shorter path"},
      {{"generate", "mandible", "-o", dir + "/g.stl", "--dicom", deep}, "(PATH_MAX)"},
  };
  for (const Case& c : cases) {
    const auto r = run_hexbite(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.args[0] << "\n" << r.err;
    EXPECT_NE(r.err.find(c.fragment), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("does not exist"), std::string::npos) << r.err;
  }
}

}  // namespace
}  // namespace hexbite
