// One-sided contact supports (a scenario's `contact: true`): an antagonist tooth or a nut pushes the bone
// but cannot pull it. A fixed support is two-sided, so a contact that the loads lift off would hold the
// bone down and add a pull to the bite force (the shipped molar clench's premolar: +26 N along the muscles,
// 2.3 % of its bite force). The run solves with every contact held, releases those that pull, and solves
// again, until the set settles (app/run_pipeline.cc).
//
// Method: patch by patch, not node by node (a contact patch is a few millimetres across: it is held or
// free as a whole). The direction a contact resists is its patch's outward normal (area-weighted over its
// boundary quads) restricted to the components it fixes. A held contact pulls when its reaction has a
// positive part along that direction; a released one touches again when its patch's mean displacement
// along it is positive (it would move into what it touches).
// Cost: linear in the patches' faces and nodes; each change of the set costs the caller one more solve.
#pragma once

#include <vector>

#include "app/run_pipeline.h"
#include "scenarios/scenario.h"
#include "solver/elasticity.h"

namespace hexbite {

// The direction support `support` resists as a contact on `patch`: the patch's outward unit normal with
// the components it does not fix set to zero. Throws InputError (naming the support's line) when that
// leaves less than a tenth of the normal (a contact fixed only along its own surface cannot push), and when
// the patch faces no one way (its facets' summed vector area is under 0.3 of their summed areas: it covers
// opposite sides of a thin part).
Vec3 contact_direction(const Support& support, const MeshPatch& patch, const HexMesh& mesh);

// After a solve in which the supports flagged in `released` were left out (their reactions zero): flags
// the held contacts that pull the bone and clears the released ones that touch again. `directions` holds
// contact_direction() per support (ignored for the others). Returns whether any flag changed.
bool update_released_contacts(const std::vector<Support>& supports, const std::vector<MeshPatch>& patches,
                              const std::vector<Vec3>& directions, const ElasticitySolution& solution,
                              std::vector<bool>& released);

}  // namespace hexbite
