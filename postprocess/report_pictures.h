// The pictures of a run report (hexbite report): the solution on the bone's outer surface, coloured by
// von Mises stress (iso and side views) and by the displacement magnitude, each with its colour bar.
// Rendered by render_mesh_png into a temporary folder, read back and the folder removed, so that the
// report can embed them and nothing is left behind. Needs an X display (can_render()); RunError without.
#pragma once

#include <string>
#include <vector>

#include "postprocess/run_results.h"

namespace hexbite {

struct ReportPicture {
  std::string field, view;  // the point array and the camera, e.g. "von_mises", "iso"
  std::string caption;      // plain text, with the field's maximum
  std::string png;          // the PNG's bytes
};

// Renders the report's pictures of `solution_vtu` (the coarse level's solution.vtu of the run that `run`
// describes, or its solution.pvtu under mpirun). Cost: three off-screen renderings of the outer surface.
std::vector<ReportPicture> render_report_pictures(const std::string& solution_vtu, const RunFigures& run);

}  // namespace hexbite
