#include "app/contact_supports.h"

#include <cmath>
#include <cstdio>
#include <set>

#include "common/error.h"
#include "mesher/vec3.h"

namespace hexbite {

using vec3::dot;

Vec3 contact_direction(const Support& support, const MeshPatch& patch, const HexMesh& mesh) {
  // Twice a bilinear quad's vector area is the cross product of its diagonals; the boundary quads are
  // oriented outward (mesher/hex_boundary.h).
  Vec3 n{0, 0, 0};
  double area = 0;  // summed magnitudes of the quads' vector areas (twice)
  for (const BoundaryQuad& q : patch.faces) {
    const Vec3 face = vec3::cross(vec3::sub(mesh.vertices[q[2]], mesh.vertices[q[0]]),
                                  vec3::sub(mesh.vertices[q[3]], mesh.vertices[q[1]]));
    n = vec3::add(n, face);
    area += vec3::norm(face);
  }
  const double length = vec3::norm(n);
  // A patch over both sides of a thin part (a plate thinner than the patch) faces both ways: its facets'
  // normals cancel, and what is left of them is no direction (it was taken as one, and a contact pushing
  // on the plate's lower side was released as pulling).
  if (!(length >= 0.3 * area))
    throw InputError(support.where.str() + ": contact support '" + support.name +
                     "' faces no one way: its patch covers opposite sides of the bone (its facets' normals "
                     "cancel: a part thinner than the patch), so what would push and what would pull is "
                     "undefined: make radius_mm smaller, or move it onto one face");
  Vec3 held{0, 0, 0};
  for (int d = 0; d < 3; ++d)
    if (support.fixed[d] && length > 0) held[d] = n[d] / length;
  if (!(vec3::norm(held) >= 0.1)) {
    char faces[96];
    std::snprintf(faces, sizeof faces, "(%.2f, %.2f, %.2f)", length > 0 ? n[0] / length : 0.0,
                  length > 0 ? n[1] / length : 0.0, length > 0 ? n[2] / length : 0.0);
    throw InputError(support.where.str() + ": contact support '" + support.name +
                     "' fixes only components along its own surface (its patch faces " + faces +
                     "), so it cannot push the bone: fix the component it faces, or remove 'contact'");
  }
  return held;
}

bool update_released_contacts(const std::vector<Support>& supports, const std::vector<MeshPatch>& patches,
                              const std::vector<Vec3>& directions, const ElasticitySolution& solution,
                              std::vector<bool>& released) {
  // Reactions below this share of the loads are the solver's round-off, neither push nor pull.
  const double noise = 1e-9 * vec3::norm(solution.applied_force);
  bool changed = false;
  for (std::size_t i = 0; i < supports.size(); ++i) {
    if (!supports[i].contact) continue;
    if (!released[i]) {
      if (dot(solution.reactions[i].force, directions[i]) > noise) released[i] = changed = true;
      continue;
    }
    std::set<int> nodes;
    for (const BoundaryQuad& q : patches[i].faces) nodes.insert(q.begin(), q.end());
    double along = 0;
    for (int v : nodes) along += dot(solution.vertex_displacement[v], directions[i]);
    if (!nodes.empty() && along / static_cast<double>(nodes.size()) > 0) {
      released[i] = false;
      changed = true;
    }
  }
  return changed;
}

}  // namespace hexbite
