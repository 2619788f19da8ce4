// The macro-element quad mesh for mandibles (seed paper section 2), designed once.
//
// Input: none; the template lives in the built-in mandible's frame (+x subject's left, +y posterior,
// +z superior, mm) and is fitted to the default dentate mandible of mesher/mandible_generator.h.
// Output: a coarse quad surface of a ball (the "macro quads"), its named key nodes, and the reference points
// of the default mandible (its landmarks and muscle insertions, and the extreme points used when a surface
// comes without a landmark file) that place the template on another mandible.
// Algorithm: the template is a polycube built as a coarse hex macro mesh in index space (a, b, c): a runs
// along the unrolled dental arch from the right condyle (a = -6) through the symphysis (a = 0) to the left
// condyle (a = 6), b upward (lower border, alveolar crest/teeth, sigmoid notch level, process tips), c
// through the bone (0 lingual, 1 buccal). The body is one row of cells along the arch; on each side the
// three posterior columns rise into the ramus, whose top forks into the coronoid process (anterior column)
// and the condylar process (posterior column), leaving the sigmoid notch between them. Its boundary is
// therefore a closed, consistently oriented polycube surface whose chords each stay in one slab of the
// index space, so every chord is simple; taking the boundary of a hex mesh (rather than listing quads by
// hand) gets orientation and closure right by construction. Each lattice node (a, b, c) is then placed on
// the default mandible: a mid-surface point of the body section (along the generator's arch curve) or of
// the ramus plate, plus or minus half the local bone thickness.
// Cost: constant (22 macro hexes). Deterministic.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "mesher/hex_mesh.h"

namespace hexbite {

struct MandibleQuadTemplate {
  QuadSurface macro;  // macro quads, counter-clockwise from outside, default-mandible frame
  std::map<std::string, int> key_nodes;   // named macro nodes, e.g. "left_gonion_corner"
  std::map<std::string, Vec3> reference;  // default mandible: landmarks and "<muscle>.insertion" points
  std::map<std::string, Vec3> extremes;   // default mandible: extreme_points() of its surface
  // Default mandible, per side ("left_", "right_"): condyle_top, coronoid_top, sigmoid_notch (the points
  // that quad_surface_placement.cc derives from a surface's shape).
  std::map<std::string, Vec3> derived;
};

// The template (built on each call; cheap).
MandibleQuadTemplate mandible_quad_template();

// Extreme points of a point set in the mandible frame, by name: "max_x" (left lateral condyle pole),
// "min_x", "min_y" (the chin: only among the points in the lowest quarter of the height),
// "left_max_y"/"right_max_y" (back of the condyles), "left_max_z"/"right_max_z" (condyle or coronoid tops),
// "min_z" (lower border). Ties: the first point in input order.
std::map<std::string, Vec3> extreme_points(const std::vector<Vec3>& points);

}  // namespace hexbite
