// The inputs of the commands that read a triangulated bone (`mesh SURFACE --method grid|sheets`, `quad
// from-mandible`, `surface clean`, `refine --surface`): the SURFACE, closed and in millimetres, and for the
// meshing commands the optional --landmarks file in the same unit. Each gets a warning on standard error when
// it does not fit: a size no mandible has (a file in metres read as millimetres), a landmark file written
// for another bone, frame or unit (landmark_fit_warning()) or with its sides swapped
// (landmark_side_warning()). Errors (unreadable, open or non-manifold
// surfaces, malformed landmark files) are InputErrors from the loaders.
#pragma once

#include <memory>
#include <string>

#include "mesher/hex_mesh.h"
#include "mesher/landmarks.h"
#include "mesher/tri_surface.h"

namespace hexbite {

struct MeshInputs {
  TriSurface surface;
  std::unique_ptr<Landmarks> landmarks;  // nullptr without --landmarks
};

// The closed SURFACE in millimetres (`units`: its unit, mm, cm or m), with the size warning.
TriSurface load_surface_input(const std::string& surface_file, const std::string& units);

// `units`: the unit of both files (mm, cm or m); `landmark_file` empty: no landmarks.
MeshInputs load_mesh_inputs(const std::string& surface_file, const std::string& units,
                            const std::string& landmark_file);

// For the commands that read a hex mesh and cannot work on an inverted one (`refine`, `quad from-mesh`):
// throws an InputError naming the inverted hexes of `mesh` (read from `path`; a corner Jacobian <= 0 or NaN)
// with their centroids, `why` they are refused, and what to do.
void require_no_inverted_hexes(const HexMesh& mesh, const std::string& path, const std::string& why);

}  // namespace hexbite
