// A core swept across the dental arch: the grid mesher's core for coarse meshes of a mandible along the
// arch (GridMeshOptions::arch_frame, docs/meshing.md "Swept core").
//
// Input: the straightened surface of a mandible in arch coordinates (s along the arch, t across it, z up;
// mesher/arch_frame.h), closed and outward, with its projector and bounding box; the target number of hexes
// counting the pillow layer that the grid mesher adds; the shift of the grid in cells; the layers across.
// Output: a positively oriented hex mesh in arch coordinates: a square grid over (s, z), the side view of
// the bone, whose cells' centres see the bone across the arch at least min_thickness_cells cells thick;
// each selected cell is a column of `layers` hexes across the bone, between the bone's two faces each
// pulled in by a third of a cell (or of the local thickness, where the bone is thinner: as the pillow
// layer pulls core vertices in). The bone along a line across the arch at a grid vertex is the interval
// between its outermost crossings with the surface; a grid vertex outside the side view takes the mean
// interval of its columns' centres.
// Why: an overlay grid on a bone only 1.3-1.8 cells thick (about 2,500 hexes) makes most hexes touch a
// staircase, whose irregular boundary vertices bound the mean scaled Jacobian near 0.8. The swept core's
// two faces follow the bone's faces with only valence-4 vertices; the staircase is left in the side view's
// outline only. With one layer and the pillow layer each column is three hexes across the bone, like the
// seed paper's sheets.
// Selection: the largest edge-connected set of columns, with no two columns meeting only at a corner (the
// later of two such is dropped), so that the core's boundary is a 2-manifold.
// Cell size: secant steps on log(total hexes) against log(h), the total being columns * layers plus the
// pillow hexes (two faces per column and `layers` per outline edge), as the grid mesher counts.
// Limits: the bone must be one interval across the arch at every grid vertex for the core to follow it;
// where a line crosses the surface more than twice (between tooth crowns) the outermost crossings are used
// and the column may span a gap, which the pillow layer pulls back inside (SweptCore::split_vertices).
// Cost: per trial size one segment query per cell centre of the S x Z grid over the side view's box, and
// one per grid vertex of the kept grid's columns: O((S Z) log T) per trial for T triangles.
#pragma once

#include <array>
#include <vector>

#include "mesher/hex_mesh.h"
#include "mesher/surface_projector.h"

namespace hexbite {

struct SweptCoreOptions {
  int layers = 1;                     // hexes across the bone in each column
  double min_thickness_cells = 0.25;  // a column needs the bone at least this many cells thick at its centre
};

struct SweptCore {
  HexMesh mesh;               // arch coordinates
  double cell_size = 0;       // grid spacing in s and z, mm
  std::array<int, 3> grid{};  // cells along s, layers across, cells along z
  long columns = 0;           // selected cells of the (s, z) grid
  long outline_edges = 0;     // edges between a selected and an unselected cell
  int split_vertices = 0;     // grid vertices whose line across the arch crosses the surface 4 or more times
  long dropped_columns = 0;   // thick enough, but outside the largest set or meeting one only at a corner
};

// Throws InputError when no column holds the bone at any trial size (bounds that miss the bone), and
// std::invalid_argument for options.layers < 1.
SweptCore swept_core(const SurfaceProjector& straightened, const Vec3& lo, const Vec3& hi, long target_hexes,
                     double shift, const SweptCoreOptions& options = {});

namespace detail {
// The selection rule of swept_core on an ns x nz grid of cells (cell (i, j) at j * ns + i): keeps the largest
// edge-connected set of selected cells, then drops the later of every two that meet only at a corner, until
// neither changes anything; returns the number of cells dropped. Exposed for tests.
long keep_manifold_columns(std::vector<char>& selected, int ns, int nz);
}  // namespace detail

}  // namespace hexbite
