// Closed triangle surfaces with known topology and geometry, shared by the test suites.
#pragma once

#include "mesher/tri_surface.h"

namespace hexbite::test {

// A torus (major radius 10, minor radius 3) as an n x m grid wrapped in both directions, outward, genus 1.
// With n much larger than m its triangles are needles.
TriSurface torus(int n, int m);

// The closed box [0, a] x [0, b] x [0, c], outward, each face split into 2 x 2 quads of two triangles.
TriSurface box(double a, double b, double c);

// An L-shaped block: the outline (0, 0), (arm, 0), (arm, width), (width, width), (width, arm), (0, arm)
// extruded from z = 0 to height, outward, 20 triangles. Its principal axes lie along its diagonal.
TriSurface l_block(double arm, double width, double height);

// `s` turned by `degrees` about the axis through the origin along `axis` (not necessarily unit).
TriSurface rotated(TriSurface s, const Vec3& axis, double degrees);

}  // namespace hexbite::test
