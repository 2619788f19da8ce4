#include "postprocess/quality_json.h"

#include <algorithm>
#include <cmath>

namespace hexbite {

namespace {

// JSON has no NaN or infinity; an undefined statistic (no elements to cover) is written as null.
nlohmann::json number(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

nlohmann::json stats_json(const MeasureStats& s) {
  return {{"count", s.count}, {"min", number(s.min)}, {"mean", number(s.mean)}, {"max", number(s.max)}};
}

nlohmann::json histogram_json(const Histogram& h) {
  return {{"lo", h.lo}, {"hi", h.hi}, {"counts", h.counts}, {"below", h.below}, {"above", h.above}};
}

}  // namespace

nlohmann::json quality_to_json(const QualitySummary& s) {
  // A badly tangled mesh may have thousands of inverted hexes; the first ones are enough to find the region.
  constexpr std::size_t kMaxListed = 100;
  const std::size_t listed = std::min(s.inverted_hexes.size(), kMaxListed);
  nlohmann::json j;
  j["hexes"] = s.hexes;
  j["nodes"] = s.nodes;
  j["inverted"] = s.inverted;
  j["inverted_hexes"] = std::vector<int>(s.inverted_hexes.begin(), s.inverted_hexes.begin() + listed);
  j["scaled_jacobian"] = stats_json(s.scaled_jacobian);
  j["jacobian"] = stats_json(s.jacobian);
  j["condition"] = stats_json(s.condition);
  j["condition_verdict"] = stats_json(s.condition_verdict);
  j["oddy"] = stats_json(s.oddy);
  j["node_degree"] = {
      {"interior_nodes", s.node_degree.interior_nodes},
      {"edges", {{"max", s.node_degree.max_edges}, {"counts", s.node_degree.edges}}},
      {"hexes", {{"max", s.node_degree.max_hexes}, {"counts", s.node_degree.hexes}}},
  };
  j["histograms"] = {
      {"scaled_jacobian", histogram_json(s.scaled_jacobian_histogram)},
      {"condition", histogram_json(s.condition_histogram)},
      {"oddy", histogram_json(s.oddy_histogram)},
  };
  return j;
}

nlohmann::json quality_to_json(const QualitySummary& summary, double volume_mm3) {
  nlohmann::json j = quality_to_json(summary);
  j["volume_mm3"] = number(volume_mm3);
  return j;
}

nlohmann::json fidelity_to_json(const MeshFidelity& f) {
  nlohmann::json unresolved = nlohmann::json::array();
  for (const UnresolvedPart& u : f.unresolved) {
    nlohmann::json near = nlohmann::json::array();
    for (const NearbyPoint& n : u.near) near.push_back({{"name", n.name}, {"distance_mm", n.distance}});
    unresolved.push_back({{"location", u.location},
                          {"extent_mm", u.extent},
                          {"samples", u.samples},
                          {"thickness_mm", u.thickness},
                          {"near", near},
                          {"what", u.what}});
  }
  return {{"hausdorff_mm", f.hausdorff},
          {"hausdorff_mesh_to_surface_mm", f.hausdorff_mesh_to_surface},
          {"hausdorff_surface_to_mesh_mm", f.hausdorff_surface_to_mesh},
          {"mean_edge_length_mm", f.mean_edge_length},
          {"mesh_volume_mm3", f.mesh_volume},
          {"surface_volume_mm3", f.surface_volume},
          {"volume_difference", f.volume_difference},
          {"unresolved", unresolved}};
}

nlohmann::json volume_fit_to_json(const BoundaryFitReport& fit) {
  return {{"boundary_nodes", fit.boundary_nodes},
          {"moved_nodes", fit.moved_nodes},
          {"limited_moves", fit.limited_moves},
          {"mean_gap_before_mm", fit.mean_gap_before},
          {"mean_gap_after_mm", fit.mean_gap_after},
          {"max_node_offset_mm", fit.max_node_offset},
          {"seconds", fit.seconds}};
}

}  // namespace hexbite
