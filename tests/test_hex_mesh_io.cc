// Hex mesh files (VTU, INP, MSH), boundary extraction and the `hexbite quality` command.
#include <gtest/gtest.h>
#include <vtkCellArray.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>

#include "common/error.h"
#include "mesher/grid_mesher.h"
#include "mesher/hex_block.h"
#include "mesher/hex_boundary.h"
#include "mesher/hex_mesh_io.h"
#include "mesher/hex_quality.h"
#include "postprocess/quality_json.h"
#include "tests/test_util.h"

namespace hexbite {
namespace {

namespace fs = std::filesystem;
using test::read_file;
using test::run_hexbite;
using test::temp_dir;
using test::write_file;

// The block with every vertex moved by up to 0.2 and values that do not round-trip through short decimals.
HexMesh perturbed_block(int nx, int ny, int nz) {
  HexMesh mesh = make_block_mesh(nx, ny, nz);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  for (Vec3& p : mesh.vertices)
    for (double& c : p) c = c * 1.1 + u(rng) / 3.0;
  return mesh;
}

const MeshArray* find_array(const std::vector<MeshArray>& arrays, const std::string& name) {
  for (const MeshArray& a : arrays)
    if (a.name == name) return &a;
  return nullptr;
}

TEST(HexMeshIo, VtuRoundTripWithArrays) {
  const HexMesh mesh = perturbed_block(3, 2, 2);
  MeshArray material{"material", 1, {}};
  for (std::size_t h = 0; h < mesh.hexes.size(); ++h) material.values.push_back(double(h % 3));
  MeshArray displacement{"displacement", 3, {}};
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v)
    for (int d = 0; d < 3; ++d) displacement.values.push_back(0.001 * v + d);

  const std::string dir = temp_dir();
  write_vtu(dir + "/a.vtu", mesh, {material}, {displacement});
  std::vector<MeshArray> cells, points;
  const HexMesh back = read_vtu(dir + "/a.vtu", &cells, &points);
  EXPECT_EQ(back.vertices, mesh.vertices);  // doubles are stored exactly
  EXPECT_EQ(back.hexes, mesh.hexes);

  const HexQualityField q = compute_hex_quality(mesh);
  ASSERT_NE(find_array(cells, "scaled_jacobian"), nullptr);
  EXPECT_EQ(find_array(cells, "scaled_jacobian")->values, q.scaled_jacobian);
  EXPECT_EQ(find_array(cells, "condition")->values, q.condition);
  EXPECT_EQ(find_array(cells, "oddy")->values, q.oddy);
  EXPECT_EQ(find_array(cells, "jacobian")->values, q.jacobian);
  ASSERT_NE(find_array(cells, "material"), nullptr);
  EXPECT_EQ(find_array(cells, "material")->values, material.values);
  ASSERT_NE(find_array(points, "displacement"), nullptr);
  EXPECT_EQ(find_array(points, "displacement")->components, 3);
  EXPECT_EQ(find_array(points, "displacement")->values, displacement.values);

  // Deterministic bytes, and no temporary file left behind.
  write_vtu(dir + "/b.vtu", mesh, {material}, {displacement});
  EXPECT_EQ(read_file(dir + "/a.vtu"), read_file(dir + "/b.vtu"));
  int files = 0;
  for (const auto& entry : fs::directory_iterator(dir)) files += entry.is_regular_file();
  EXPECT_EQ(files, 2);
}

// Names holding XML's special characters are escaped in the file: reorder wrote Name="E & nu" as it was,
// and no XML reader (hexbite's included) accepted the file it made.
TEST(HexMeshIo, VtuArrayNamesWithXmlCharactersReadBack) {
  const HexMesh mesh = make_block_mesh(1, 1, 1);
  const std::string name = "E & nu <\"x\"> 'y'";
  const std::string dir = temp_dir();
  write_vtu(dir + "/a.vtu", mesh, {{name, 1, {7.0}}}, {{name, 1, std::vector<double>(8, 2.0)}});
  std::vector<MeshArray> cells, points;
  read_vtu(dir + "/a.vtu", &cells, &points);
  ASSERT_NE(find_array(cells, name), nullptr);
  EXPECT_EQ(find_array(cells, name)->values, std::vector<double>{7.0});
  ASSERT_NE(find_array(points, name), nullptr);
  // And through the command that found it.
  const auto r = run_hexbite({"reorder", dir + "/a.vtu", "-o", dir + "/b.vtu", "-q"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  cells.clear();
  read_vtu(dir + "/b.vtu", &cells);
  EXPECT_NE(find_array(cells, name), nullptr);
}

TEST(HexMeshIo, VtuRejectsBadArrays) {
  const HexMesh mesh = make_block_mesh(1, 1, 1);
  const std::string path = temp_dir() + "/bad.vtu";
  EXPECT_THROW(write_vtu(path, mesh, {{"condition", 1, {1.0}}}), std::invalid_argument);
  EXPECT_THROW(write_vtu(path, mesh, {{"material", 1, {1.0, 2.0}}}), std::invalid_argument);
  EXPECT_FALSE(fs::exists(path));
}

// A hand-written ASCII VTU file with the given cell type, connectivity, offsets and point coordinates.
std::string ascii_vtu(int cells, const std::string& types, const std::string& connectivity,
                      const std::string& offsets, const std::string& points, int num_points) {
  std::ostringstream s;
  s << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" "
       "byte_order=\"LittleEndian\">\n"
    << "<UnstructuredGrid><Piece NumberOfPoints=\"" << num_points << "\" NumberOfCells=\"" << cells << "\">\n"
    << "<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">" << points
    << "</DataArray></Points>\n<Cells>\n"
    << "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">" << connectivity << "</DataArray>\n"
    << "<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">" << offsets << "</DataArray>\n"
    << "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">" << types << "</DataArray>\n"
    << "</Cells></Piece></UnstructuredGrid></VTKFile>\n";
  return s.str();
}

const char* kCubePoints = "0 0 0 1 0 0 1 1 0 0 1 0 0 0 1 1 0 1 1 1 1 0 1 1";

TEST(HexMeshIo, VtuReaderErrors) {
  const std::string dir = temp_dir();
  // A hand-written valid file reads, which shows that the error cases below fail for their own reason.
  write_file(dir + "/ok.vtu", ascii_vtu(1, "12", "0 1 2 3 4 5 6 7", "8", kCubePoints, 8));
  EXPECT_EQ(read_vtu(dir + "/ok.vtu").hexes.size(), 1u);

  std::string msg = test::message_of<InputError>([&] { read_vtu(dir + "/missing.vtu"); });
  EXPECT_NE(msg.find("missing.vtu"), std::string::npos);
  EXPECT_NE(msg.find("does not exist"), std::string::npos);

  write_file(dir + "/garbage.vtu", "this is not a mesh\n\x01\x02\x03");
  msg = test::message_of<InputError>([&] { read_vtu(dir + "/garbage.vtu"); });
  EXPECT_NE(msg.find("garbage.vtu"), std::string::npos);
  EXPECT_NE(msg.find("not a VTK XML unstructured grid"), std::string::npos);

  write_file(dir + "/empty.vtu", "");
  EXPECT_NE(test::message_of<InputError>([&] { read_vtu(dir + "/empty.vtu"); }).find("empty"),
            std::string::npos);

  write_file(dir + "/tetra.vtu", ascii_vtu(2, "12 10", "0 1 2 3 4 5 6 7 0 1 3 4", "8 12", kCubePoints, 8));
  msg = test::message_of<InputError>([&] { read_vtu(dir + "/tetra.vtu"); });
  EXPECT_NE(msg.find("cell 1 is a vtkTetra"), std::string::npos) << msg;
  EXPECT_NE(msg.find("type 10"), std::string::npos) << msg;

  write_file(dir + "/range.vtu", ascii_vtu(1, "12", "0 1 2 3 4 5 6 9", "8", kCubePoints, 8));
  msg = test::message_of<InputError>([&] { read_vtu(dir + "/range.vtu"); });
  EXPECT_NE(msg.find("vertex 9"), std::string::npos) << msg;

  write_file(dir + "/nan.vtu", ascii_vtu(1, "12", "0 1 2 3 4 5 6 7", "8",
                                         "0 0 0 1 0 0 1 1 0 0 1 0 0 0 1 1 0 1 1 nan 1 0 1 1", 8));
  msg = test::message_of<InputError>([&] { read_vtu(dir + "/nan.vtu"); });
  EXPECT_NE(msg.find("vertex 6"), std::string::npos) << msg;
  EXPECT_NE(msg.find("NaN"), std::string::npos) << msg;

  // A truncated binary file: the header promises data that is not there.
  write_vtu(dir + "/full.vtu", make_block_mesh(2, 2, 2));
  const std::string full = read_file(dir + "/full.vtu");
  write_file(dir + "/truncated.vtu", full.substr(0, full.size() / 2));
  msg = test::message_of<InputError>([&] { read_vtu(dir + "/truncated.vtu"); });
  EXPECT_NE(msg.find("truncated.vtu"), std::string::npos) << msg;
  EXPECT_NE(msg.find("damaged or truncated"), std::string::npos) << msg;

  // A cell data array too short for the cells, in a piece without <PointData> (as meshio writes a mesh with
  // cell data only): VTK 9.1 ended in a segmentation fault. The same array of the right length reads.
  const std::string piece =
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" "
      "byte_order=\"LittleEndian\" header_type=\"UInt32\">\n<UnstructuredGrid><Piece NumberOfPoints=\"8\" "
      "NumberOfCells=\"1\">\n<CellData>ARRAY</CellData>\n<Points><DataArray type=\"Float64\" "
      "NumberOfComponents=\"3\" format=\"ascii\">" +
      std::string(kCubePoints) +
      "</DataArray></Points>\n<Cells><DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">0 1 2 "
      "3 4 5 6 7</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">8</DataArray>\n"
      "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">12</DataArray></Cells>\n"
      "</Piece></UnstructuredGrid></VTKFile>\n";
  const auto with_array = [&](const std::string& array) {
    std::string text = piece;
    return text.replace(text.find("ARRAY"), 5, array);
  };
  write_file(dir + "/short.vtu", with_array("<DataArray type=\"Float64\" Name=\"region\" format=\"ascii\">"
                                            "</DataArray>"));
  msg = test::message_of<InputError>([&] { read_vtu(dir + "/short.vtu"); });
  EXPECT_NE(msg.find("the data of its array 'region' holds 0 values where its piece's counts give 1"),
            std::string::npos)
      << msg;
  write_file(dir + "/cells_only.vtu",
             with_array("<DataArray type=\"Float64\" Name=\"region\" format=\"ascii\">7</DataArray>"));
  EXPECT_EQ(read_vtu(dir + "/cells_only.vtu").hexes.size(), 1u);
  // An array without a name: VTK read no cells at all ("holds no hexahedra").
  write_file(dir + "/unnamed.vtu", with_array("<DataArray type=\"Float64\" format=\"ascii\">7</DataArray>"));
  msg = test::message_of<InputError>([&] { read_vtu(dir + "/unnamed.vtu"); });
  EXPECT_NE(
      msg.find(
          "a data array in its <CellData> of piece 0 has no name (its Name attribute is missing or empty)"),
      std::string::npos)
      << msg;
}

// VTK reads as many values as a piece's counts give and ignores the rest: a 2-hex file whose NumberOfCells
// said 1 read as 1 hex (exit 0) in every encoding but raw appended data. Now each array's length is checked.
TEST(HexMeshIo, VtuArraysLongerThanTheCountsAreRefused) {
  const std::string dir = temp_dir();
  const std::string two = ascii_vtu(2, "12 12", "0 1 2 3 4 5 6 7 1 8 9 2 5 10 11 6", "8 16",
                                    "0 0 0 1 0 0 1 1 0 0 1 0 0 0 1 1 0 1 1 1 1 0 1 1 "
                                    "2 0 0 2 1 0 2 0 1 2 1 1",
                                    12);
  write_file(dir + "/two.vtu", two);
  EXPECT_EQ(read_vtu(dir + "/two.vtu").hexes.size(), 2u);
  const auto one_cell = [](std::string text) {
    return text.replace(text.find("NumberOfCells=\"2\""), 17, "NumberOfCells=\"1\"");
  };
  write_file(dir + "/ascii.vtu", one_cell(two));
  std::string msg = test::message_of<InputError>([&] { read_vtu(dir + "/ascii.vtu"); });
  EXPECT_NE(msg.find("ascii.vtu': the data of its array 'offsets' holds more than the 1 values its piece's "
                     "counts give; the file is damaged"),
            std::string::npos)
      << msg;
  // The same through VTK's writer, inline base64 and appended base64, compressed or not.
  vtkNew<vtkPoints> points;
  for (const Vec3& p : make_block_mesh(2, 1, 1).vertices) points->InsertNextPoint(p.data());
  vtkNew<vtkUnstructuredGrid> grid;
  grid->SetPoints(points);
  for (const std::array<int, 8>& hex : make_block_mesh(2, 1, 1).hexes) {
    const vtkIdType ids[8] = {hex[0], hex[1], hex[2], hex[3], hex[4], hex[5], hex[6], hex[7]};
    grid->InsertNextCell(VTK_HEXAHEDRON, 8, ids);
  }
  for (const bool appended : {false, true})
    for (const bool compressed : {false, true}) {
      vtkNew<vtkXMLUnstructuredGridWriter> writer;
      writer->SetInputData(grid);
      writer->WriteToOutputStringOn();
      if (appended) {
        writer->SetDataModeToAppended();
        writer->EncodeAppendedDataOn();
      } else {
        writer->SetDataModeToBinary();
      }
      if (!compressed) writer->SetCompressorTypeToNone();
      ASSERT_EQ(writer->Write(), 1);
      const std::string name = std::string(appended ? "appended" : "inline") + (compressed ? "_z" : "");
      write_file(dir + "/" + name + ".vtu", writer->GetOutputString());
      EXPECT_EQ(read_vtu(dir + "/" + name + ".vtu").hexes.size(), 2u) << name;
      write_file(dir + "/" + name + "_1.vtu", one_cell(writer->GetOutputString()));
      msg = test::message_of<InputError>([&] { read_vtu(dir + "/" + name + "_1.vtu"); });
      EXPECT_NE(msg.find("holds more than the 1 values its piece's counts give"), std::string::npos)
          << name << ": " << msg;
    }
}

// '>' is legal in an XML attribute, but VTK's reader takes it for the end of an inline array's element and
// said "Cannot read cell data array "E>nu" from PointData". The message now names the name as the cause;
// an empty Name is called empty.
TEST(HexMeshIo, VtuArrayNamesVtkCannotReadAreNamed) {
  const std::string dir = temp_dir();
  std::string text = ascii_vtu(1, "12", "0 1 2 3 4 5 6 7", "8", kCubePoints, 8);
  const auto with_cell_array = [&](const std::string& name) {
    std::string t = text;
    return t.insert(t.find("<Points>"),
                    "<PointData></PointData><CellData><DataArray type=\"Float64\" Name=\"" + name +
                        "\" format=\"ascii\">7</DataArray></CellData>\n");
  };
  write_file(dir + "/gt.vtu", with_cell_array("E>nu"));
  std::string msg = test::message_of<InputError>([&] { read_vtu(dir + "/gt.vtu"); });
  EXPECT_NE(msg.find("its cell array 'E>nu' is stored in the XML (format=\"ascii\") and its name holds a "
                     "'>'"),
            std::string::npos)
      << msg;
  write_file(dir + "/empty_name.vtu", with_cell_array(""));
  msg = test::message_of<InputError>([&] { read_vtu(dir + "/empty_name.vtu"); });
  EXPECT_NE(msg.find("has no name (its Name attribute is missing or empty)"), std::string::npos) << msg;
  // Written by hexbite, such a name reads back (it is escaped, and the data is appended).
  write_vtu(dir + "/ok.vtu", make_block_mesh(1, 1, 1), {{"E>nu", 1, {7.0}}});
  std::vector<MeshArray> cells;
  read_vtu(dir + "/ok.vtu", &cells);
  EXPECT_NE(find_array(cells, "E>nu"), nullptr);
}

// A .vtu with its boundary quads, or of voxels, was refused ("cell 1 is a vtkQuad"), where the .msh reader
// skips boundary quads: surface cells are skipped (and their values of cell arrays), a voxel is read as the
// hexahedron it is, and another volume cell is refused with what to do.
TEST(HexMeshIo, VtuSurfaceCellsAreSkippedAndVoxelsRead) {
  const std::string dir = temp_dir();
  write_file(dir + "/voxel.vtu", ascii_vtu(1, "11", "0 1 3 2 4 5 7 6", "8", kCubePoints, 8));
  const HexMesh voxel = read_vtu(dir + "/voxel.vtu");
  ASSERT_EQ(voxel.hexes.size(), 1u);
  EXPECT_EQ(voxel.hexes[0], (std::array<int, 8>{0, 1, 2, 3, 4, 5, 6, 7}));
  EXPECT_GT(compute_hex_quality(voxel).scaled_jacobian[0], 0.99);

  std::string text = ascii_vtu(3, "9 12 5", "0 1 2 3 0 1 2 3 4 5 6 7 4 5 6", "4 12 15", kCubePoints, 8);
  text.insert(text.find("<Points>"),
              "<PointData></PointData><CellData><DataArray type=\"Int32\" "
              "Name=\"region\" format=\"ascii\">5 9 6</DataArray></CellData>\n");
  write_file(dir + "/with_quads.vtu", text);
  std::vector<MeshArray> cells;
  const HexMesh mesh = read_vtu(dir + "/with_quads.vtu", &cells);
  ASSERT_EQ(mesh.hexes.size(), 1u);
  ASSERT_NE(find_array(cells, "region"), nullptr);
  EXPECT_EQ(find_array(cells, "region")->values, std::vector<double>{9});

  write_file(dir + "/wedge.vtu", ascii_vtu(1, "13", "0 1 2 4 5 6", "6", kCubePoints, 8));
  const std::string msg = test::message_of<InputError>([&] { read_vtu(dir + "/wedge.vtu"); });
  EXPECT_NE(msg.find("cell 0 is a vtkWedge (VTK cell type 13); only hexahedra"), std::string::npos) << msg;
  EXPECT_NE(msg.find("Mesh.SubdivisionAlgorithm = 2"), std::string::npos) << msg;
}

// Before, a file without hexahedra read as an empty mesh (quality printed n/a, refine wrote an empty mesh,
// exit 0), a hex listing a vertex twice was measured as "inverted", and an oversized Gmsh node block ended
// in std::bad_alloc (exit 1, neither file nor line named).
TEST(HexMeshIo, ReadersRejectMeshesWithoutHexesOrWithCollapsedHexes) {
  const std::string dir = temp_dir();
  write_file(dir + "/none.vtu", ascii_vtu(0, "", "", "", kCubePoints, 8));
  std::string msg = test::message_of<InputError>([&] { read_vtu(dir + "/none.vtu"); });
  EXPECT_NE(msg.find("none.vtu' holds no hexahedra (8 points"), std::string::npos) << msg;

  write_file(dir + "/collapsed.vtu", ascii_vtu(1, "12", "0 1 2 3 4 5 6 6", "8", kCubePoints, 8));
  msg = test::message_of<InputError>([&] { read_vtu(dir + "/collapsed.vtu"); });
  EXPECT_NE(msg.find("hexahedron 0 lists vertex 6 twice (corners 6 and 7)"), std::string::npos) << msg;

  const std::string header =
      "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n8\n1 0 0 0\n2 1 0 0\n3 1 1 0\n4 0 1 0\n"
      "5 0 0 1\n6 1 0 1\n7 1 1 1\n8 0 1 1\n$EndNodes\n$Elements\n1\n";
  write_file(dir + "/quads.msh", header + "1 3 2 0 1 1 2 3 4\n$EndElements\n");
  msg = test::message_of<InputError>([&] { read_msh(dir + "/quads.msh"); });
  EXPECT_NE(msg.find("quads.msh' holds no hexahedra"), std::string::npos) << msg;
  write_file(dir + "/collapsed.msh", header + "1 5 2 0 1 1 2 3 4 5 6 6 8\n$EndElements\n");
  msg = test::message_of<InputError>([&] { read_msh(dir + "/collapsed.msh"); });
  // By the file's element and node tags and its line (was "hexahedron 0 lists vertex 5": 0-based numbers).
  EXPECT_NE(msg.find("line 17: hexahedron 1 lists node 6 twice (corners 6 and 7 of 8)"), std::string::npos)
      << msg;
  // A hex listed twice (Gmsh writes a volume's elements once per physical group) was read as two hexes:
  // twice the volume, every node interior, refine doubled it and reorder failed with internal text.
  std::string twice = header;
  twice.replace(twice.rfind("$Elements\n1\n"), 12, "$Elements\n2\n");
  write_file(dir + "/twice.msh",
             twice + "1 5 2 1 1 1 2 3 4 5 6 7 8\n2 5 2 2 1 5 6 7 8 1 2 3 4\n$EndElements\n");
  msg = test::message_of<InputError>([&] { read_msh(dir + "/twice.msh"); });
  EXPECT_NE(msg.find("line 18: hexahedron 2 has the same 8 nodes as hexahedron 1 (line 17): a hexahedron "
                     "listed twice"),
            std::string::npos)
      << msg;
  write_file(dir + "/twice.vtu",
             ascii_vtu(2, "12 12", "0 1 2 3 4 5 6 7 4 5 6 7 0 1 2 3", "8 16", kCubePoints, 8));
  msg = test::message_of<InputError>([&] { read_vtu(dir + "/twice.vtu"); });
  EXPECT_NE(msg.find("hexahedra 0 and 1 (0-based) have the same 8 vertices"), std::string::npos) << msg;
  // A node count the blocks do not reach was read without a word.
  write_file(dir + "/count.msh",
             "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 99 1 99\n3 1 0 1\n1\n0 0 0\n$EndNodes\n");
  msg = test::message_of<InputError>([&] { read_msh(dir + "/count.msh"); });
  EXPECT_NE(msg.find("the $Nodes section announces 99 nodes, but its blocks hold 1"), std::string::npos)
      << msg;

  for (const char* count : {"1000000000000000", "-5"}) {
    write_file(dir + "/block.msh", "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 1 1 1\n3 1 0 " +
                                       std::string(count) + "\n1\n0 0 0\n$EndNodes\n");
    msg = test::message_of<InputError>([&] { read_msh(dir + "/block.msh"); });
    EXPECT_NE(msg.find("line 6: a block of " + std::string(count) + " nodes"), std::string::npos) << msg;
  }
}

// A coordinate "nan" used to be reported as "expected more numbers on this line", as if the line were short.
TEST(HexMeshIo, MshTokensThatAreNoNumbersAreNamed) {
  const std::string dir = temp_dir();
  const auto message = [&](const std::string& node_line) {
    write_file(dir + "/bad.msh",
               "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n2\n1 0 0 0\n" + node_line + "\n$EndNodes\n");
    return test::message_of<InputError>([&] { read_msh(dir + "/bad.msh"); });
  };
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"2 1 nan 0", "line 7: 'nan' is not a finite number"},
      {"2 1 -inf 0", "line 7: '-inf' is not a finite number"},
      {"2 1 1e999 0", "line 7: '1e999' is out of range for a number"},
      {"2.5 1 0 0", "line 7: '2.5' is not a whole number"},
      {"2 1 0 0x", "line 7: '0x' is not a number"},
      {"2 1 0", "line 7: expected more numbers on this line"}};
  for (const auto& [line, expected] : cases) {
    const std::string msg = message(line);
    EXPECT_NE(msg.find("bad.msh', " + expected), std::string::npos) << line << ": " << msg;
  }
  write_file(dir + "/signed.msh",
             "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
             "$Nodes\n1\n+1 +1.5 -2e+1 0\n$EndNodes\n"
             "$Elements\n0\n$EndElements\n");
  EXPECT_NE(test::message_of<InputError>([&] { read_msh(dir + "/signed.msh"); }).find("holds no hexahedra"),
            std::string::npos);  // signs and exponents as C's strtod takes them are numbers
}

// A string array with fewer values than points crashed VTK's reader (segmentation fault). No command uses
// string arrays, so it is not read; the numeric array beside it is.
TEST(HexMeshIo, ShortStringArrayIsSkippedNotACrash) {
  const std::string dir = temp_dir();
  std::string labelled = ascii_vtu(1, "12", "0 1 2 3 4 5 6 7", "8", kCubePoints, 8);
  labelled.insert(labelled.find("<Points>"),
                  "<PointData><DataArray type=\"String\" Name=\"label\" format=\"ascii\">97 0</DataArray>"
                  "</PointData><CellData><DataArray type=\"Float64\" Name=\"E\" format=\"ascii\">17000"
                  "</DataArray></CellData>");
  write_file(dir + "/labelled.vtu", labelled);
  std::vector<MeshArray> cell_arrays, point_arrays;
  EXPECT_EQ(read_vtu(dir + "/labelled.vtu", &cell_arrays, &point_arrays).hexes.size(), 1u);
  ASSERT_EQ(cell_arrays.size(), 1u);
  EXPECT_EQ(cell_arrays[0].name, "E");
  EXPECT_TRUE(point_arrays.empty());
}

// A damaged point count in the header made VTK allocate petabytes ("failed: std::bad_alloc", no file named;
// then "do not fit in memory", exit 1): refused as bad input, naming the count.
TEST(HexMeshIo, ImpossiblePointCountNamesTheFile) {
  const std::string dir = temp_dir();
  std::string vtu = ascii_vtu(1, "12", "0 1 2 3 4 5 6 7", "8", kCubePoints, 8);
  vtu.replace(vtu.find("NumberOfPoints=\"8\""), 18, "NumberOfPoints=\"1000000000000000\"");
  write_file(dir + "/huge.vtu", vtu);
  const std::string msg = test::message_of<InputError>([&] { read_vtu(dir + "/huge.vtu"); });
  EXPECT_NE(
      msg.find(
          "huge.vtu': its <Piece> announces NumberOfPoints=\"1000000000000000\", more than the 2^31 - 1"),
      std::string::npos)
      << msg;
}

// The fuzzer's damaged compressed VTUs: a negative count, one wrong array offset (both a segmentation
// fault in VTK's reader, exit 139), a negative component count and bytes inserted into the appended data
// (both "vector::..." from the C++ library, exit 1). Each is now an InputError naming the file.
TEST(HexMeshIo, DamagedAppendedDataIsRefusedNotACrash) {
  const std::string dir = temp_dir();
  write_vtu(dir + "/m.vtu", make_block_mesh(2, 2, 2));
  const std::string good = test::read_file(dir + "/m.vtu");
  const auto damaged = [&](const std::string& name, const std::string& from, const std::string& to) {
    std::string text = good;
    const std::size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
    write_file(dir + "/" + name, text);
    return test::message_of<InputError>([&] { read_vtu(dir + "/" + name); });
  };
  EXPECT_NE(damaged("np.vtu", "NumberOfPoints=\"27\"", "NumberOfPoints=\"-1\"")
                .find("np.vtu': its <Piece> announces NumberOfPoints=\"-1\", a negative count"),
            std::string::npos);
  EXPECT_NE(damaged("comp.vtu", "NumberOfComponents=\"3\"", "NumberOfComponents=\"-1\"")
                .find("comp.vtu': its data array 'Points' announces NumberOfComponents=\"-1\""),
            std::string::npos);
  // The second array's offset (the first is at 0) moved to 1.
  const std::size_t second = good.find("offset=\"", good.find("offset=\"0\"") + 10);
  const std::string offset = good.substr(second, good.find('"', second + 8) + 1 - second);
  EXPECT_NE(damaged("off.vtu", offset, "offset=\"1\"").find("off.vtu': the data of its array '"),
            std::string::npos);
  const std::size_t data = good.find('_', good.find("<AppendedData")) + 1;
  EXPECT_NE(damaged("ins.vtu", good.substr(data, 8), "ABCDEFGHIJ" + good.substr(data, 8))
                .find("ins.vtu': the data of its array '"),
            std::string::npos);
  // A file VTK's own writer makes (raw appended data, uncompressed, 32-bit headers) still reads.
  const HexMesh cube = make_block_mesh(1, 1, 1);
  vtkNew<vtkPoints> points;
  for (const Vec3& p : cube.vertices) points->InsertNextPoint(p[0], p[1], p[2]);
  vtkNew<vtkUnstructuredGrid> grid;
  grid->SetPoints(points);
  vtkIdType hex[8];
  for (int k = 0; k < 8; ++k) hex[k] = cube.hexes[0][k];
  grid->InsertNextCell(VTK_HEXAHEDRON, 8, hex);
  vtkNew<vtkXMLUnstructuredGridWriter> writer;
  writer->SetInputData(grid);
  writer->SetFileName((dir + "/vtk.vtu").c_str());
  writer->SetDataModeToAppended();
  writer->EncodeAppendedDataOff();
  writer->SetCompressorTypeToNone();
  writer->SetHeaderTypeToUInt32();
  ASSERT_EQ(writer->Write(), 1);
  EXPECT_EQ(read_vtu(dir + "/vtk.vtu").hexes.size(), 1u);
}

// Parses the *NODE, *ELEMENT and set blocks of an .inp file written by write_inp.
struct ParsedInp {
  std::vector<Vec3> nodes;
  std::vector<std::array<int, 8>> elements;
  std::map<std::string, std::vector<int>> sets;  // keyword "NSET:name" / "ELSET:name" -> 1-based ids
  std::string element_type;
};

ParsedInp parse_inp(const std::string& text) {
  ParsedInp p;
  std::istringstream in(text);
  std::string line, block;
  while (std::getline(in, line)) {
    if (line.rfind("**", 0) == 0) continue;
    if (line[0] == '*') {
      if (line.rfind("*NODE", 0) == 0)
        block = "NODE";
      else if (line.rfind("*ELEMENT", 0) == 0) {
        block = "ELEMENT";
        p.element_type = line.substr(line.find("TYPE=") + 5, 4);
      } else {
        const auto eq = line.find('=');
        block = line.substr(1, line.find(',') - 1) + ":" + line.substr(eq + 1);
      }
      continue;
    }
    for (char& c : line)
      if (c == ',') c = ' ';
    std::istringstream s(line);
    if (block == "NODE") {
      int id;
      Vec3 x;
      s >> id >> x[0] >> x[1] >> x[2];
      EXPECT_EQ(id, static_cast<int>(p.nodes.size()) + 1);
      p.nodes.push_back(x);
    } else if (block == "ELEMENT") {
      int id;
      std::array<int, 8> e;
      s >> id;
      for (int& v : e) {
        s >> v;
        --v;
      }
      p.elements.push_back(e);
    } else {
      int id;
      int count = 0;
      while (s >> id) {
        p.sets[block].push_back(id);
        ++count;
      }
      EXPECT_LE(count, 16);
    }
  }
  return p;
}

TEST(HexMeshIo, InpExport) {
  const HexMesh mesh = perturbed_block(3, 2, 2);
  IndexSet bottom{"BOTTOM", {}};
  for (int v = 0; v < 12; ++v) bottom.ids.push_back(v);  // the z = 0 layer: 4 x 3 vertices
  IndexSet left{"left_cells", {0, 3, 6, 9}};
  const std::string path = temp_dir() + "/m.inp";
  write_inp(path, mesh, {bottom, {"many", std::vector<int>(40, 1)}}, {left});
  const ParsedInp p = parse_inp(read_file(path));
  EXPECT_EQ(p.element_type, "C3D8");
  // CalculiX reads at most 20 characters per field, so coordinates carry 13 significant digits.
  ASSERT_EQ(p.nodes.size(), mesh.vertices.size());
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(p.nodes[v][c], mesh.vertices[v][c], 1e-12) << "node " << v;
  EXPECT_EQ(p.elements, mesh.hexes);
  std::vector<int> bottom_1based;
  for (int v : bottom.ids) bottom_1based.push_back(v + 1);
  EXPECT_EQ(p.sets.at("NSET:BOTTOM"), bottom_1based);
  EXPECT_EQ(p.sets.at("ELSET:left_cells"), (std::vector<int>{1, 4, 7, 10}));
  EXPECT_EQ(p.sets.at("NSET:many").size(), 40u);

  EXPECT_THROW(write_inp(path, mesh, {{"1bad", {0}}}), std::invalid_argument);
  EXPECT_THROW(write_inp(path, mesh, {{"nall", {0}}}), std::invalid_argument);
  // CalculiX printed an 80-character set name blank in model.dat ("total force ... for set  and time").
  EXPECT_NO_THROW(write_inp(path, mesh, {{std::string(79, 'A'), {0}}}));
  EXPECT_THROW(write_inp(path, mesh, {{std::string(80, 'A'), {0}}}), std::invalid_argument);
  EXPECT_THROW(write_inp(path, mesh, {}, {{"E", {12}}}), std::invalid_argument);
}

TEST(HexMeshIo, MshRoundTrip) {
  const HexMesh mesh = perturbed_block(3, 2, 2);
  const std::string dir = temp_dir();
  write_msh(dir + "/m.msh", mesh);
  const HexMesh back = read_msh(dir + "/m.msh");
  EXPECT_EQ(back.vertices, mesh.vertices);
  EXPECT_EQ(back.hexes, mesh.hexes);
  write_msh(dir + "/n.msh", mesh);
  EXPECT_EQ(read_file(dir + "/m.msh"), read_file(dir + "/n.msh"));
}

// write_hex_mesh and read_hex_mesh choose the format by the file name, in any case; the arrays go only into
// and come only from a .vtu.
TEST(HexMeshIo, FormatByFileName) {
  const HexMesh mesh = perturbed_block(3, 2, 2);
  const std::string dir = temp_dir();
  const MeshArray tag{"tag", 1, std::vector<double>(mesh.hexes.size(), 7.0)};
  write_hex_mesh(dir + "/m.vtu", mesh, {tag});
  write_hex_mesh(dir + "/m.MSH", mesh, {tag});
  write_hex_mesh(dir + "/m.inp", mesh);
  std::vector<MeshArray> cells, points;
  const HexMesh from_vtu = read_hex_mesh(dir + "/m.vtu", &cells, &points);
  EXPECT_EQ(from_vtu.hexes, mesh.hexes);
  ASSERT_NE(find_array(cells, "tag"), nullptr);
  const HexMesh from_msh = read_hex_mesh(dir + "/m.MSH", &cells, &points);
  EXPECT_EQ(from_msh.vertices, mesh.vertices);
  EXPECT_EQ(from_msh.hexes, mesh.hexes);
  EXPECT_TRUE(cells.empty());
  EXPECT_EQ(read_file(dir + "/m.MSH").rfind("$MeshFormat\n4.1", 0), 0u);
  const ParsedInp inp = parse_inp(read_file(dir + "/m.inp"));
  EXPECT_EQ(inp.elements, mesh.hexes);
  const std::string message = test::message_of<InputError>([&] { write_hex_mesh(dir + "/m.stl", mesh); });
  EXPECT_NE(message.find("give a file name ending in .vtu, .inp (Abaqus / CalculiX) or .msh"),
            std::string::npos)
      << message;
  EXPECT_FALSE(fs::exists(dir + "/m.stl"));
}

// The commands that write a hex mesh write it as .vtu, .inp or .msh by the name after -o, and the commands
// that read one read a .msh too: a mesh exported to Gmsh can be refined and reordered (before, only .vtu:
// "this command writes .vtu", and refine and reorder read .vtu only).
TEST(HexMeshIo, MeshRefineAndReorderWriteEveryFormat) {
  const std::string dir = temp_dir();
  write_file(dir + "/cubes.obj", test::cubes_obj(1));
  for (const char* ext : {".vtu", ".inp", ".msh"}) {
    const test::CommandResult r =
        run_hexbite({"mesh", dir + "/cubes.obj", "--target-hexes", "200", "-o", dir + "/m" + ext, "-q"});
    ASSERT_EQ(r.exit_code, 0) << ext << ": " << r.err;
  }
  const HexMesh vtu = read_vtu(dir + "/m.vtu");
  EXPECT_EQ(read_msh(dir + "/m.msh").hexes, vtu.hexes);
  EXPECT_EQ(parse_inp(read_file(dir + "/m.inp")).elements, vtu.hexes);

  test::CommandResult r =
      run_hexbite({"refine", dir + "/m.msh", "--surface", dir + "/cubes.obj", "-o", dir + "/fine.inp", "-q"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(parse_inp(read_file(dir + "/fine.inp")).elements.size(), 8 * vtu.hexes.size());
  r = run_hexbite({"reorder", dir + "/m.msh", "-o", dir + "/rcm.msh", "--method", "rcm", "-q"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(read_msh(dir + "/rcm.msh").hexes.size(), vtu.hexes.size());

  r = run_hexbite({"mesh", dir + "/cubes.obj", "-o", dir + "/m.stl"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("this command writes .vtu, .inp or .msh"), std::string::npos) << r.err;
}

TEST(HexMeshIo, MshVersion22WithLowerDimensionalElements) {
  const std::string dir = temp_dir();
  // Gmsh writes boundary quads and points beside the hexes; node tags need not be contiguous.
  write_file(dir + "/v22.msh",
             "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n8\n"
             "10 0 0 0\n11 1 0 0\n12 1 1 0\n13 0 1 0\n14 0 0 1\n15 1 0 1\n16 1 1 1\n17 0 1 1\n$EndNodes\n"
             "$Elements\n3\n1 15 2 0 1 10\n2 3 2 0 1 10 13 12 11\n3 5 2 1 1 10 11 12 13 14 15 16 "
             "17\n$EndElements\n");
  const HexMesh m = read_msh(dir + "/v22.msh");
  ASSERT_EQ(m.hexes.size(), 1u);
  // Trailing blanks after a section name, which Gmsh accepts, hid the section ("$Elements before $Nodes").
  std::string blanks = read_file(dir + "/v22.msh");
  blanks.replace(blanks.find("$Nodes\n"), 7, "$Nodes \r\n");
  blanks.replace(blanks.find("$EndElements\n"), 13, "$EndElements\t\n");
  write_file(dir + "/blanks.msh", blanks);
  EXPECT_EQ(read_msh(dir + "/blanks.msh").hexes, m.hexes);
  EXPECT_EQ(m.hexes[0], (std::array<int, 8>{0, 1, 2, 3, 4, 5, 6, 7}));
  EXPECT_EQ(hex_quality(m.vertices.data()).scaled_jacobian, 1.0);

  write_file(
      dir + "/tet.msh",
      "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n"
      "$Elements\n1\n7 4 2 0 1 1 2 3 4\n$EndElements\n");
  std::string msg = test::message_of<InputError>([&] { read_msh(dir + "/tet.msh"); });
  // The type by name, and what to do (was "is a volume element of Gmsh type 4").
  EXPECT_NE(msg.find("line 13: element 7 is a 4-node tetrahedron (Gmsh type 4); only 8-node hexahedra (type "
                     "5) are accepted: give an all-hex mesh (in Gmsh, for instance Mesh.SubdivisionAlgorithm "
                     "= 2"),
            std::string::npos)
      << msg;
  EXPECT_NE(msg.find("or mesh the surface with hexbite mesh"), std::string::npos) << msg;

  write_file(dir + "/junk.msh", "hello\n");
  EXPECT_NE(test::message_of<InputError>([&] { read_msh(dir + "/junk.msh"); }).find("not a Gmsh"),
            std::string::npos);
}

// Gmsh physical groups were dropped without a word by reorder and refine (a .vtu input's arrays get a
// warning): they are read, with their names, and named in a warning.
TEST(HexMeshIo, MshPhysicalGroupsAreNamedWhenNotCarriedOver) {
  const std::string dir = temp_dir();
  write_file(
      dir + "/v22.msh",
      "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n2\n2 5 \"floor\"\n3 1 \"cortical bone\"\n"
      "$EndPhysicalNames\n$Nodes\n8\n1 0 0 0\n2 1 0 0\n3 1 1 0\n4 0 1 0\n5 0 0 1\n6 1 0 1\n7 1 1 1\n"
      "8 0 1 1\n$EndNodes\n$Elements\n2\n1 3 2 5 1 1 4 3 2\n2 5 2 1 1 1 2 3 4 5 6 7 8\n$EndElements\n");
  GmshTags tags;
  read_msh(dir + "/v22.msh", &tags);
  EXPECT_EQ(tags.physical_groups, (std::vector<std::string>{"physical group 'floor' (2-D, tag 5)",
                                                            "physical group 'cortical bone' (3-D, tag 1)"}));
  write_file(dir + "/v41.msh",
             "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n0 0 0 1\n1 0 0 0 1 1 1 1 7 0\n$EndEntities\n"
             "$Nodes\n1 8 1 8\n3 1 0 8\n1\n2\n3\n4\n5\n6\n7\n8\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n"
             "1 1 1\n0 1 1\n$EndNodes\n$Elements\n1 1 1 1\n3 1 5 1\n1 1 2 3 4 5 6 7 8\n$EndElements\n");
  read_msh(dir + "/v41.msh", &tags);
  EXPECT_EQ(tags.physical_groups, std::vector<std::string>{"physical group 7 (3-D)"});
  // hexbite's own .msh has none.
  write_msh(dir + "/own.msh", make_block_mesh(1, 1, 1));
  read_msh(dir + "/own.msh", &tags);
  EXPECT_TRUE(tags.physical_groups.empty());

  for (const char* command : {"reorder", "refine"}) {
    const auto r = run_hexbite({command, dir + "/v22.msh", "-o", dir + "/out.msh", "-q"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("warning: not carried over to " + dir +
                         "/out.msh: physical group 'floor' (2-D, tag 5), "
                         "physical group 'cortical bone' (3-D, tag 1)"),
              std::string::npos)
        << command << ": " << r.err;
  }
}

// Two hexes that touch but do not share their corner nodes (two Gmsh volumes meshed without Coherence Mesh)
// were read as one mesh: quality counted the face between them as boundary and refine --surface moved its
// nodes onto the surface, so the halves overlapped. Unused points may still coincide.
TEST(HexMeshIo, CoincidentNodesOfHexesAreRefused) {
  const std::string dir = temp_dir();
  const std::string points = std::string(kCubePoints) + " 1 0 0 2 0 0 2 1 0 1 1 0 1 0 1 2 0 1 2 1 1 1 1 1";
  write_file(dir + "/two.vtu",
             ascii_vtu(2, "12 12", "0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15", "8 16", points, 16));
  std::string msg = test::message_of<InputError>([&] { read_vtu(dir + "/two.vtu"); });
  EXPECT_NE(msg.find("two.vtu': vertices 1 and 8 (0-based) lie at the same place (1, 0, 0) mm but are "
                     "distinct"),
            std::string::npos)
      << msg;
  EXPECT_NE(msg.find("4 such pairs in all: merge coincident nodes where the mesh was made (in Gmsh: "
                     "'Coherence Mesh;'"),
            std::string::npos)
      << msg;
  // The same two hexes joined (shared nodes) read, with the now unused copies at the same places.
  write_file(dir + "/joined.vtu",
             ascii_vtu(2, "12 12", "0 1 2 3 4 5 6 7 1 9 10 2 5 13 14 6", "8 16", points, 16));
  EXPECT_EQ(read_vtu(dir + "/joined.vtu").hexes.size(), 2u);

  // In a .msh the nodes are named by their tags.
  write_file(dir + "/two.msh",
             "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n16\n1 0 0 0\n2 1 0 0\n3 1 1 0\n4 0 1 0\n"
             "5 0 0 1\n6 1 0 1\n7 1 1 1\n8 0 1 1\n21 1 0 0\n22 2 0 0\n23 2 1 0\n24 1 1 0\n25 1 0 1\n"
             "26 2 0 1\n27 2 1 1\n28 1 1 1\n$EndNodes\n$Elements\n2\n1 5 2 1 1 1 2 3 4 5 6 7 8\n"
             "2 5 2 2 2 21 22 23 24 25 26 27 28\n$EndElements\n");
  msg = test::message_of<InputError>([&] { read_msh(dir + "/two.msh"); });
  EXPECT_NE(msg.find("two.msh': nodes 2 and 21 lie at the same place (1, 0, 0) mm"), std::string::npos)
      << msg;
  const test::CommandResult r = run_hexbite({"quality", dir + "/two.vtu"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("vertices 1 and 8 (0-based) lie at the same place"), std::string::npos) << r.err;
}

// Gmsh 2.2 with Mesh.SaveParametric writes its nodes in $ParametricNodes ("tag x y z dim entity u v"): it
// was skipped, and the file refused with "$Elements before $Nodes".
TEST(HexMeshIo, MshVersion22ParametricNodes) {
  const std::string dir = temp_dir();
  write_file(dir + "/p.msh",
             "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$ParametricNodes\n8\n1 0 0 0 3 1\n2 1 0 0 0 2\n"
             "3 1 1 0 1 3 0.5\n4 0 1 0 2 1 0.25 0.75\n5 0 0 1 3 1\n6 1 0 1 3 1\n7 1 1 1 3 1\n8 0 1 1 3 1\n"
             "$EndParametricNodes\n$Elements\n1\n1 5 2 1 1 1 2 3 4 5 6 7 8\n$EndElements\n");
  const HexMesh m = read_msh(dir + "/p.msh");
  ASSERT_EQ(m.hexes.size(), 1u);
  EXPECT_EQ(m.vertices[3], (Vec3{0, 1, 0}));
  EXPECT_EQ(hex_quality(m.vertices.data()).scaled_jacobian, 1.0);
}

// Messages about a hex of a .msh input give its Gmsh element tag beside hexbite's 0-based index (refine said
// "hex 1 at (1.50, 0.50, 0.50) mm" for the element Gmsh calls 9).
TEST(HexMeshIo, InvertedHexesOfAMshAreNamedByTheirElementTags) {
  const std::string dir = temp_dir();
  // Two hexes side by side; the second (tag 9) lists its faces top first: inverted.
  write_file(dir + "/inv.msh",
             "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n12\n1 0 0 0\n2 1 0 0\n3 1 1 0\n4 0 1 0\n"
             "5 0 0 1\n6 1 0 1\n7 1 1 1\n8 0 1 1\n9 2 0 0\n10 2 1 0\n11 2 0 1\n12 2 1 1\n$EndNodes\n"
             "$Elements\n2\n4 5 2 1 1 1 2 3 4 5 6 7 8\n9 5 2 1 1 6 11 12 7 2 9 10 3\n$EndElements\n");
  test::CommandResult r = run_hexbite({"refine", dir + "/inv.msh", "-o", dir + "/fine.vtu"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("hex 1 (Gmsh element 9) at (1.50, 0.50, 0.50) mm"), std::string::npos) << r.err;
  r = run_hexbite({"quality", dir + "/inv.msh", "--worst", "1"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("inverted hexes (0-based): 1 (Gmsh element 9)\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Gmsh element"), std::string::npos) << r.out;
  r = run_hexbite({"quality", dir + "/inv.msh", "--worst", "1", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["worst"][0]["gmsh_element"], 9);
}

// A mesh file in metres (Mesh.ScalingFactor = 0.001) was read in mm without a word: mesh files have no unit
// option, so the commands that read one warn about a size no bone has.
TEST(HexMeshIo, MeshOfNoBonesSizeIsWarnedAbout) {
  const std::string dir = temp_dir();
  HexMesh mesh = make_block_mesh(2, 2, 2);
  for (Vec3& p : mesh.vertices)
    for (double& c : p) c *= 0.005;
  write_msh(dir + "/m.msh", mesh);
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"quality", dir + "/m.msh", "-q"},
        std::vector<std::string>{"reorder", dir + "/m.msh", "-o", dir + "/r.msh", "-q"},
        std::vector<std::string>{"refine", dir + "/m.msh", "-o", dir + "/f.msh", "-q"}}) {
    const test::CommandResult r = run_hexbite(args);
    EXPECT_EQ(r.exit_code, 0) << args[0] << ": " << r.err;
    EXPECT_NE(r.err.find("hexbite: warning: '" + dir +
                         "/m.msh': the mesh is only 0.01 mm across (the largest side of its bounding box) "
                         "with its coordinates read as mm"),
              std::string::npos)
        << args[0] << ": " << r.err;
    EXPECT_NE(r.err.find("If the file's coordinates are in m (10 mm across), scale the mesh from m to "
                         "millimetres where it was made"),
              std::string::npos)
        << args[0] << ": " << r.err;
  }
  // A mesh in mm: no warning.
  write_msh(dir + "/mm.msh", make_block_mesh(2, 2, 2));
  EXPECT_EQ(run_hexbite({"quality", dir + "/mm.msh", "-q"}).err, "");

  // refine --surface with the surface's --units m: the mesh does not lie on it, and the message sent the
  // user back to --units ("give the surface the mesh was made from, in its units (--units, now m)").
  write_msh(dir + "/cube.msh", make_block_mesh(2, 2, 2, {0, 0, 0}, {0.02, 0.02, 0.02}));
  std::string obj = test::cubes_obj(1);  // a 20 mm cube, written here in metres
  for (std::size_t at = obj.find("20"); at != std::string::npos; at = obj.find("20", at))
    obj.replace(at, 2, "0.02");
  write_file(dir + "/cube.obj", obj);
  const test::CommandResult r = run_hexbite(
      {"refine", dir + "/cube.msh", "--surface", dir + "/cube.obj", "--units", "m", "-o", dir + "/f.vtu"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("does not lie on"), std::string::npos) << r.err;
  EXPECT_NE(
      r.err.find("; the mesh is 0.02 mm across, no bone's size: hex mesh files are read in mm, so scale "
                 "the mesh to millimetres where it was made (--units sets the unit of the surface "
                 "only)"),
      std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("give the surface the mesh was made from"), std::string::npos) << r.err;
}

// Area vector of a planar or nearly planar quad: half the cross product of its diagonals.
Vec3 area_vector(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const Vec3 p{c[0] - a[0], c[1] - a[1], c[2] - a[2]}, q{d[0] - b[0], d[1] - b[1], d[2] - b[2]};
  return {0.5 * (p[1] * q[2] - p[2] * q[1]), 0.5 * (p[2] * q[0] - p[0] * q[2]),
          0.5 * (p[0] * q[1] - p[1] * q[0])};
}

TEST(HexBoundary, BlockThreeByTwoByTwo) {
  const HexMesh mesh = make_block_mesh(3, 2, 2);
  const HexBoundary b = extract_boundary(mesh);
  // 2 (3x2) + 2 (3x2) + 2 (2x2) faces.
  ASSERT_EQ(b.surface.quads.size(), 32u);
  ASSERT_EQ(b.quad_face.size(), 32u);
  // All vertices but the 2 interior ones (1,1,1) and (2,1,1) are on the boundary.
  EXPECT_EQ(b.boundary_vertices.size(), mesh.vertices.size() - 2);

  // Outward orientation by the divergence theorem: the sum over the quads of (area vector)_x times the
  // centroid's x is the volume, 12; the same for y and z.
  double flux[3] = {0, 0, 0};
  for (std::size_t i = 0; i < b.surface.quads.size(); ++i) {
    const auto& q = b.surface.quads[i];
    const Vec3 &p0 = b.surface.vertices[q[0]], &p1 = b.surface.vertices[q[1]], &p2 = b.surface.vertices[q[2]],
               &p3 = b.surface.vertices[q[3]];
    const Vec3 n = area_vector(p0, p1, p2, p3);
    for (int d = 0; d < 3; ++d) flux[d] += n[d] * 0.25 * (p0[d] + p1[d] + p2[d] + p3[d]);
    // The map back to the hex face gives the same vertices.
    const auto [h, f] = b.quad_face[i];
    for (int k = 0; k < 4; ++k) EXPECT_EQ(b.boundary_vertices[q[k]], mesh.hexes[h][kHexFaces[f][k]]);
  }
  for (int d = 0; d < 3; ++d) EXPECT_NEAR(flux[d], 12.0, 1e-12);

  // Every face that is not on the boundary is shared by exactly two hexes.
  std::map<std::array<int, 4>, int> uses;
  for (const auto& hex : mesh.hexes)
    for (const auto& f : kHexFaces) {
      std::array<int, 4> key{hex[f[0]], hex[f[1]], hex[f[2]], hex[f[3]]};
      std::sort(key.begin(), key.end());
      ++uses[key];
    }
  int interior = 0, boundary = 0;
  for (const auto& [key, count] : uses) {
    EXPECT_LE(count, 2);
    (count == 2 ? interior : boundary) += 1;
  }
  EXPECT_EQ(boundary, 32);
  EXPECT_EQ(interior, 20);  // (12 x 6 - 32) / 2

  const std::vector<char> mask = boundary_vertex_mask(mesh);
  int on = 0;
  for (char c : mask) on += c;
  EXPECT_EQ(on, static_cast<int>(b.boundary_vertices.size()));
}

TEST(HexBoundary, NonManifoldFaceIsAnError) {
  HexMesh mesh = make_block_mesh(1, 1, 1);
  mesh.hexes.push_back(mesh.hexes[0]);
  mesh.hexes.push_back(mesh.hexes[0]);
  const std::string msg = test::message_of<InputError>([&] { extract_boundary(mesh); });
  EXPECT_NE(msg.find("shared by 3 hexes (0, 1, 2)"), std::string::npos) << msg;
}

TEST(QualityCommand, JsonMatchesLibrary) {
  HexMesh mesh = perturbed_block(4, 3, 3);
  mesh.vertices[mesh.hexes[0][6]] = {0.5, 0.5, 0.5};  // one inverted hex at least
  const std::string path = temp_dir() + "/q.vtu";
  write_vtu(path, mesh);
  const test::CommandResult r = run_hexbite({"quality", path, "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  const QualitySummary s = summarize_quality(read_vtu(path));
  EXPECT_EQ(j, quality_to_json(s, hex_mesh_volume(read_vtu(path))));
  EXPECT_TRUE(j["volume_mm3"].is_number());
  EXPECT_EQ(j["hexes"], 36);
  EXPECT_EQ(j["nodes"], 80);
  EXPECT_GE(j["inverted"].get<int>(), 1);
  for (const char* key : {"scaled_jacobian", "condition", "condition_verdict", "oddy"})
    for (const char* stat : {"min", "mean", "max"})
      EXPECT_TRUE(j[key][stat].is_number()) << key << ' ' << stat;
  EXPECT_DOUBLE_EQ(j["scaled_jacobian"]["min"].get<double>(), s.scaled_jacobian.min);
  EXPECT_DOUBLE_EQ(j["condition"]["max"].get<double>(), s.condition.max);
  EXPECT_DOUBLE_EQ(j["condition_verdict"]["mean"].get<double>(), s.condition.mean / 3.0);
  EXPECT_EQ(j["node_degree"]["edges"]["max"], s.node_degree.max_edges);

  const test::CommandResult table = run_hexbite({"quality", path});
  ASSERT_EQ(table.exit_code, 0) << table.err;
  for (const char* row :
       {"scaled Jacobian", "condition number (cube = 3)", "condition number (Verdict, cube = 1)", "Oddy",
        "inverted elements:", "node degree"})
    EXPECT_NE(table.out.find(row), std::string::npos) << row << "\n" << table.out;
}

// --worst N lists the N hexes of lowest scaled Jacobian with their condition numbers and centroids, as a
// table after the report and as "worst" in --json; without it the output is what it was.
TEST(QualityCommand, WorstHexesInTextAndJson) {
  HexMesh mesh = make_block_mesh(3, 3, 3);
  mesh.vertices[mesh.hexes[0][6]] = {0.5, 0.5, 0.5};  // hex 0 inverted, the neighbours of the vertex bent
  const std::string path = temp_dir() + "/w.vtu";
  write_vtu(path, mesh);

  test::CommandResult r = run_hexbite({"quality", path, "--json", "--worst", "3"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_TRUE(j.contains("worst")) << r.out;
  ASSERT_EQ(j["worst"].size(), 3u);
  EXPECT_EQ(j["worst"][0]["hex"], 0);
  EXPECT_NEAR(j["worst"][0]["scaled_jacobian"].get<double>(), -0.7698, 1e-4);
  EXPECT_TRUE(j["worst"][0]["condition"].is_null());  // +inf: inverted
  EXPECT_EQ(j["worst"][0]["centroid"].size(), 3u);
  const Vec3 c = hex_centroid(mesh, 0);
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(j["worst"][0]["centroid"][a].get<double>(), c[a], 1e-12);
  EXPECT_TRUE(j["worst"][1]["condition"].is_number());
  EXPECT_LE(j["worst"][1]["scaled_jacobian"].get<double>(), j["worst"][2]["scaled_jacobian"].get<double>());
  // The other keys are those without --worst.
  nlohmann::json plain = nlohmann::json::parse(run_hexbite({"quality", path, "--json"}).out);
  EXPECT_FALSE(plain.contains("worst"));
  j.erase("worst");
  EXPECT_EQ(j, plain);

  r = run_hexbite({"quality", path, "--worst", "2"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("worst 2 hexes (lowest scaled Jacobian first; ties: larger condition number first):\n"
                       "       hex   scaled Jacobian         condition   centroid (mm)\n"
                       "         0           -0.7698               inf   (0.44, 0.44, 0.44)\n"),
            std::string::npos)
      << r.out;
  EXPECT_EQ(r.out.rfind(run_hexbite({"quality", path}).out, 0), 0u) << "the report before the list changed";

  // A count is a whole number from 0.
  r = run_hexbite({"quality", path, "--worst", "-1"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("give a whole number from 0"), std::string::npos) << r.err;
}

TEST(QualityCommand, JsonVolumeOfVtuAndMsh) {
  // A 2 x 3 x 4 block of unit cubes, sheared (x += 0.5 z): the volume stays 24, the hexes are not boxes.
  HexMesh mesh = make_block_mesh(2, 3, 4);
  for (Vec3& p : mesh.vertices) p[0] += 0.5 * p[2];
  const std::string dir = temp_dir();
  write_vtu(dir + "/b.vtu", mesh);
  write_msh(dir + "/b.msh", mesh);
  for (const char* name : {"/b.vtu", "/b.msh"}) {
    const test::CommandResult r = run_hexbite({"quality", dir + name, "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NEAR(nlohmann::json::parse(r.out)["volume_mm3"].get<double>(), 24.0, 1e-9) << name;
  }
}

TEST(QualityCommand, BadInputExitsTwo) {
  const std::string dir = temp_dir();
  write_file(dir + "/tetra.vtu", ascii_vtu(1, "10", "0 1 3 4", "4", kCubePoints, 8));
  write_file(dir + "/garbage.vtu",
             "\x7f"
             "ELF garbage");
  // An Abaqus deck (which hexbite writes but does not read): the message says which formats are read.
  write_file(dir + "/deck.inp", "*NODE, NSET=NALL\n1, 0, 0, 0\n");
  const std::pair<std::string, std::string> cases[] = {
      {dir + "/missing.vtu", "does not exist"},
      {dir + "/tetra.vtu", "cell 0 is a vtkTetra"},
      {dir + "/garbage.vtu", "not a VTK XML unstructured grid"},
      {dir + "/deck.inp", "hex meshes are read from .vtu or Gmsh .msh (4.1 or 2.2 ASCII) files only"}};
  for (const auto& [path, expected] : cases) {
    const test::CommandResult r = run_hexbite({"quality", path});
    EXPECT_EQ(r.exit_code, 2) << path;
    EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(path), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
}

}  // namespace
}  // namespace hexbite

namespace hexbite {
namespace {

// CalculiX reads 20 characters of a data field; a longer number would lose its exponent.
TEST(InpNumber, FitsTwentyCharactersAndReadsBackClosely) {
  for (double v : {-5.1474133753646426e-05, 0.28, -0.024689548693392765, 11000.0, -1.2345678901234567e-100}) {
    const std::string text = format_inp_number(v);
    EXPECT_LE(text.size(), 20u) << text;
    EXPECT_NEAR(std::strtod(text.c_str(), nullptr), v, 5e-13 * std::abs(v)) << text;  // 13 digits at least
  }
  EXPECT_EQ(format_inp_number(0.28), "0.28");
}

}  // namespace
}  // namespace hexbite
