#include "postprocess/report_pictures.h"

#include <stdlib.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <vector>

#include "common/atomic_file.h"
#include "common/error.h"
#include "postprocess/render.h"
#include "postprocess/report_format.h"

namespace hexbite {

namespace {

// What to do when the pictures cannot be drawn under TMPDIR.
constexpr const char* kTmpdirAdvice = "point TMPDIR at a folder you can write to, or give --no-pictures";

// A fresh folder under the system's temporary folder, removed with everything in it when this goes.
class TemporaryFolder {
 public:
  TemporaryFolder() {
    // TMPDIR naming a missing folder or a file gave the library's own text ("filesystem error:
    // temp_directory_path: No such file or directory"). Bad input (exit 2), as for run and study, which
    // refuse such a TMPDIR before MPI starts.
    std::error_code ec;
    const std::filesystem::path base = std::filesystem::temp_directory_path(ec);
    const char* tmpdir = std::getenv("TMPDIR");
    if (ec)
      throw InputError("cannot make a temporary folder for the report's pictures: TMPDIR is '" +
                       std::string(tmpdir ? tmpdir : "") + "' (" + ec.message() + "); " + kTmpdirAdvice);
    std::string name = (base / "hexbite-report-XXXXXX").string();
    if (mkdtemp(name.data()) == nullptr)
      throw InputError("cannot make a temporary folder for the report's pictures in '" + base.string() +
                       "' (" + std::strerror(errno) + "); " + kTmpdirAdvice);
    place_ = (tmpdir && *tmpdir ? "TMPDIR '" : "'") + base.string() + "'";
    path_ = name;
    // Ctrl-C or SIGTERM during the rendering left the folder and its pictures behind (helper P).
    guards_.push_back(std::make_unique<RemovedOnSignal>(path_, RemovedOnSignal::kFolder));
  }
  ~TemporaryFolder() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TemporaryFolder(const TemporaryFolder&) = delete;
  TemporaryFolder& operator=(const TemporaryFolder&) = delete;
  // The path of a file `name` in the folder, removed with it also on a signal.
  std::string file(const std::string& name) {
    const std::string path = path_ + "/" + name;
    guards_.push_back(std::make_unique<RemovedOnSignal>(path));
    return path;
  }
  // The folder it was made in, for messages: "TMPDIR '/scratch'", or "'/tmp'".
  const std::string& place() const { return place_; }

 private:
  std::string place_;
  std::string path_;
  std::vector<std::unique_ptr<RemovedOnSignal>> guards_;
};

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  if (!in) throw RunError("cannot read the rendered picture '" + path + "'");
  return bytes.str();
}

// The pictures must show the run whose figures the report prints: a solution.vtu left from another run (a
// results.json copied or restored beside it) was drawn without a word. Its hex count, and the largest
// displacement, must be the coarse level's (to 1e-4: an MPI run's pieces hold single-precision values).
void check_same_run(const std::string& solution_vtu, const RenderedMesh& drawn, const std::string& field,
                    const LevelFigures& l) {
  std::string differs;
  if (drawn.cells != l.hexes)
    differs = "has " + std::to_string(drawn.cells) + " hexes where results.json's coarse level has " +
              std::to_string(l.hexes);
  else if (field == "displacement" &&
           std::abs(drawn.field_max - l.max_displacement) > 1e-4 * std::max(l.max_displacement, 1e-12))
    differs = "has a largest displacement of " + format_mm(drawn.field_max) +
              " mm where results.json's coarse level has " + format_mm(l.max_displacement) + " mm";
  if (!differs.empty())
    throw InputError("'" + solution_vtu + "' " + differs +
                     ": it is not the solution of the run that results.json describes; run the scenario "
                     "again into this folder, or add --no-pictures");
}

}  // namespace

std::vector<ReportPicture> render_report_pictures(const std::string& solution_vtu, const RunFigures& run) {
  const LevelFigures& l = run.coarse;
  // The stress peaks at the edges of fixed patches (a singularity of the exact solution) would leave the
  // rest of the bone in the lowest colour: the scale stops at the 99th percentile of the per-hex stress.
  const std::string vm_scale =
      "Colour scale up to the 99th percentile of the per-hex stress, " + format_mpa(l.von_mises_p99) +
      " MPa (higher stresses in red); the maximum is " + format_mpa(l.von_mises_max) + " MPa at " +
      format_point(l.von_mises_max_at) + " mm.";
  struct Spec {
    std::string field, view, caption;
    double colour_max;
  };
  const std::vector<Spec> specs = {
      {"von_mises", "iso", "von Mises stress (MPa) on the outer surface, oblique view. " + vm_scale,
       l.von_mises_p99},
      {"von_mises", "side", "von Mises stress (MPa) on the outer surface, seen from the right. " + vm_scale,
       l.von_mises_p99},
      {"displacement", "iso",
       "Displacement magnitude (mm), oblique view (undeformed shape). Colour scale up to the maximum, " +
           format_mm(l.max_displacement) + " mm at " + format_point(l.max_displacement_at) + " mm.",
       0.0},
  };
  TemporaryFolder folder;
  std::vector<ReportPicture> pictures;
  for (const Spec& s : specs) {
    RenderOptions options;
    options.view = s.view;
    options.width = 1200;
    options.height = 800;
    options.colour_max = s.colour_max;
    const std::string png = folder.file(s.field + "_" + s.view + ".png");
    RenderedMesh drawn;
    try {
      drawn = render_mesh_png(solution_vtu, s.field, png, options);
    } catch (const RunError& e) {
      // The writer's advice ("make room on the disk or choose another output folder") blamed the report's
      // folder for a full TMPDIR, where the picture is drawn.
      if (std::string(e.what()).find(kWriteFailed) == std::string::npos) throw;
      throw RunError("cannot draw the report's pictures in " + folder.place() + ": " + kWriteFailed +
                     "; make room there, point TMPDIR at another folder, or give --no-pictures");
    }
    check_same_run(solution_vtu, drawn, s.field, l);
    pictures.push_back({s.field, s.view, s.caption, read_bytes(png)});
  }
  return pictures;
}

}  // namespace hexbite
