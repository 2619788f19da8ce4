#pragma once

#include <string>

namespace hexbite {

// How a message names the choices a user can change: the command line's options (hexbite mesh, hexbite
// quad from-mandible) or a scenario's keys (hexbite run), so that the advice can be followed as written.
struct InputTerms {
  std::string grid_method = "--method grid";
  std::string sheets_method = "--method sheets";
  std::string target_hexes = "--target-hexes";
  std::string landmarks = "--landmarks";
  std::string units = "give --units <unit>";  // how to read the surface in another unit ("<unit>" replaced)
  std::string surface_unit = "mm";            // the unit the surface was read in
};

// The terms of `hexbite mesh`, reading its surface in `surface_unit`.
inline InputTerms mesh_command_terms(const std::string& surface_unit) {
  InputTerms terms;
  terms.surface_unit = surface_unit;
  return terms;
}

// The terms of `hexbite quad from-mandible`, which has no --method: the meshers are another command.
inline InputTerms quad_command_terms(const std::string& surface_unit) {
  InputTerms terms = mesh_command_terms(surface_unit);
  terms.grid_method = "hexbite mesh --method grid";
  terms.sheets_method = "hexbite mesh --method sheets";
  return terms;
}

// The terms of a scenario file (docs/scenario-format.md) whose surface is read in `surface_unit`.
inline InputTerms scenario_terms(const std::string& surface_unit) {
  return {"method: grid",
          "method: sheets",
          "mesh.target_hexes",
          "landmarks: {file: ...}",
          "write units: <unit> in geometry.surface",
          surface_unit};
}

}  // namespace hexbite
