#include "app/mesh_inputs.h"

#include <iostream>
#include <string>
#include <vector>

#include "common/error.h"
#include "mesher/hex_quality.h"
#include "mesher/quad_surface_io.h"
#include "mesher/surface_check.h"
#include "mesher/units.h"

namespace hexbite {

TriSurface load_surface_input(const std::string& surface_file, const std::string& units) {
  TriSurface surface = load_closed_surface(surface_file, unit_to_mm(units));
  // The result would come out fine, but in the wrong unit every later number (and the solver's) is off by
  // 1000.
  const std::string size_warning =
      implausible_size_warning(largest_extent(surface), units, "give --units <unit>");
  if (!size_warning.empty())
    std::cerr << "hexbite: warning: '" << surface_file << "': " << size_warning << '\n';
  return surface;
}

MeshInputs load_mesh_inputs(const std::string& surface_file, const std::string& units,
                            const std::string& landmark_file) {
  MeshInputs in;
  in.surface = load_surface_input(surface_file, units);
  if (landmark_file.empty()) return in;
  in.landmarks = std::make_unique<Landmarks>(read_landmarks(landmark_file, unit_to_mm(units)));
  // --units reads both files; a landmark file in another unit than the surface must be converted.
  const std::string how =
      "convert the landmark file to the surface's unit, " + units + " (--units reads both files in it)";
  for (const std::string& warning :
       {landmark_fit_warning(*in.landmarks, in.surface, landmark_file, units, how),
        landmark_side_warning(*in.landmarks, landmark_file)})
    if (!warning.empty()) std::cerr << "hexbite: warning: " << warning << ".\n";
  return in;
}

std::string HexMeshInput::element_suffix(int h) const {
  return gmsh.elements.empty() ? std::string() : ", Gmsh element " + std::to_string(gmsh.elements[h]);
}

std::string HexMeshInput::node_suffix(int v) const {
  return gmsh.nodes.empty() ? std::string() : ", Gmsh node " + std::to_string(gmsh.nodes[v]);
}

std::function<std::string(int)> HexMeshInput::hex_label() const {
  if (gmsh.elements.empty()) return {};
  return [this](int h) { return " (" + element_suffix(h).substr(2) + ")"; };
}

std::string mesh_size_warning(double largest_extent_mm, const std::string& what, const std::string& files) {
  return implausible_size_warning(largest_extent_mm, "mm",
                                  "scale the " + what + " from <unit> to millimetres where it was made: " +
                                      files + " are read in mm, and no option sets their unit",
                                  what);
}

QuadSurface load_quad_surface_input(const std::string& path) {
  QuadSurface surface = read_quad_surface(path);
  const std::string warning =
      mesh_size_warning(largest_extent(surface.vertices), "quad surface", "quad surface files");
  if (!warning.empty()) std::cerr << "hexbite: warning: '" << path << "': " << warning << '\n';
  return surface;
}

void HexMeshInput::warn_physical_groups_not_carried(const std::string& path, const std::string& output,
                                                    const std::string& command) const {
  if (gmsh.physical_groups.empty()) return;
  std::string list;
  for (const std::string& group : gmsh.physical_groups) list += (list.empty() ? "" : ", ") + group;
  std::cerr << "hexbite: warning: not carried over to " << output << ": " << list << " of " << path << " ("
            << command << " writes no physical groups; define them again on its mesh).\n";
}

HexMeshInput load_hex_mesh_input(const std::string& path, std::vector<MeshArray>* cell_arrays,
                                 std::vector<MeshArray>* point_arrays, std::vector<std::string>* not_read) {
  HexMeshInput in;
  in.mesh = read_hex_mesh(path, cell_arrays, point_arrays, not_read, &in.gmsh);
  const std::string warning = mesh_size_warning(largest_extent(in.mesh.vertices));
  if (!warning.empty()) std::cerr << "hexbite: warning: '" << path << "': " << warning << '\n';
  return in;
}

void require_no_inverted_hexes(const HexMeshInput& input, const std::string& path, const std::string& why) {
  const HexMesh& mesh = input.mesh;
  const HexQualityField field = compute_hex_quality(mesh);
  std::vector<int> inverted;
  for (std::size_t h = 0; h < mesh.hexes.size(); ++h)
    if (!(field.jacobian[h] > 0.0)) inverted.push_back(static_cast<int>(h));  // NaN counts as inverted
  if (inverted.empty()) return;
  const std::string count = std::to_string(inverted.size());
  throw InputError("'" + path + "' has " + count + " inverted " + (inverted.size() == 1 ? "hex" : "hexes") +
                   " (a corner Jacobian <= 0), " + why + ": " +
                   hex_list_text(mesh, inverted, 5, input.hex_label()) +
                   "; nothing written: re-mesh the surface (hexbite mesh), or find the worst hexes with "
                   "hexbite quality " +
                   path + " --worst " + count);
}

}  // namespace hexbite
