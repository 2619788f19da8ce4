// `hexbite render`: pictures of surfaces and of solution fields, and a clear refusal without a display.
#include <gtest/gtest.h>

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
}

}  // namespace
}  // namespace hexbite
