// `hexbite render`: a picture of a surface or of a mesh coloured by a result field, for reports and the
// README.
#include <CLI/CLI.hpp>

#include "app/commands.h"
#include "app/option_checks.h"
#include "common/paths.h"
#include "common/progress.h"
#include "mesher/surface_io.h"
#include "mesher/units.h"
#include "postprocess/render.h"

namespace hexbite {

void add_render_command(CLI::App& app) {
  auto* cmd =
      app.add_subcommand("render", "Render a surface or a mesh (VTU) to a PNG picture (needs an X display)");
  struct Args {
    std::string input, output, units = "mm", field;
    RenderOptions options;
  };
  auto args = std::make_shared<Args>();
  cmd->add_option("INPUT", args->input, "Surface file (STL, OBJ, PLY, OFF, VTP) or hex mesh / solution (VTU)")
      ->required();
  cmd->add_option("-o,--output", args->output, "PNG file to write")->required()->check(output_file({".png"}));
  cmd->add_option("--units", args->units, "Length unit of a surface input: mm, cm or m");
  cmd->add_option("--field", args->field,
                  "VTU only: colour by this point array (e.g. von_mises, displacement)");
  cmd->add_option("--max", args->options.colour_max,
                  "Upper end of the colour scale (default: the field's maximum)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--view", args->options.view, "iso, side (from the right), front, back or top");
  cmd->add_option("--width", args->options.width, "Picture width in pixels")->check(CLI::Range(64, 8192));
  cmd->add_option("--height", args->options.height, "Picture height in pixels")->check(CLI::Range(64, 8192));
  cmd->add_option("--title", args->options.title, "Caption drawn in the lower left corner");
  cmd->add_flag("!--no-edges", args->options.edges, "Do not draw the element edges");
  cmd->callback([args] {
    if (ends_with(args->input, ".vtu")) {
      render_mesh_png(args->input, args->field, args->output, args->options);
    } else {
      const TriSurface surface = read_surface(args->input, unit_to_mm(args->units));
      render_surface_png(surface, args->output, args->options);
    }
    info("wrote " + args->output);
  });
}

}  // namespace hexbite
