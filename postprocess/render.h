// Pictures of surfaces and meshes for reports and the README (VTK, off-screen).
#pragma once

#include <string>
#include <vector>

#include "mesher/tri_surface.h"

namespace hexbite {

struct RenderOptions {
  std::string view = "iso";  // iso | side | front | top | back
  int width = 1200, height = 800;
  bool edges = true;      // draw the triangle or quad edges
  std::string title;      // optional caption in the picture's corner
  double colour_max = 0;  // upper end of the colour scale; 0 = the field's maximum
  int component = -1;     // the component of a field of several; -1 = none given
};

// Why VTK cannot open a window here ("DISPLAY is not set", "the X display ':77' does not answer", "the X
// display ':77' has no OpenGL ..." or "... has no usable OpenGL: <what failed>" when no OpenGL 3.2 context
// can be made and used on it), or empty when it can; checked once per process. Rendering without a display
// aborts inside VTK (exit 134), so callers check this first and tell the user to run under `xvfb-run -a`.
std::string display_problem();

// Renders the triangle surface and writes a PNG atomically. Throws RunError when no display.
void render_surface_png(const TriSurface& surface, const std::string& png_path, const RenderOptions& options);

// What render_mesh_png drew: the file's cell count and the field's largest value (the displacement: its
// magnitude; an array of several components: the component drawn; 0 for an empty field), before any cap
// of the colour scale, so that callers can tell that a file belongs to the figures they print beside it.
struct RenderedMesh {
  long cells = 0;
  double field_max = 0;
};

// Renders the outer surface of a hex mesh file (VTU, or a PVTU with its pieces) coloured by a point array
// (e.g. "von_mises" of a solution.vtu), else a cell array, with a colour bar, and writes a PNG atomically.
// An array of several components is coloured by options.component, the point array "displacement" without
// one by its magnitude. An empty field draws the mesh in bone colour. Throws InputError naming the file for
// an unreadable VTU, an unknown array (listing the available ones) or an array of several components
// without a component (listing them and the arrays of one), RunError when there is no display.
RenderedMesh render_mesh_png(const std::string& vtu_path, const std::string& field,
                             const std::string& png_path, const RenderOptions& options);

}  // namespace hexbite
