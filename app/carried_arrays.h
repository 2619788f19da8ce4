// The input mesh's own arrays carried into the output of `reorder` and `refine`, and the warning that names
// what an output leaves out.
#pragma once

#include <string>
#include <vector>

#include "mesher/hex_mesh.h"
#include "mesher/hex_mesh_io.h"

namespace hexbite {

// The input's cell arrays split by their names: `own` the user's; `clashing` those named like a quality
// array of write_vtu's but holding other values (a user's 'condition'), which the output's quality array of
// that name replaces. Quality arrays that hexbite wrote are in neither: the writer recomputes them.
struct CellArrays {
  std::vector<MeshArray> own;
  std::vector<std::string> clashing;
};

CellArrays split_cell_arrays(const HexMesh& mesh, const std::vector<MeshArray>& arrays);

// Warnings on standard error for what `command`'s output `output` leaves out of the input `input`: a .vtu
// carries the user's numeric cell arrays, and its point arrays when `points_carried`, but not a user's array
// under a quality array's name, nor `not_read` (text arrays, field data); .msh and .inp files carry no
// arrays at all. Nothing when all is carried.
void warn_arrays_not_carried(const std::string& input, const std::string& output, const std::string& command,
                             const CellArrays& cells, const std::vector<MeshArray>& point_arrays,
                             bool points_carried, const std::vector<std::string>& not_read);

}  // namespace hexbite
