// `hexbite render`: a picture of a surface or of a mesh coloured by a result field, for reports and the
// README.
#include <CLI/CLI.hpp>
#include <limits>
#include <string>

#include "app/commands.h"
#include "app/option_checks.h"
#include "common/error.h"
#include "common/paths.h"
#include "common/progress.h"
#include "mesher/surface_io.h"
#include "mesher/units.h"
#include "postprocess/render.h"

namespace hexbite {

namespace {

// Options that the input would ignore are refused before anything is read (as `mesh` refuses its own):
// `--field`, `--max` and `--component` colour a mesh's arrays, which a surface has none of; `--units` scales
// a surface, and a .vtu is read in mm. Returns whether the input is a mesh (a .vtu, or the .pvtu of a run
// under mpirun, in any case).
bool check_render_input(const std::string& input, bool field, bool max, bool component, bool units) {
  const std::string ext = lower_extension(input);
  const bool mesh = ext == ".vtu" || ext == ".pvtu";
  if (!mesh && ext != ".stl" && ext != ".obj" && ext != ".ply" && ext != ".off" && ext != ".vtp")
    throw InputError("cannot render '" + input +
                     "': " + (ext.empty() ? std::string("no extension") : "unknown extension '" + ext + "'") +
                     "; render reads a surface (.stl, .obj, .ply, .off, .vtp) or a hex mesh or solution "
                     "(.vtu, or .pvtu with its pieces), in any case");
  if (!mesh && field)
    throw InputError("--field colours a mesh or solution (.vtu) by one of its arrays, but '" + input +
                     "' is a surface, which has none: drop --field, or render the .vtu");
  if (max && !field)
    throw InputError(
        "--max caps the colour scale of --field, and no --field is given: drop --max, or add "
        "--field NAME");
  if (component && !field)
    throw InputError(
        "--component picks a component of the array of --field, and no --field is given: drop --component, "
        "or add --field NAME");
  if (mesh && units)
    throw InputError("--units gives the unit of a surface input, but '" + input +
                     "' is a mesh, read in mm: drop --units");
  return mesh;
}

}  // namespace

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
  CLI::Option* units = cmd->add_option("--units", args->units, "Length unit of a surface input: mm, cm or m");
  CLI::Option* field =
      cmd->add_option("--field", args->field,
                      "VTU only: colour by this point array (e.g. von_mises, displacement), else cell array");
  CLI::Option* component =
      cmd->add_option("--component", args->options.component,
                      "With --field: the component of an array of several (e.g. 0 for stress xx); needed "
                      "for all but the displacement, drawn by its magnitude without it")
          ->transform(count_in_range(0, 99));
  // Finite (CLI::PositiveNumber let NaN through, and answered inf with a 309-digit upper bound).
  CLI::Option* max =
      cmd->add_option("--max", args->options.colour_max,
                      "With --field: upper end of the colour scale (default: the field's maximum)")
          ->check(number_in_range(std::numeric_limits<double>::min(), std::numeric_limits<double>::max(),
                                  "greater than 0"));
  cmd->add_option("--view", args->options.view, "iso, side (from the right), front, back or top")
      ->capture_default_str();
  // Counts like the others (CLI::Range said "Value 1e3 not in range 64 to 8192", and the same of "abc").
  cmd->add_option("--width", args->options.width, "Picture width in pixels")
      ->transform(count_in_range(64, 8192))
      ->capture_default_str();
  cmd->add_option("--height", args->options.height, "Picture height in pixels")
      ->transform(count_in_range(64, 8192))
      ->capture_default_str();
  cmd->add_option("--title", args->options.title, "Caption drawn in the lower left corner")
      ->check(one_line_of_text("the title"));
  cmd->add_flag("!--no-edges", args->options.edges, "Do not draw the element edges");
  cmd->callback([args, units, field, max, component] {
    if (check_render_input(args->input, field->count() > 0, max->count() > 0, component->count() > 0,
                           units->count() > 0)) {
      render_mesh_png(args->input, args->field, args->output, args->options);
    } else {
      const TriSurface surface = read_surface(args->input, unit_to_mm(args->units));
      render_surface_png(surface, args->output, args->options);
    }
    info("wrote " + args->output);
  });
}

}  // namespace hexbite
