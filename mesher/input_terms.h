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
  std::string units = "--units m or cm";
};

// The terms of a scenario file (docs/scenario-format.md).
inline InputTerms scenario_terms() {
  return {"method: grid", "method: sheets", "mesh.target_hexes", "landmarks: {file: ...}",
          "units: m or cm in geometry.surface"};
}

}  // namespace hexbite
