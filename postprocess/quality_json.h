// JSON form of a hex mesh quality summary: the object `hexbite quality --json` prints and results.json
// embeds.
//
// Keys: hexes, nodes, inverted, inverted_hexes (at most the first 100 indices), scaled_jacobian, jacobian,
// condition (cube = 3), condition_verdict (cube = 1), oddy, each {count, min, mean, max} (null where count is
// 0), node_degree {interior_nodes, edges {max, counts}, hexes {max, counts}} where counts[d] is the number of
// interior nodes of degree d, and histograms {scaled_jacobian, condition, oddy}, each {lo, hi, counts,
// below, above}. Cost: linear in the size of the summary.
#pragma once

#include <nlohmann/json.hpp>

#include "mesher/boundary_fit.h"
#include "mesher/grid_mesher.h"
#include "mesher/hex_quality.h"

namespace hexbite {

nlohmann::json quality_to_json(const QualitySummary& summary);

// The same object plus `volume_mm3`, the mesh volume (hex_mesh_volume: exact for trilinear hexes, inverted
// parts counted negative), as `hexbite quality --json` prints it. results.json keeps the object above.
nlohmann::json quality_to_json(const QualitySummary& summary, double volume_mm3);

// A mesh's geometric fidelity, as `hexbite mesh --json` prints it and results.json embeds it: hausdorff_mm,
// hausdorff_mesh_to_surface_mm, hausdorff_surface_to_mesh_mm, mean_edge_length_mm, mesh_volume_mm3,
// surface_volume_mm3, volume_difference, and unresolved: [{location, extent_mm, samples, near [{name,
// distance_mm}], what}].
nlohmann::json fidelity_to_json(const MeshFidelity& fidelity);

// A volume fit (mesher/boundary_fit.h), as `hexbite mesh --json` and `hexbite refine --json` print it under
// `volume_fit`: boundary_nodes, moved_nodes, limited_moves, mean_gap_before_mm, mean_gap_after_mm,
// max_node_offset_mm, seconds.
nlohmann::json volume_fit_to_json(const BoundaryFitReport& fit);

}  // namespace hexbite
