// Closed triangle surfaces with known topology and geometry, shared by the test suites.
#pragma once

#include "mesher/tri_surface.h"

namespace hexbite::test {

// A torus (major radius 10, minor radius 3) as an n x m grid wrapped in both directions, outward, genus 1.
// With n much larger than m its triangles are needles.
TriSurface torus(int n, int m);

}  // namespace hexbite::test
