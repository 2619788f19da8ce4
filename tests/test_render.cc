// `hexbite render`: pictures of surfaces and of solution fields, and a clear refusal without a display.
#include <gtest/gtest.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "tests/test_util.h"

namespace hexbite {
namespace {

namespace fs = std::filesystem;
using test::read_file;
using test::run_hexbite;
using test::temp_dir;

// Runs `hexbite ARGS` through the shell with the given prefix (e.g. "env -u DISPLAY"); returns the exit code.
int run_with_prefix(const std::string& prefix, const std::string& args, const std::string& log) {
  const std::string cmd = prefix + " '" + std::string(HEXBITE_EXE) + "' " + args + " >'" + log + "' 2>&1";
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// A display for the rendering tests: the caller's, or a virtual one from xvfb-run (scripts/test.sh
// provides one already; this keeps a plain `ctest` working too).
std::string display_prefix() {
  return std::getenv("DISPLAY") != nullptr ? "" : "xvfb-run -a";
}

// Width and height from a PNG's IHDR chunk (big-endian at bytes 16 and 20).
std::pair<int, int> png_size(const std::string& bytes) {
  auto be32 = [&](std::size_t at) {
    return (static_cast<unsigned char>(bytes[at]) << 24) | (static_cast<unsigned char>(bytes[at + 1]) << 16) |
           (static_cast<unsigned char>(bytes[at + 2]) << 8) | static_cast<unsigned char>(bytes[at + 3]);
  };
  return {be32(16), be32(20)};
}

TEST(Render, SurfaceAndSolutionFieldPictures) {
  const std::string dir = temp_dir();
  ASSERT_EQ(run_hexbite({"-q", "generate", "mandible", "-o", dir + "/jaw.stl", "--variant", "atrophic",
                         "--voxel", "1.5"})
                .exit_code,
            0);
  ASSERT_EQ(run_with_prefix(display_prefix(),
                            "render '" + dir + "/jaw.stl' -o '" + dir + "/jaw.png' --width 320 --height 200",
                            dir + "/log1"),
            0)
      << read_file(dir + "/log1");
  const std::string png = read_file(dir + "/jaw.png");
  ASSERT_GT(png.size(), 24u);
  EXPECT_EQ(png.substr(1, 3), "PNG");
  EXPECT_EQ(png_size(png), std::make_pair(320, 200));

  // A mesh coloured by a field that it does not have: exit 2 naming the arrays it does have.
  ASSERT_EQ(run_hexbite({"-q", "mesh", dir + "/jaw.stl", "--method", "grid", "--target-hexes", "300", "-o",
                         dir + "/jaw.vtu"})
                .exit_code,
            0);
  EXPECT_EQ(run_with_prefix(display_prefix(),
                            "render '" + dir + "/jaw.vtu' --field no_such_field -o '" + dir + "/f.png'",
                            dir + "/log2"),
            2);
  EXPECT_NE(read_file(dir + "/log2")
                .find("no point or cell array 'no_such_field'; available: scaled_jacobian (per "
                      "hex), condition (per hex)"),
            std::string::npos)
      << read_file(dir + "/log2");
  EXPECT_FALSE(fs::exists(dir + "/f.png"));
  // The per-hex quality arrays that hexbite mesh writes colour the picture too (before: "no point array
  // 'scaled_jacobian'; available: none").
  EXPECT_EQ(run_with_prefix(display_prefix(),
                            "render '" + dir + "/jaw.vtu' --field scaled_jacobian -o '" + dir +
                                "/sj.png' --width 320 --height 200",
                            dir + "/log3"),
            0)
      << read_file(dir + "/log3");
  EXPECT_EQ(png_size(read_file(dir + "/sj.png")), std::make_pair(320, 200));
  // A top of the colour scale below every value: refused (it gave an inverted table, VTK's coloured errors
  // and a legend of 0 to 1, exit 0).
  EXPECT_EQ(run_with_prefix(display_prefix(),
                            "render '" + dir + "/jaw.vtu' --field scaled_jacobian --max 0.01 -o '" + dir +
                                "/low.png' --width 320 --height 200",
                            dir + "/log4"),
            2);
  const std::string log4 = read_file(dir + "/log4");
  EXPECT_NE(log4.find("the colour scale's top, 0.01, is not above the smallest value of 'scaled_jacobian'"),
            std::string::npos)
      << log4;
  EXPECT_EQ(log4.find("Bad table range"), std::string::npos) << log4;
  EXPECT_FALSE(fs::exists(dir + "/low.png"));
}

// Pixels of the object, neither background (white) nor text (grey: the legend's title reaches left of its
// bar), in the part of the picture left of `share` of its width (the rest is the colour legend's): on the
// outermost two rows and columns of that part, and in all of it.
struct ObjectPixels {
  int on_border = 0, all = 0;
};
ObjectPixels object_pixels(const std::string& png, double share = 1.0) {
  vtkNew<vtkPNGReader> reader;
  reader->SetFileName(png.c_str());
  reader->Update();
  vtkImageData* image = reader->GetOutput();
  int dims[3];
  image->GetDimensions(dims);
  const int width = static_cast<int>(share * dims[0]);
  ObjectPixels count;
  for (int y = 0; y < dims[1]; ++y)
    for (int x = 0; x < width; ++x) {
      double rgb[3];
      for (int c = 0; c < 3; ++c) rgb[c] = image->GetScalarComponentAsDouble(x, y, 0, c);
      if (rgb[0] + rgb[1] + rgb[2] >= 3 * 255 - 30 || (rgb[0] == rgb[1] && rgb[1] == rgb[2])) continue;
      ++count.all;
      if (x <= 1 || x >= width - 2 || y <= 1 || y >= dims[1] - 2) ++count.on_border;
    }
  return count;
}

// The whole object is in the picture: a tall box seen from the front in a landscape picture, and the jaw in
// a portrait one, used to run off the top and bottom, or the sides (a fixed zoom after VTK's ResetCamera).
// In a tall narrow picture (200 x 1200) the jaw was cut at both sides, or missing altogether, leaving the
// legend alone (the zoom divided the view angle, which overshot at the wide angles such a shape needs).
TEST(Render, TheWholeObjectIsInThePicture) {
  const std::string dir = temp_dir();
  test::write_file(dir + "/tall.obj",
                   "v 0 0 0\nv 10 0 0\nv 10 10 0\nv 0 10 0\nv 0 0 60\nv 10 0 60\nv 10 10 60\nv 0 10 60\n"
                   "f 1 4 3\nf 1 3 2\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\nf 3 4 8\n"
                   "f 3 8 7\nf 4 1 5\nf 4 5 8\n");
  ASSERT_EQ(run_hexbite({"-q", "generate", "mandible", "-o", dir + "/jaw.stl", "--voxel", "1.5"}).exit_code,
            0);
  ASSERT_EQ(run_hexbite({"-q", "mesh", dir + "/jaw.stl", "--method", "grid", "--target-hexes", "300", "-o",
                         dir + "/jaw.vtu"})
                .exit_code,
            0);
  struct Case {
    std::string input, options;
  };
  for (const Case& c :
       {Case{"tall.obj", "--view front"}, Case{"tall.obj", "--view iso"},
        Case{"jaw.stl", "--view front --width 300 --height 600"},
        Case{"jaw.stl", "--view top --width 300 --height 600"},
        Case{"jaw.stl", "--view top --width 200 --height 1200"}, Case{"jaw.stl", "--width 200 --height 1200"},
        Case{"jaw.vtu", "--view top --width 200 --height 1200 --field scaled_jacobian"},
        Case{"jaw.vtu", "--width 100 --height 2000 --field scaled_jacobian"},
        Case{"jaw.stl", "--view side --width 2000 --height 64"}}) {
    ASSERT_EQ(run_with_prefix(display_prefix(),
                              "render '" + dir + "/" + c.input + "' -o '" + dir + "/p.png' " + c.options,
                              dir + "/log"),
              0)
        << read_file(dir + "/log");
    // Left of the legend, which starts at 0.82 of the width, when there is one.
    const ObjectPixels pixels =
        object_pixels(dir + "/p.png", c.options.find("--field") != std::string::npos ? 0.82 : 1.0);
    EXPECT_EQ(pixels.on_border, 0) << c.input << " " << c.options;
    EXPECT_GT(pixels.all, 0) << c.input << " " << c.options;
  }
}

// An array of several components is coloured by the one --component picks; without it only the
// displacement is drawn (by its magnitude), and any other such array is refused naming its components and the
// arrays of one. Before, `--field stress` was coloured by sqrt(xx^2 + yy^2 + zz^2 + xy^2 + yz^2 + xz^2),
// which is no stress measure, and `--field principal_stress` by a norm that lost every sign.
TEST(Render, AnArrayOfSeveralComponentsNeedsAComponent) {
  const std::string dir = temp_dir(), vtu = dir + "/hex.vtu", png = dir + "/p.png";
  test::write_file(
      vtu,
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" "
      "byte_order=\"LittleEndian\">\n"
      "<UnstructuredGrid><Piece NumberOfPoints=\"8\" NumberOfCells=\"1\">\n"
      "<PointData><DataArray type=\"Float64\" Name=\"displacement\" NumberOfComponents=\"3\" "
      "format=\"ascii\">"
      "0 0 0 1 0 0 1 1 0 0 1 0 0 0 1 1 0 1 1 1 1 0 1 1</DataArray>\n"
      "<DataArray type=\"Float64\" Name=\"von_mises\" format=\"ascii\">1 2 3 4 5 6 7 "
      "8</DataArray></PointData>\n"
      "<CellData><DataArray type=\"Float64\" Name=\"stress\" NumberOfComponents=\"6\" format=\"ascii\">"
      "-9 2 3 4 5 6</DataArray>\n"
      "<DataArray type=\"Float64\" Name=\"principal_stress\" NumberOfComponents=\"3\" "
      "ComponentName0=\"largest\" "
      "ComponentName1=\"middle\" ComponentName2=\"smallest\" format=\"ascii\">12 -1 "
      "-14</DataArray></CellData>\n"
      "<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">"
      "0 0 0 10 0 0 10 10 0 0 10 0 0 0 10 10 0 10 10 10 10 0 10 10</DataArray></Points>\n"
      "<Cells><DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">0 1 2 3 4 5 6 7</DataArray>\n"
      "<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">8</DataArray>\n"
      "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">12</DataArray></Cells>\n"
      "</Piece></UnstructuredGrid></VTKFile>\n");
  struct Case {
    std::string options, fragment;
  };
  const std::vector<Case> refused = {
      {"--field stress",
       "'stress' in '" + vtu +
           "' has 6 components (0, 1, 2, 3, 4, 5): pick one with --component N, or colour by an array of one "
           "component: von_mises"},
      {"--field principal_stress", "has 3 components (0 largest, 1 middle, 2 smallest): pick one"},
      {"--field stress --component 6",
       "--component 6 is not a component of 'stress' in '" + vtu + "', which has 6 (0, 1, 2, 3, 4, 5)"},
      {"--field von_mises --component 0", "'von_mises' in '" + vtu + "' has one component: drop --component"},
      {"--component 1", "--component picks a component of the array of --field, and no --field is given"},
  };
  for (const Case& c : refused) {
    EXPECT_EQ(
        run_with_prefix(display_prefix(), "render '" + vtu + "' -o '" + png + "' " + c.options, dir + "/log"),
        2)
        << c.options << "\n"
        << read_file(dir + "/log");
    EXPECT_NE(read_file(dir + "/log").find(c.fragment), std::string::npos) << read_file(dir + "/log");
    EXPECT_FALSE(fs::exists(png)) << c.options;
  }
  for (const std::string options : {"--field stress --component 0", "--field principal_stress --component 2",
                                    "--field displacement", "--field displacement --component 2"}) {
    EXPECT_EQ(run_with_prefix(display_prefix(),
                              "render '" + vtu + "' -o '" + png + "' --width 320 --height 200 " + options,
                              dir + "/log"),
              0)
        << options << "\n"
        << read_file(dir + "/log");
    EXPECT_EQ(read_file(dir + "/log").find("ERR"), std::string::npos) << read_file(dir + "/log");
    EXPECT_TRUE(fs::exists(png)) << options;
    fs::remove(png);
  }
}

// A cut-off VTU: one error line with VTK's explanation in it, not VTK's own coloured multi-line log.
TEST(Render, DamagedMeshIsOneCleanError) {
  const std::string dir = temp_dir();
  ASSERT_EQ(run_hexbite({"-q", "generate", "mandible", "-o", dir + "/jaw.stl", "--voxel", "1.5"}).exit_code,
            0);
  ASSERT_EQ(run_hexbite({"-q", "mesh", dir + "/jaw.stl", "--method", "grid", "--target-hexes", "300", "-o",
                         dir + "/jaw.vtu"})
                .exit_code,
            0);
  const std::string vtu = read_file(dir + "/jaw.vtu");
  test::write_file(dir + "/cut.vtu", vtu.substr(0, 300));
  EXPECT_EQ(run_with_prefix(display_prefix(), "render '" + dir + "/cut.vtu' -o '" + dir + "/cut.png'",
                            dir + "/log"),
            2);
  const std::string log = read_file(dir + "/log");
  EXPECT_NE(log.find("cannot read '" + dir + "/cut.vtu'"), std::string::npos) << log;
  EXPECT_NE(log.find("(VTK: Error parsing XML"), std::string::npos) << log;
  EXPECT_EQ(log.find("vtkXMLParser"), std::string::npos) << log;
  EXPECT_EQ(log.find("\x1b["), std::string::npos) << log;  // no terminal colour codes
  EXPECT_FALSE(fs::exists(dir + "/cut.png"));
}

// Options that the input would ignore, a .vtu named in capitals, non-finite --max values and a --title
// that is not one line of UTF-8: exit 2 before anything is read or a display is needed. Before: `--field` on
// a surface and `--max` without `--field` were silently ignored, `--max nan` too, `--max inf` was refused
// with a 309-digit bound, and `MESH.VTU` was read as a surface ("unknown extension '.vtu'; accepted surface
// formats are .stl, ...").
TEST(Render, OptionsTheInputIgnoresAreRefused) {
  const std::string dir = temp_dir();
  test::write_file(dir + "/cube.obj", test::cubes_obj(1));
  test::write_file(dir + "/cube.msh",
                   "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n8\n1 0 0 0\n2 1 0 0\n3 1 1 0\n4 0 1 0\n"
                   "5 0 0 1\n6 1 0 1\n7 1 1 1\n8 0 1 1\n$EndNodes\n$Elements\n1\n1 5 0 1 2 3 4 5 6 7 8\n"
                   "$EndElements\n");
  ASSERT_EQ(run_hexbite({"-q", "reorder", dir + "/cube.msh", "-o", dir + "/CUBE.VTU"}).exit_code, 0);
  const std::string png = dir + "/p.png";
  struct Case {
    std::vector<std::string> args;
    std::string fragment;
  };
  const std::vector<Case> cases = {
      {{"render", dir + "/cube.obj", "--field", "von_mises", "-o", png},
       "--field colours a mesh or solution (.vtu) by one of its arrays, but '" + dir +
           "/cube.obj' is a surface, which has none"},
      {{"render", dir + "/CUBE.VTU", "--max", "10", "-o", png},
       "--max caps the colour scale of --field, and no --field is given"},
      {{"render", dir + "/CUBE.VTU", "--units", "m", "-o", png}, "--units gives the unit of a surface input"},
      {{"render", dir + "/cube.msh", "-o", png},
       "unknown extension '.msh'; render reads a surface (.stl, .obj, .ply, .off, .vtp) or a hex mesh"},
      {{"render", dir + "/CUBE.VTU", "--field", "no_such", "-o", png}, "no point or cell array 'no_such'"},
      {{"render", dir + "/CUBE.VTU", "--field", "scaled_jacobian", "--max", "nan", "-o", png},
       "--max: nan is out of range: give a number greater than 0"},
      {{"render", dir + "/CUBE.VTU", "--field", "scaled_jacobian", "--max", "inf", "-o", png},
       "--max: inf is out of range: give a number greater than 0"},
      {{"render", dir + "/CUBE.VTU", "--field", "scaled_jacobian", "--max", "0", "-o", png},
       "--max: 0 is out of range"},
      // Counts: "Value abc not in range 64 to 8192" before, and the same of 1e4.
      {{"render", dir + "/cube.obj", "--width", "abc", "-o", png},
       "--width: abc is not a number: give a whole number from 64 to 8,192"},
      {{"render", dir + "/cube.obj", "--height", "1e4", "-o", png}, "--height: 1e4 is out of range"},
      // A caption VTK cannot draw: it was dropped from the picture, with VTK's errors, and exit 0.
      {{"render", dir + "/cube.obj", "--title", "r\xe9sum\xe9", "-o", png},
       "--title: the title is not valid UTF-8 (byte 0xE9 at position 2)"},
      {{"render", dir + "/cube.obj", "--title", "a\x1b[1m", "-o", png},
       "--title: the title holds a control character (0x1B)"},
  };
  for (const Case& c : cases) {
    const auto r = run_hexbite(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.args[1] << "\n" << r.err;
    EXPECT_NE(r.err.find(c.fragment), std::string::npos) << r.err;
  }
  EXPECT_FALSE(fs::exists(png));
}

// A picture that cannot be written: in a folder that takes no new files (/proc, also for root) it is refused
// when the command line is read; a write that fails on the way (a full disk, here a file size limit) is one
// line and leaves no file. Before: VTK's coloured log ("Unable to open file ...", then "Ran out of disk
// space") and then only "cannot write '/proc/...png'"; later libpng's "Write Error" lines beside ours.
TEST(Render, AnUnwritablePictureIsOneCleanError) {
  const std::string dir = temp_dir();
  test::write_file(dir + "/cube.obj", test::cubes_obj(1));
  const std::string in_proc = "/proc/hexbite_no_such_picture.png";
  EXPECT_EQ(run_with_prefix(display_prefix(),
                            "render '" + dir + "/cube.obj' -o " + in_proc + " --width 64 --height 64",
                            dir + "/log"),
            2);
  std::string log = read_file(dir + "/log");
  EXPECT_NE(log.find("cannot write '" + in_proc + "': no file can be made in '/proc'"), std::string::npos)
      << log;

  const std::string png = dir + "/full.png";
  EXPECT_EQ(run_with_prefix(display_prefix() + " bash -c 'trap \"\" XFSZ; ulimit -f 1; exec \"$@\"' bash",
                            "render '" + dir + "/cube.obj' -o '" + png + "' --width 400 --height 300",
                            dir + "/log"),
            1);
  log = read_file(dir + "/log");
  EXPECT_EQ(log,
            "hexbite: failed: cannot write '" + png +
                "': the disk is full or the file passed a size limit (ulimit -f): make room on the disk or "
                "choose another output folder\n");         // no libpng lines
  EXPECT_EQ(log.find("\x1b["), std::string::npos) << log;  // no terminal colour codes
  EXPECT_FALSE(fs::exists(png));
}

TEST(Render, WithoutDisplayFailsClearlyAndWritesNothing) {
  const std::string dir = temp_dir();
  ASSERT_EQ(run_hexbite({"-q", "generate", "mandible", "-o", dir + "/jaw.stl", "--voxel", "1.5"}).exit_code,
            0);
  const int code = run_with_prefix("env -u DISPLAY", "render '" + dir + "/jaw.stl' -o '" + dir + "/jaw.png'",
                                   dir + "/log");
  EXPECT_EQ(code, 1);
  EXPECT_NE(read_file(dir + "/log").find("no X display"), std::string::npos) << read_file(dir + "/log");
  EXPECT_NE(read_file(dir + "/log").find("xvfb-run -a"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir + "/jaw.png"));
  // A DISPLAY whose X server is gone (a closed ssh session): VTK aborted (exit 134).
  EXPECT_EQ(run_with_prefix("env DISPLAY=:1999", "render '" + dir + "/jaw.stl' -o '" + dir + "/jaw.png'",
                            dir + "/log"),
            1);
  EXPECT_NE(read_file(dir + "/log")
                .find("no X display (the X display ':1999' does not answer); run the "
                      "command under `xvfb-run -a`"),
            std::string::npos)
      << read_file(dir + "/log");
  EXPECT_FALSE(fs::exists(dir + "/jaw.png"));
}

// A display that answers but cannot give an OpenGL context: VTK aborted on it (exit 134, "Could not find a
// decent config") without a word of hexbite's. Now it is refused as a display that does not answer is.
// Indirect GLX (LIBGL_ALWAYS_INDIRECT=1, set by ssh -X users; X servers refuse it) passed the GLX checks and
// VTK aborted all the same ("Cannot create GLX context. Aborting.", exit 134): now a context is made first.
TEST(Render, ADisplayWithoutOpenGlFailsClearlyAndWritesNothing) {
  const std::string dir = temp_dir(), png = dir + "/cube.png";
  test::write_file(dir + "/cube.obj", test::cubes_obj(1));
  struct Case {
    std::vector<std::string> options;
    std::string environment, fragment;
  };
  for (const Case& c :
       {Case{{"-extension", "GLX"}, "", "has no OpenGL: its X server lacks the GLX extension"},
        Case{{"-screen", "0", "640x480x8"}, "", "has no OpenGL: "},
        Case{{}, "LIBGL_ALWAYS_INDIRECT=1", "has no usable OpenGL: no OpenGL context could be made"}}) {
    const test::VirtualDisplay x(c.options);
    if (x.display().empty()) GTEST_SKIP() << "no X server for this test: " << x.problem();
    EXPECT_EQ(run_with_prefix("env DISPLAY=" + x.display() + " " + c.environment,
                              "render '" + dir + "/cube.obj' -o '" + png + "'", dir + "/log"),
              1);
    const std::string log = read_file(dir + "/log");
    EXPECT_NE(log.find("no X display (the X display '" + x.display() + "' " + c.fragment), std::string::npos)
        << log;
    EXPECT_NE(log.find("); run the command under `xvfb-run -a`"), std::string::npos) << log;
    EXPECT_FALSE(fs::exists(png));
  }
}

}  // namespace
}  // namespace hexbite
