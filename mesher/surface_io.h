// Reading and writing triangle surfaces: STL (ASCII and binary), OBJ, PLY, OFF and VTP.
#pragma once

#include <string>

#include "mesher/tri_surface.h"

namespace hexbite {

// Reads a surface, choosing the format from the extension (.stl .obj .ply .off .vtp, any case),
// and scales coordinates by scale_to_mm. The result is the file's polygon soup as stored
// (STL: three vertices per triangle; polygons with more corners are fanned into triangles);
// duplicates are merged later by repair_surface().
// Throws InputError naming the file (and line or record) for: a missing or empty file, an unknown
// extension, a truncated or malformed file, a NaN or infinite coordinate, an out-of-range index.
TriSurface read_surface(const std::string& path, double scale_to_mm = 1.0);

// Writes a surface in the format given by the extension, atomically (temporary file, then rename).
// STL is written binary. Output is deterministic: same surface, same bytes.
void write_surface(const std::string& path, const TriSurface& surface);

}  // namespace hexbite
