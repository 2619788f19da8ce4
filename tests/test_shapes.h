// Closed triangle surfaces with known topology and geometry, shared by the test suites.
#pragma once

#include "mesher/tri_surface.h"

namespace hexbite::test {

// A torus (major radius 10, minor radius 3) as an n x m grid wrapped in both directions, outward, genus 1.
// With n much larger than m its triangles are needles.
TriSurface torus(int n, int m);

// The closed box [0, a] x [0, b] x [0, c], outward, each face split into 2 x 2 quads of two triangles.
TriSurface box(double a, double b, double c);

}  // namespace hexbite::test
