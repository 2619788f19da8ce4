// Hex mesh files: VTU (VTK XML unstructured grid) read and write, Gmsh .msh read and write, and the Abaqus /
// CalculiX .inp export; write_hex_mesh and read_hex_mesh choose among them by the file name.
//
// Input/output: a HexMesh in VTK node order plus optional named per-cell and per-point arrays. Writers are
// atomic (a temporary file renamed into place) and deterministic (same mesh, same bytes). Readers keep only
// hexahedra (a VTU's vtkVoxel read as the hexahedron it is), skip surface, line and point cells, and throw
// InputError naming the file and what is wrong: missing, unreadable, not a mesh of that format, another
// volume cell (with its index and type), no hexahedron at all, a NaN or infinite
// coordinate, a vertex index out of range, a hexahedron listing a vertex twice (collapsed hexes), a
// hexahedron listed twice, two distinct vertices of hexes at exactly the same place (hexes that touch without
// sharing their nodes; unused points may coincide). Orientation is not checked here: that is the quality
// module's job (inverted hexes). Cost: O(n log n) in the mesh size (the sorts that find copies).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "mesher/hex_mesh.h"

namespace hexbite {

// A named array with `components` values per cell or per point, stored tuple after tuple. `vtk_type` is the
// VTK data type it is written as (vtkType.h's ids; VTK_DOUBLE = 11 by default) and the type it was read as,
// so that a VTU read and written again keeps its integer arrays integer; the values pass through doubles,
// exact for integers up to 2^53.
struct MeshArray {
  std::string name;
  int components = 1;
  std::vector<double> values;
  int vtk_type = 11;
  // For a 64-bit integer type (signed or unsigned), the values exactly, as their 64 bits: a double holds
  // integers up to 2^53 only, and `reorder` wrote 123456789012345679 back as ...680. When not empty, the
  // writer takes these instead of `values` (which hold the same numbers rounded).
  std::vector<std::uint64_t> bits64;
};

// The array whose tuple i is `a`'s tuple tuples[i] (bits64 too): a subset, a new order or repeats.
MeshArray array_tuples(const MeshArray& a, const std::vector<int>& tuples);

// A named set of 0-based node or element indices, for solver input files.
struct IndexSet {
  std::string name;
  std::vector<int> ids;
};

// Names of the per-cell quality arrays that write_vtu always adds (see mesher/hex_quality.h):
// scaled_jacobian, condition (cube = 3), oddy and jacobian. Callers may not reuse these names.
inline const char* const kVtuQualityArrays[4] = {"scaled_jacobian", "condition", "oddy", "jacobian"};

struct HexQualityField;
// The values write_vtu writes under kVtuQualityArrays[i], Float64 with one component.
const std::vector<double>& vtu_quality_array(const HexQualityField& quality, int i);

// Writes a .vtu file: binary appended, zlib-compressed, double coordinates, VTK_HEXAHEDRON cells, with the
// quality arrays above and the caller's extra cell and point arrays (Float64). Throws std::invalid_argument
// when an extra array has the wrong size or a reserved or duplicate name.
void write_vtu(const std::string& path, const HexMesh& mesh, const std::vector<MeshArray>& cell_arrays = {},
               const std::vector<MeshArray>& point_arrays = {});

// Reads a .vtu file of hexahedra. When given, cell_arrays and point_arrays receive the file's numeric
// arrays (as doubles with their VTK type, in file order; the quality arrays included; cell arrays with the
// values of the hexes only), and `not_read` what
// the file holds beside them: "cell array 'label' (text)", "field data 'TimeValue'".
HexMesh read_vtu(const std::string& path, std::vector<MeshArray>* cell_arrays = nullptr,
                 std::vector<MeshArray>* point_arrays = nullptr,
                 std::vector<std::string>* not_read = nullptr);

// Exports an Abaqus / CalculiX input deck: *NODE (NSET=NALL), *ELEMENT TYPE=C3D8 (ELSET=EALL; the C3D8 node
// order is VTK's hexahedron order), then one *NSET / *ELSET per given set. Numbers are 1-based in the file.
// Set names must start with a letter and hold only letters, digits and '_' (at most 79 characters:
// CalculiX prints an 80-character one blank), and
// may not be NALL or EALL; violations throw std::invalid_argument. No material or step: the solver adds them.
void write_inp(const std::string& path, const HexMesh& mesh, const std::vector<IndexSet>& node_sets = {},
               const std::vector<IndexSet>& element_sets = {});

// A number for an .inp data line: the shortest text that reads back exactly (15 to 17 significant digits),
// shortened to the 20 characters that CalculiX reads of a field (at least 13 significant digits remain).
std::string format_inp_number(double v);

// Writes a Gmsh 4.1 ASCII .msh file: one volume entity, nodes tagged 1..n, hexahedra (element type 5,
// Gmsh's node order, which equals VTK's) tagged 1..m.
void write_msh(const std::string& path, const HexMesh& mesh);

// The tags a .msh file gives its nodes and hexes, in the order of HexMesh::vertices and HexMesh::hexes,
// for messages that name a node or a hex as Gmsh does (hexbite numbers them from 0 in file order).
struct GmshTags {
  std::vector<long> nodes;
  std::vector<long> elements;
  // The file's physical groups, which no writer carries over: "physical group 'bone' (3-D, tag 1)", or
  // "physical group 2 (2-D)" for one without a name.
  std::vector<std::string> physical_groups;
};

// Reads a Gmsh ASCII .msh file, format 4.1 or 2.2 (its nodes in $Nodes, or in 2.2 $ParametricNodes).
// Points, lines and faces are skipped; hexahedra (type 5) are kept; any other volume element is an
// InputError. All nodes are kept, in the file's order. When given, `tags` receives the file's node and
// element tags and its physical groups (from $PhysicalNames, 4.1's $Entities and 2.2's element tags).
HexMesh read_msh(const std::string& path, GmshTags* tags = nullptr);

// The hex mesh formats by the file name's extension (any case): .vtu (write_vtu, with the arrays), .inp
// (write_inp, nodes and C3D8 elements only) or .msh (write_msh); the arrays go only into a .vtu. Throws
// InputError for another extension.
void write_hex_mesh(const std::string& path, const HexMesh& mesh,
                    const std::vector<MeshArray>& cell_arrays = {},
                    const std::vector<MeshArray>& point_arrays = {});

// Reads a .msh file (read_msh) by its extension (any case), any other name as a .vtu (read_vtu, which names
// a file that is not one); the arrays come only from a .vtu (a .msh leaves them empty), the Gmsh tags
// only from a .msh (a .vtu leaves them empty).
HexMesh read_hex_mesh(const std::string& path, std::vector<MeshArray>* cell_arrays = nullptr,
                      std::vector<MeshArray>* point_arrays = nullptr,
                      std::vector<std::string>* not_read = nullptr, GmshTags* tags = nullptr);

}  // namespace hexbite
