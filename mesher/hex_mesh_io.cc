#include "mesher/hex_mesh_io.h"

#include <vtkCell.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCellTypes.h>
#include <vtkDataArray.h>
#include <vtkDataArraySelection.h>
#include <vtkFieldData.h>
#include <vtkIdTypeArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridReader.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <system_error>
#include <type_traits>
#include <unordered_map>
#include <utility>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/markup_escape.h"
#include "common/paths.h"
#include "mesher/hex_quality.h"
#include "mesher/vtk_messages.h"

namespace hexbite {

namespace fs = std::filesystem;

namespace {

// Shortest decimal text that reads back to the same double, so text files round-trip exactly.
std::string format_double(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// The checks every reader makes before parsing: the file exists, is a regular file, is not empty and opens.
void check_readable(const std::string& path, const char* what) {
  require_regular_file(path, std::string(what) + " file");
  std::ifstream probe(path, std::ios::binary);
  if (!probe)
    throw InputError("cannot read " + std::string(what) + " '" + path +
                     "': the file cannot be opened (check permissions)");
  std::error_code ec;
  if (fs::file_size(path, ec) == 0)
    throw InputError("cannot read " + std::string(what) + " '" + path + "': the file is empty");
}

// Two distinct vertices of hexes at exactly the same place leave the hexes on either side unconnected: the
// face between them counted as boundary, refine moved its nodes onto the surface (the halves overlapped)
// and the solver would see two loose bodies. Sorting the used vertices by their coordinates finds them in
// O(n log n). Unused points may coincide: no hex joins through them.
void check_coincident_vertices(const HexMesh& mesh, const std::string& where,
                               const std::vector<long>& node_tags) {
  std::vector<char> used(mesh.vertices.size(), 0);
  for (const std::array<int, 8>& hex : mesh.hexes)
    for (int v : hex) used[v] = 1;
  std::vector<int> order;
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v)
    if (used[v]) order.push_back(static_cast<int>(v));
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return std::make_pair(mesh.vertices[a], a) < std::make_pair(mesh.vertices[b], b);
  });
  std::size_t pairs = 0, first = 0;
  for (std::size_t i = 1; i < order.size(); ++i)
    if (mesh.vertices[order[i]] == mesh.vertices[order[i - 1]] && pairs++ == 0) first = i;
  if (pairs == 0) return;
  const int a = order[first - 1], b = order[first];
  const Vec3& p = mesh.vertices[a];
  char place[128];
  std::snprintf(place, sizeof place, "(%.9g, %.9g, %.9g) mm", p[0], p[1], p[2]);
  // Named as the file numbers them: by their Gmsh node tags, or else 0-based.
  const std::string names =
      node_tags.empty() ? "vertices " + std::to_string(a) + " and " + std::to_string(b) + " (0-based)"
                        : "nodes " + std::to_string(node_tags[a]) + " and " + std::to_string(node_tags[b]);
  throw InputError(
      where + ": " + names + " lie at the same place " + place +
      " but are distinct, so the hexes using them are not joined there (their shared faces would count as "
      "boundary)" +
      (pairs > 1 ? "; " + std::to_string(pairs) + " such pairs in all" : std::string()) +
      ": merge coincident nodes where the mesh was made (in Gmsh: 'Coherence Mesh;' after meshing, or "
      "Geometry.AutoCoherence = 1 or BooleanFragments so that touching volumes share their faces)");
}

// Checks vertex coordinates and hex indices of a mesh just read; `where` names the file, `node_tags` its
// Gmsh node tags (empty for a .vtu).
void check_mesh(const HexMesh& mesh, const std::string& where, const std::vector<long>& node_tags = {}) {
  if (mesh.hexes.empty())
    throw InputError(where + " holds no hexahedra (" + std::to_string(mesh.vertices.size()) +
                     " points and no volume cells): give a hex mesh");
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v)
    for (double c : mesh.vertices[v])
      if (!std::isfinite(c))
        throw InputError(where + ": vertex " + std::to_string(v) + " has a NaN or infinite coordinate");
  const long n = static_cast<long>(mesh.vertices.size());
  for (std::size_t h = 0; h < mesh.hexes.size(); ++h) {
    const std::array<int, 8>& hex = mesh.hexes[h];
    for (int k = 0; k < 8; ++k) {
      if (hex[k] < 0 || hex[k] >= n)
        throw InputError(where + ": hexahedron " + std::to_string(h) + " refers to vertex " +
                         std::to_string(hex[k]) + ", but there are only " + std::to_string(n) + " vertices");
      // A collapsed (degenerate) hex has no volume at that corner; its measures would call it inverted.
      for (int j = 0; j < k; ++j)
        if (hex[j] == hex[k])
          throw InputError(where + ": hexahedron " + std::to_string(h) + " lists vertex " +
                           std::to_string(hex[k]) + " twice (corners " + std::to_string(j) + " and " +
                           std::to_string(k) +
                           "); a hexahedron needs 8 distinct vertices: collapsed hexes are not supported, "
                           "fix the connectivity where the mesh was made");
    }
  }
  // A hex listed twice doubles the volume and the stiffness there and turns the faces between the copies
  // into interior faces (quality said "2 hexes", refine doubled them, reorder failed with internal text).
  std::vector<std::pair<std::array<int, 8>, std::size_t>> sorted(mesh.hexes.size());
  for (std::size_t h = 0; h < mesh.hexes.size(); ++h) {
    sorted[h] = {mesh.hexes[h], h};
    std::sort(sorted[h].first.begin(), sorted[h].first.end());
  }
  std::sort(sorted.begin(), sorted.end());
  for (std::size_t i = 1; i < sorted.size(); ++i)
    if (sorted[i].first == sorted[i - 1].first)
      throw InputError(where + ": hexahedra " + std::to_string(sorted[i - 1].second) + " and " +
                       std::to_string(sorted[i].second) +
                       " (0-based) have the same 8 vertices: a hexahedron listed twice; remove the copies "
                       "where the mesh was made");
  check_coincident_vertices(mesh, where, node_tags);
}

void check_arrays(const std::vector<MeshArray>& arrays, std::size_t count, const char* kind,
                  std::set<std::string>& names) {
  for (const MeshArray& a : arrays) {
    if (a.name.empty())
      throw std::invalid_argument(std::string("write_vtu: a ") + kind + " array has no name");
    if (!names.insert(a.name).second)
      throw std::invalid_argument("write_vtu: array name '" + a.name + "' is reserved or used twice");
    if (a.components < 1 || a.values.size() != count * static_cast<std::size_t>(a.components))
      throw std::invalid_argument("write_vtu: " + std::string(kind) + " array '" + a.name + "' has " +
                                  std::to_string(a.values.size()) + " values, expected " +
                                  std::to_string(count) + " x " + std::to_string(a.components));
  }
}

static_assert(VTK_DOUBLE == 11, "MeshArray::vtk_type's default is VTK_DOUBLE");

// VTK's 64-bit integer types on this platform, whose values a double cannot always hold.
bool is_64_bit_integer(const vtkDataArray& a) {
  return a.GetDataTypeSize() == 8 && a.GetDataType() != VTK_DOUBLE;
}

vtkSmartPointer<vtkDataArray> make_vtk_array(const MeshArray& a) {
  vtkSmartPointer<vtkDataArray> array;
  array.TakeReference(vtkDataArray::CreateDataArray(a.vtk_type));
  // VTK 9.1's XML writer puts the name into its Name="..." attribute as it is: a name holding & < or "
  // made a file that no XML reader accepts. Escaped here, it reads back as the name itself.
  array->SetName(markup_escape(a.name).c_str());
  array->SetNumberOfComponents(a.components);
  array->SetNumberOfTuples(static_cast<vtkIdType>(a.values.size() / a.components));
  if (!a.bits64.empty() && is_64_bit_integer(*array) && a.bits64.size() == a.values.size()) {
    std::memcpy(array->GetVoidPointer(0), a.bits64.data(), a.bits64.size() * sizeof(std::uint64_t));
    return array;
  }
  for (std::size_t i = 0; i < a.values.size(); ++i)
    array->SetComponent(static_cast<vtkIdType>(i / a.components), static_cast<int>(i % a.components),
                        a.values[i]);
  return array;
}

std::vector<MeshArray> arrays_of(vtkFieldData* data) {
  std::vector<MeshArray> out;
  for (int i = 0; i < data->GetNumberOfArrays(); ++i) {
    vtkDataArray* a = data->GetArray(i);
    if (a == nullptr) continue;  // string or other non-numeric arrays
    MeshArray m;
    m.name = a->GetName() ? a->GetName() : "";
    m.components = a->GetNumberOfComponents();
    m.vtk_type = a->GetDataType();
    m.values.resize(static_cast<std::size_t>(a->GetNumberOfTuples()) * m.components);
    for (vtkIdType t = 0; t < a->GetNumberOfTuples(); ++t)
      for (int c = 0; c < m.components; ++c) m.values[t * m.components + c] = a->GetComponent(t, c);
    if (is_64_bit_integer(*a) && !m.values.empty()) {  // the XML reader's arrays are contiguous
      m.bits64.resize(m.values.size());
      std::memcpy(m.bits64.data(), a->GetVoidPointer(0), m.bits64.size() * sizeof(std::uint64_t));
    }
    out.push_back(std::move(m));
  }
  return out;
}

}  // namespace

const std::vector<double>& vtu_quality_array(const HexQualityField& quality, int i) {
  const std::vector<double>* arrays[4] = {&quality.scaled_jacobian, &quality.condition, &quality.oddy,
                                          &quality.jacobian};
  return *arrays[i];
}

void write_vtu(const std::string& path, const HexMesh& mesh, const std::vector<MeshArray>& cell_arrays,
               const std::vector<MeshArray>& point_arrays) {
  std::set<std::string> names(std::begin(kVtuQualityArrays), std::end(kVtuQualityArrays));
  check_arrays(cell_arrays, mesh.hexes.size(), "cell", names);
  names.clear();
  check_arrays(point_arrays, mesh.vertices.size(), "point", names);

  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(static_cast<vtkIdType>(mesh.vertices.size()));
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v)
    points->SetPoint(static_cast<vtkIdType>(v), mesh.vertices[v].data());

  vtkNew<vtkIdTypeArray> offsets;
  vtkNew<vtkIdTypeArray> connectivity;
  offsets->SetNumberOfValues(static_cast<vtkIdType>(mesh.hexes.size() + 1));
  connectivity->SetNumberOfValues(static_cast<vtkIdType>(mesh.hexes.size() * 8));
  for (std::size_t h = 0; h <= mesh.hexes.size(); ++h) offsets->SetValue(h, static_cast<vtkIdType>(8 * h));
  for (std::size_t h = 0; h < mesh.hexes.size(); ++h)
    for (int k = 0; k < 8; ++k) connectivity->SetValue(8 * h + k, mesh.hexes[h][k]);
  vtkNew<vtkCellArray> cells;
  cells->SetData(offsets, connectivity);

  vtkNew<vtkUnstructuredGrid> grid;
  grid->SetPoints(points);
  grid->SetCells(VTK_HEXAHEDRON, cells);

  const HexQualityField q = compute_hex_quality(mesh);
  for (int i = 0; i < 4; ++i)
    grid->GetCellData()->AddArray(make_vtk_array({kVtuQualityArrays[i], 1, vtu_quality_array(q, i)}));
  for (const MeshArray& a : cell_arrays) grid->GetCellData()->AddArray(make_vtk_array(a));
  for (const MeshArray& a : point_arrays) grid->GetPointData()->AddArray(make_vtk_array(a));

  // Into memory first, then written and checked like every other file: VTK writing to the file itself did
  // not notice a write that failed (a full disk, a file size limit), and left a truncated file with exit 0.
  vtkNew<vtkXMLUnstructuredGridWriter> writer;
  writer->WriteToOutputStringOn();
  writer->SetInputData(grid);
  writer->SetDataModeToAppended();
  writer->EncodeAppendedDataOff();
  writer->SetCompressorTypeToZLib();
  writer->SetHeaderTypeToUInt64();
  writer->SetIdTypeToInt64();
  VtkMessageCapture capture;
  if (writer->Write() != 1 || !capture.errors().empty())
    throw RunError("cannot write '" + path +
                   "': " + (capture.errors().empty() ? std::string("VTK writer failed") : capture.errors()));
  write_file_atomically(path, writer->GetOutputString());
}

MeshArray array_tuples(const MeshArray& a, const std::vector<int>& tuples) {
  const std::size_t n = static_cast<std::size_t>(a.components);
  MeshArray out{a.name, a.components, {}, a.vtk_type, {}};
  out.values.reserve(tuples.size() * n);
  for (const int t : tuples) {
    const std::size_t k = static_cast<std::size_t>(t) * n;
    out.values.insert(out.values.end(), a.values.begin() + k, a.values.begin() + k + n);
    if (!a.bits64.empty())
      out.bits64.insert(out.bits64.end(), a.bits64.begin() + k, a.bits64.begin() + k + n);
  }
  return out;
}

HexMesh read_vtu(const std::string& path, std::vector<MeshArray>* cell_arrays,
                 std::vector<MeshArray>* point_arrays, std::vector<std::string>* not_read) {
  check_readable(path, "hex mesh");
  const std::string where = "hex mesh '" + path + "'";
  vtkNew<vtkXMLUnstructuredGridReader> reader;
  VtkMessageCapture capture;
  if (reader->CanReadFile(path.c_str()) == 0) {
    // Any name but .msh comes here: for another extension (an Abaqus .inp, a surface) say what is read.
    const std::string ext = lower_extension(path);
    throw InputError(
        "cannot read " + where +
        ": not a VTK XML unstructured grid (.vtu) file; expected a <VTKFile type=\"UnstructuredGrid\"> "
        "document" +
        (ext == ".vtu"
             ? std::string()
             : "; hex meshes are read from .vtu or Gmsh .msh (4.1 or 2.2 ASCII) files only: give one "
               "(an .inp is written, not read; Gmsh converts other formats to .msh)"));
  }
  reader->SetFileName(path.c_str());
  update_xml_reader(reader, path);
  vtkUnstructuredGrid* grid = reader->GetOutput();
  // Warnings (for example about an unknown array type) do not make a file unreadable; errors do.
  if (!capture.errors().empty() || grid == nullptr)
    throw InputError("cannot read " + where + ": the file is damaged or truncated" +
                     (capture.errors().empty() ? std::string(" (VTK: no output)") : capture.reason()));
  const vtkIdType num_points = grid->GetNumberOfPoints();
  const vtkIdType num_cells = grid->GetNumberOfCells();
  if (num_points > std::numeric_limits<int>::max() || num_cells > std::numeric_limits<int>::max())
    throw InputError("cannot read " + where + ": more than 2^31 points or cells are not supported");

  HexMesh mesh;
  mesh.vertices.resize(num_points);
  for (vtkIdType v = 0; v < num_points; ++v) grid->GetPoint(v, mesh.vertices[v].data());
  // Surface, line and point cells are skipped, as read_msh skips Gmsh's lower-dimensional elements (a mesh
  // exported with its boundary quads); a vtkVoxel is a hexahedron whose nodes 2, 3 and 6, 7 come in the
  // other order. `kept` lists the file's cells that became hexes, for the cell arrays.
  std::vector<int> kept;
  for (vtkIdType c = 0; c < num_cells; ++c) {
    const int type = grid->GetCellType(c);
    if (type != VTK_HEXAHEDRON && type != VTK_VOXEL) {
      if (grid->GetCell(c)->GetCellDimension() < 3) continue;
      const char* name = vtkCellTypes::GetClassNameFromTypeId(type);
      throw InputError(where + ": cell " + std::to_string(c) + " is a " + (name ? name : "unknown cell") +
                       " (VTK cell type " + std::to_string(type) +
                       "); only hexahedra (VTK_HEXAHEDRON, type 12, or vtkVoxel, type 11) are accepted, "
                       "surface cells skipped: give an all-hex mesh (in Gmsh, for instance "
                       "Mesh.SubdivisionAlgorithm = 2, which splits every element into hexahedra, with "
                       "Mesh.ElementOrder = 1), or mesh the surface with hexbite mesh");
    }
    vtkIdType npts = 0;
    const vtkIdType* pts = nullptr;
    grid->GetCellPoints(c, npts, pts);
    if (npts != 8)
      throw InputError(where + ": hexahedron " + std::to_string(c) + " has " + std::to_string(npts) +
                       " vertices instead of 8");
    std::array<int, 8> hex;
    for (int k = 0; k < 8; ++k) {
      if (pts[k] < 0 || pts[k] >= num_points)
        throw InputError(where + ": hexahedron " + std::to_string(c) + " refers to vertex " +
                         std::to_string(pts[k]) + ", but there are only " + std::to_string(num_points) +
                         " vertices");
      hex[k] = static_cast<int>(pts[k]);
    }
    if (type == VTK_VOXEL) {
      std::swap(hex[2], hex[3]);
      std::swap(hex[6], hex[7]);
    }
    mesh.hexes.push_back(hex);
    kept.push_back(static_cast<int>(c));
  }
  check_mesh(mesh, where);
  if (cell_arrays != nullptr) {
    *cell_arrays = arrays_of(grid->GetCellData());
    if (kept.size() != static_cast<std::size_t>(num_cells))
      for (MeshArray& a : *cell_arrays) a = array_tuples(a, kept);  // the values of the hexes only
  }
  if (point_arrays != nullptr) *point_arrays = arrays_of(grid->GetPointData());
  if (not_read != nullptr) {
    // Text arrays are left unread (update_xml_reader() disables them), and field data has no place here.
    not_read->clear();
    for (const auto& [kind, selection] : {std::pair{"cell", reader->GetCellDataArraySelection()},
                                          std::pair{"point", reader->GetPointDataArraySelection()}})
      for (int i = 0; i < selection->GetNumberOfArrays(); ++i)
        if (selection->ArrayIsEnabled(selection->GetArrayName(i)) == 0)
          not_read->push_back(std::string(kind) + " array '" + selection->GetArrayName(i) + "' (text)");
    vtkFieldData* field = grid->GetFieldData();
    for (int i = 0; field != nullptr && i < field->GetNumberOfArrays(); ++i)
      not_read->push_back(
          std::string("field data '") +
          (field->GetAbstractArray(i)->GetName() ? field->GetAbstractArray(i)->GetName() : "") + "'");
  }
  return mesh;
}

namespace {

void check_set(const IndexSet& set, std::size_t count, const char* kind, std::set<std::string>& names) {
  const std::string& n = set.name;
  // CalculiX takes 80 characters, but prints an 80-character name blank in model.dat's totals ("for set
  // and time"); 79 print.
  bool ok = !n.empty() && n.size() <= 79 && std::isalpha(static_cast<unsigned char>(n[0]));
  for (char ch : n) ok = ok && (std::isalnum(static_cast<unsigned char>(ch)) || ch == '_');
  if (!ok)
    throw std::invalid_argument(
        "write_inp: " + std::string(kind) + " set name '" + n +
        "' must start with a letter and hold only letters, digits and '_' (at most 79)");
  std::string upper = n;
  for (char& ch : upper) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
  // Abaqus names are case-insensitive, so NAll would collide with the NALL set written for all nodes.
  if (!names.insert(upper).second)
    throw std::invalid_argument("write_inp: set name '" + n +
                                "' is reserved or used twice (names ignore case)");
  for (int id : set.ids)
    if (id < 0 || static_cast<std::size_t>(id) >= count)
      throw std::invalid_argument("write_inp: " + std::string(kind) + " set '" + n + "' holds index " +
                                  std::to_string(id) + ", out of range [0, " + std::to_string(count) + ")");
}

// Abaqus allows at most 16 entries per data line of a set.
void write_set(std::ostringstream& out, const char* keyword, const IndexSet& set) {
  out << '*' << keyword << ", " << keyword << '=' << set.name << '\n';
  for (std::size_t i = 0; i < set.ids.size(); ++i) {
    out << set.ids[i] + 1;
    out << ((i % 16 == 15 || i + 1 == set.ids.size()) ? "\n" : ", ");
  }
}

}  // namespace

std::string format_inp_number(double v) {
  char buf[32];
  int digits = 17;
  for (int d = 15; d <= 17; ++d) {
    std::snprintf(buf, sizeof buf, "%.*g", d, v);
    if (std::strtod(buf, nullptr) == v) {
      digits = d;
      break;
    }
  }
  // CalculiX reads the first 20 characters of a field: give up the last digits rather than the exponent.
  for (;; --digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, v);
    if (std::strlen(buf) <= 20) return buf;
  }
}

void write_inp(const std::string& path, const HexMesh& mesh, const std::vector<IndexSet>& node_sets,
               const std::vector<IndexSet>& element_sets) {
  std::set<std::string> names = {"NALL", "EALL"};
  for (const IndexSet& s : node_sets) check_set(s, mesh.vertices.size(), "node", names);
  for (const IndexSet& s : element_sets) check_set(s, mesh.hexes.size(), "element", names);

  std::ostringstream out;
  out << "** hexbite hex mesh: " << mesh.vertices.size() << " nodes, " << mesh.hexes.size()
      << " C3D8 elements; units mm (add material and steps in N, MPa)\n";
  out << "*NODE, NSET=NALL\n";
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    const Vec3& p = mesh.vertices[v];
    out << v + 1 << ", " << format_inp_number(p[0]) << ", " << format_inp_number(p[1]) << ", "
        << format_inp_number(p[2]) << '\n';
  }
  // C3D8 numbers its nodes like VTK_HEXAHEDRON: face 1-2-3-4, then 5-6-7-8 above it.
  out << "*ELEMENT, TYPE=C3D8, ELSET=EALL\n";
  for (std::size_t h = 0; h < mesh.hexes.size(); ++h) {
    out << h + 1;
    for (int v : mesh.hexes[h]) out << ", " << v + 1;
    out << '\n';
  }
  for (const IndexSet& s : node_sets) write_set(out, "NSET", s);
  for (const IndexSet& s : element_sets) write_set(out, "ELSET", s);
  write_file_atomically(path, out.str());
}

void write_msh(const std::string& path, const HexMesh& mesh) {
  Vec3 lo{0, 0, 0}, hi{0, 0, 0};
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v)
    for (int d = 0; d < 3; ++d) {
      lo[d] = v == 0 ? mesh.vertices[v][d] : std::min(lo[d], mesh.vertices[v][d]);
      hi[d] = v == 0 ? mesh.vertices[v][d] : std::max(hi[d], mesh.vertices[v][d]);
    }
  const std::size_t n = mesh.vertices.size(), m = mesh.hexes.size();
  std::ostringstream out;
  out << "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
  // One volume entity without physical groups or bounding surfaces holds every node and element.
  out << "$Entities\n0 0 0 1\n1 " << format_double(lo[0]) << ' ' << format_double(lo[1]) << ' '
      << format_double(lo[2]) << ' ' << format_double(hi[0]) << ' ' << format_double(hi[1]) << ' '
      << format_double(hi[2]) << " 0 0\n$EndEntities\n";
  out << "$Nodes\n1 " << n << ' ' << (n ? 1 : 0) << ' ' << n << "\n3 1 0 " << n << '\n';
  for (std::size_t v = 0; v < n; ++v) out << v + 1 << '\n';
  for (const Vec3& p : mesh.vertices)
    out << format_double(p[0]) << ' ' << format_double(p[1]) << ' ' << format_double(p[2]) << '\n';
  out << "$EndNodes\n";
  // Gmsh's 8-node hexahedron (type 5) numbers its nodes like VTK_HEXAHEDRON.
  out << "$Elements\n1 " << m << ' ' << (m ? 1 : 0) << ' ' << m << "\n3 1 5 " << m << '\n';
  for (std::size_t h = 0; h < m; ++h) {
    out << h + 1;
    for (int v : mesh.hexes[h]) out << ' ' << v + 1;
    out << '\n';
  }
  out << "$EndElements\n";
  write_file_atomically(path, out.str());
}

namespace {

// Line-oriented reader of an ASCII .msh file that names the file and line in its errors.
class MshReader {
 public:
  explicit MshReader(const std::string& path) : path_(path), in_(path) {}

  bool next_line(std::string& line) {
    if (!std::getline(in_, line)) return false;
    ++line_no_;
    // Trailing blanks and a '\r' as Gmsh itself ignores them: "$Nodes " is still the $Nodes section.
    while (!line.empty() && std::isspace(static_cast<unsigned char>(line.back()))) line.pop_back();
    return true;
  }
  std::istringstream numbers() {
    std::string line;
    if (!next_line(line)) fail("the file ends early");
    return std::istringstream(line);
  }
  template <typename... T>
  void read(std::istringstream& s, T&... values) {
    (read_one(s, values), ...);
  }
  [[noreturn]] void fail(const std::string& what) const {
    throw InputError("cannot read Gmsh mesh '" + path_ + "', line " + std::to_string(line_no_) + ": " + what);
  }
  // The next blank-separated token as a whole number or a finite number: a token such as "nan", "1.5" for a
  // count or "1e999" is named, not taken for the end of the line.
  template <typename V>
  void read_one(std::istringstream& s, V& value) {
    std::string token;
    if (!(s >> token)) fail("expected more numbers on this line");
    const char* first = token.data() + (token.size() > 1 && token[0] == '+' ? 1 : 0);
    const char* last = token.data() + token.size();
    const auto [end, error] = std::from_chars(first, last, value);
    const std::string kind = std::is_integral_v<V> ? "a whole number" : "a number";
    if (error == std::errc::result_out_of_range) fail("'" + token + "' is out of range for " + kind);
    if (error != std::errc() || end != last) fail("'" + token + "' is not " + kind);
    if constexpr (std::is_floating_point_v<V>)
      if (!std::isfinite(value)) fail("'" + token + "' is not a finite number");
  }
  long line() const { return line_no_; }
  void expect_end(const std::string& section) {
    std::string line;
    if (!next_line(line) || line != "$End" + section) fail("expected $End" + section);
  }

 private:
  std::string path_;
  std::ifstream in_;
  long line_no_ = 0;
};

// Dimension of the Gmsh element types we may meet; 0 for types we do not know.
int gmsh_element_dimension(int type) {
  switch (type) {
    case 15:
      return 0;
    case 1:
    case 8:
    case 26:
    case 27:
    case 28:
      return 1;
    case 2:
    case 3:
    case 9:
    case 10:
    case 16:
    case 20:
    case 21:
    case 22:
    case 23:
    case 24:
    case 25:
      return 2;
    case 4:
    case 5:
    case 6:
    case 7:
    case 11:
    case 12:
    case 13:
    case 14:
    case 17:
    case 18:
    case 19:
    case 29:
    case 92:
    case 93:
      return 3;
    default:
      return -1;
  }
}

// "a 4-node tetrahedron" for the common Gmsh volume types other than the 8-node hexahedron.
std::string gmsh_volume_element_name(int type) {
  switch (type) {
    case 4:
      return "a 4-node tetrahedron";
    case 6:
      return "a 6-node prism";
    case 7:
      return "a 5-node pyramid";
    case 11:
      return "a 10-node tetrahedron";
    case 12:
      return "a 27-node hexahedron";
    case 17:
      return "a 20-node hexahedron";
    default:
      return "a volume element";
  }
}

}  // namespace

HexMesh read_msh(const std::string& path, GmshTags* tags) {
  check_readable(path, "Gmsh mesh");
  MshReader r(path);
  HexMesh mesh;
  std::unordered_map<long, int> node_index;
  std::vector<long> node_tags, hex_tags;  // of mesh.vertices and mesh.hexes, for messages
  std::string line, version;
  bool have_format = false, have_nodes = false, have_elements = false;
  auto add_node = [&](long tag, const Vec3& p) {
    if (!node_index.emplace(tag, static_cast<int>(mesh.vertices.size())).second)
      r.fail("node tag " + std::to_string(tag) + " appears twice");
    mesh.vertices.push_back(p);
    node_tags.push_back(tag);
  };
  std::map<std::array<long, 8>, std::pair<long, long>> hex_lines;  // sorted nodes -> (tag, line)
  auto add_element = [&](long tag, int type, const std::vector<long>& nodes) {
    const int dim = gmsh_element_dimension(type);
    if (dim < 0)
      r.fail("element " + std::to_string(tag) + " has unknown element type " + std::to_string(type));
    if (dim < 3) return;
    if (type != 5)
      r.fail("element " + std::to_string(tag) + " is " + gmsh_volume_element_name(type) + " (Gmsh type " +
             std::to_string(type) +
             "); only 8-node hexahedra (type 5) are accepted: give an all-hex mesh (in Gmsh, for instance "
             "Mesh.SubdivisionAlgorithm = 2, which splits every element into hexahedra, with "
             "Mesh.ElementOrder = 1), or mesh the surface with hexbite mesh");
    if (nodes.size() != 8) r.fail("hexahedron " + std::to_string(tag) + " does not have 8 nodes");
    std::array<int, 8> hex;
    for (int k = 0; k < 8; ++k) {
      const auto it = node_index.find(nodes[k]);
      if (it == node_index.end())
        r.fail("hexahedron " + std::to_string(tag) + " refers to node " + std::to_string(nodes[k]) +
               ", which is not in $Nodes");
      hex[k] = it->second;
      // Named here by the file's tags (check_mesh() would give the reader's 0-based numbers).
      for (int j = 0; j < k; ++j)
        if (nodes[j] == nodes[k])
          r.fail("hexahedron " + std::to_string(tag) + " lists node " + std::to_string(nodes[k]) +
                 " twice (corners " + std::to_string(j + 1) + " and " + std::to_string(k + 1) +
                 " of 8); a hexahedron needs 8 distinct nodes: collapsed hexes are not supported, fix the "
                 "connectivity where the mesh was made");
    }
    // A volume in two physical groups has its elements written once per group in MSH 2.2.
    std::array<long, 8> key;
    std::copy(nodes.begin(), nodes.end(), key.begin());
    std::sort(key.begin(), key.end());
    const auto [first, fresh] = hex_lines.emplace(key, std::make_pair(tag, r.line()));
    if (!fresh)
      r.fail("hexahedron " + std::to_string(tag) + " has the same 8 nodes as hexahedron " +
             std::to_string(first->second.first) + " (line " + std::to_string(first->second.second) +
             "): a hexahedron listed twice (Gmsh writes a volume's elements once per physical group that "
             "holds it): keep the volume in one physical group, or remove the copies");
    mesh.hexes.push_back(hex);
    hex_tags.push_back(tag);
  };

  std::map<std::pair<int, long>, std::string> physical;  // (dimension, tag) -> name, "" for none
  while (r.next_line(line)) {
    if (line == "$MeshFormat") {
      auto s = r.numbers();
      int file_type = -1;
      s >> version >> file_type;
      if (version != "4.1" && version != "2.2")
        r.fail("format version " + version + " is not supported; save the mesh as version 4.1 or 2.2");
      if (file_type != 0) r.fail("binary .msh files are not supported; save the mesh as ASCII");
      r.expect_end("MeshFormat");
      have_format = true;
    } else if (line == "$PhysicalNames") {
      auto s = r.numbers();
      long count = 0;
      r.read(s, count);
      for (long i = 0; i < count; ++i) {
        if (!r.next_line(line)) r.fail("expected a physical name");
        std::istringstream ps(line);
        int dim = 0;
        long tag = 0;
        ps >> dim >> tag;
        const std::size_t open = line.find('"'), close = line.rfind('"');
        physical[{dim, tag}] = open < close ? line.substr(open + 1, close - open - 1) : "";
      }
      r.expect_end("PhysicalNames");
    } else if (line == "$Entities" && version == "4.1") {
      // Points "tag x y z", then curves, surfaces and volumes "tag minX minY minZ maxX maxY maxZ", each
      // followed by its physical tags "count tag ...".
      auto s = r.numbers();
      long counts[4] = {0, 0, 0, 0};
      r.read(s, counts[0], counts[1], counts[2], counts[3]);
      for (int dim = 0; dim < 4; ++dim)
        for (long i = 0; i < counts[dim]; ++i) {
          auto es = r.numbers();
          double skip = 0;
          for (int k = 0; k < (dim == 0 ? 4 : 7); ++k) r.read(es, skip);
          long n = 0, tag = 0;
          r.read(es, n);
          for (long k = 0; k < n; ++k) {
            r.read(es, tag);
            physical.emplace(std::make_pair(dim, std::labs(tag)), "");
          }
        }
      r.expect_end("Entities");
    } else if (line == "$Nodes" || line == "$ParametricNodes") {
      // MSH 2.2 with Mesh.SaveParametric writes $ParametricNodes: "tag x y z dim entity" and up to two
      // parametric coordinates, which the 2.2 branch below leaves unread (4.1 keeps them in $Nodes).
      const std::string section = line.substr(1);
      if (!have_format) r.fail(line + " before $MeshFormat");
      if (section == "ParametricNodes" && version != "2.2")
        r.fail("$ParametricNodes belongs to format 2.2, but the file says " + version);
      if (version == "4.1") {
        auto s = r.numbers();
        long blocks = 0, count = 0, lo = 0, hi = 0;
        r.read(s, blocks, count, lo, hi);
        for (long b = 0; b < blocks; ++b) {
          auto bs = r.numbers();
          int dim = 0, entity = 0, parametric = 0;
          long in_block = 0;
          r.read(bs, dim, entity, parametric, in_block);
          if (in_block < 0 || in_block > count)
            r.fail("a block of " + std::to_string(in_block) + " nodes, but the section announces " +
                   std::to_string(count) + " nodes in all");
          std::vector<long> tags;  // grows as tags are read: a cut-off file then fails on its lines
          for (long i = 0; i < in_block; ++i) {
            auto ts = r.numbers();
            r.read(ts, tags.emplace_back());
          }
          for (long t : tags) {
            auto cs = r.numbers();
            Vec3 p;
            r.read(cs, p[0], p[1], p[2]);
            add_node(t, p);
          }
        }
        // A count the blocks do not reach: a section cut or edited by hand.
        if (static_cast<long>(mesh.vertices.size()) != count)
          r.fail("the $Nodes section announces " + std::to_string(count) + " nodes, but its blocks hold " +
                 std::to_string(mesh.vertices.size()));
      } else {
        auto s = r.numbers();
        long count = 0;
        r.read(s, count);
        for (long i = 0; i < count; ++i) {
          auto ns = r.numbers();
          long tag = 0;
          Vec3 p;
          r.read(ns, tag, p[0], p[1], p[2]);
          add_node(tag, p);
        }
      }
      r.expect_end(section);
      have_nodes = true;
    } else if (line == "$Elements") {
      if (!have_nodes) r.fail("$Elements before $Nodes");
      std::vector<long> nodes;
      if (version == "4.1") {
        auto s = r.numbers();
        long blocks = 0, count = 0, lo = 0, hi = 0;
        r.read(s, blocks, count, lo, hi);
        long elements = 0;
        for (long b = 0; b < blocks; ++b) {
          auto bs = r.numbers();
          int dim = 0, entity = 0, type = 0;
          long in_block = 0;
          r.read(bs, dim, entity, type, in_block);
          elements += in_block;
          for (long i = 0; i < in_block; ++i) {
            auto es = r.numbers();
            long tag = 0, v = 0;
            r.read(es, tag);
            nodes.clear();
            while (es >> v) nodes.push_back(v);
            add_element(tag, type, nodes);
          }
        }
        if (elements != count)
          r.fail("the $Elements section announces " + std::to_string(count) +
                 " elements, but its blocks hold " + std::to_string(elements));
      } else {
        auto s = r.numbers();
        long count = 0;
        r.read(s, count);
        for (long i = 0; i < count; ++i) {
          auto es = r.numbers();
          long tag = 0, v = 0;
          int type = 0, num_tags = 0;
          r.read(es, tag, type, num_tags);
          for (int t = 0; t < num_tags; ++t) {
            r.read(es, v);
            if (t == 0 && v != 0) physical.emplace(std::make_pair(gmsh_element_dimension(type), v), "");
          }
          nodes.clear();
          while (es >> v) nodes.push_back(v);
          add_element(tag, type, nodes);
        }
      }
      r.expect_end("Elements");
      have_elements = true;
    }
  }
  if (!have_format) r.fail("no $MeshFormat section: not a Gmsh .msh file");
  if (!have_elements) r.fail("no $Elements section");
  check_mesh(mesh, "Gmsh mesh '" + path + "'", node_tags);
  if (tags != nullptr) {
    *tags = {std::move(node_tags), std::move(hex_tags), {}};
    for (const auto& [key, name] : physical)
      tags->physical_groups.push_back("physical group " +
                                      (name.empty() ? std::to_string(key.second) : "'" + name + "'") + " (" +
                                      std::to_string(key.first) + "-D" +
                                      (name.empty() ? "" : ", tag " + std::to_string(key.second)) + ")");
  }
  return mesh;
}

void write_hex_mesh(const std::string& path, const HexMesh& mesh, const std::vector<MeshArray>& cell_arrays,
                    const std::vector<MeshArray>& point_arrays) {
  const std::string ext = lower_extension(path);
  if (ext == ".vtu")
    write_vtu(path, mesh, cell_arrays, point_arrays);
  else if (ext == ".inp")
    write_inp(path, mesh);
  else if (ext == ".msh")
    write_msh(path, mesh);
  else
    throw InputError("cannot write hex mesh '" + path +
                     "': unknown format; give a file name ending in .vtu, .inp (Abaqus / CalculiX) or .msh "
                     "(Gmsh)");
}

HexMesh read_hex_mesh(const std::string& path, std::vector<MeshArray>* cell_arrays,
                      std::vector<MeshArray>* point_arrays, std::vector<std::string>* not_read,
                      GmshTags* tags) {
  if (lower_extension(path) != ".msh") {
    if (tags) *tags = {};
    return read_vtu(path, cell_arrays, point_arrays, not_read);
  }
  if (cell_arrays) cell_arrays->clear();
  if (point_arrays) point_arrays->clear();
  if (not_read) not_read->clear();
  return read_msh(path, tags);
}

}  // namespace hexbite
