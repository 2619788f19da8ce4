// Structured hex blocks: the simplest valid meshes, for tests, benchmarks and verification problems.
#pragma once

#include "mesher/hex_mesh.h"

namespace hexbite {

// An nx x ny x nz block of equal hexes spanning the box [lower, upper], vertices numbered x fastest
// (vertex (i, j, k) has id i + (nx + 1) (j + (ny + 1) k)), hexes likewise, positively oriented.
// Cost: O(nx ny nz).
HexMesh make_block_mesh(int nx, int ny, int nz, const Vec3& lower, const Vec3& upper);

// The same with unit cubes: the box [0, nx] x [0, ny] x [0, nz].
HexMesh make_block_mesh(int nx, int ny, int nz);

}  // namespace hexbite
