// The principal axes of a closed surface: a rotation about its centroid that lays its axes of inertia
// along x, y and z.
//
// Why: the overlay grid lies along the coordinate axes, and a solid with flat faces at an angle to them
// (a box rotated by 30 degrees) gets a staircase core whose pillow hexes can stay inverted (a 100 x 20 x
// 20 mm box: 2 inverted at 1,500 hexes, where the unrotated box meshes cleanly). A grid along the principal
// axes sees such a solid as if it were not rotated (mesher/grid_mesher.h tries it then).
// Input: a closed triangle surface in mm. Output: the frame, or nullopt for a solid without distinct axes.
// Cost: one pass over the triangles and a 3 x 3 eigenproblem.
#pragma once

#include <array>
#include <optional>

#include "mesher/tri_surface.h"

namespace hexbite {

struct PrincipalFrame {
  Vec3 centre{};               // the surface's area-weighted centroid
  std::array<Vec3, 3> axes{};  // orthonormal, right-handed: the frame's x, y and z in body coordinates
  Vec3 to_frame(const Vec3& body) const;
  Vec3 to_body(const Vec3& frame) const;
  // Whether every axis lies within `degrees` of a coordinate axis (the frame is then the axes' grid).
  bool along_coordinate_axes(double degrees = 2.0) const;
};

// The axes of the surface's second moments (area-weighted). Two moments within 5 % of each other leave
// their plane's axes free: they are then chosen along the coordinate axis that lies nearest that plane (a
// box of square section rotated about z keeps z). nullopt when all three moments are that close (a sphere,
// a cube: no axis to prefer) or the surface has no area.
std::optional<PrincipalFrame> principal_frame(const TriSurface& surface);

// The frame of the solid's largest flat faces: its z along the normal shared by the largest area of
// triangles (within 3 degrees, either sign), its x along the normal of the largest area among the
// triangles at right angles to that (within 3 degrees), y completing it; centred like principal_frame.
// For solids whose principal axes do not follow their faces: an L-shaped block's lie along its diagonal
// (its two arms have equal moments), so a grid along them cuts every side face at 45 degrees. nullopt when
// either direction gathers less than a tenth of the surface's area (no flat faces: a mandible, a sphere).
// Cost: two passes over the triangles (the normals binned in cells of about 3 degrees).
std::optional<PrincipalFrame> face_frame(const TriSurface& surface);

// Whether every axis of `a` lies within `degrees` of an axis of `b` (the two grids are the same).
bool same_axes(const PrincipalFrame& a, const PrincipalFrame& b, double degrees = 2.0);

}  // namespace hexbite
