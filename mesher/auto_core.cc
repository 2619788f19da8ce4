#include "mesher/auto_core.h"

#include <algorithm>
#include <utility>

#include "common/number_format.h"
#include "mesher/arch_frame.h"

namespace hexbite {

namespace {

// What keeps a swept mesh from the bounds, or empty.
std::string shortfall(const QualitySummary& q, const AutoCoreOptions& bounds) {
  if (q.inverted > 0) return std::to_string(q.inverted) + " inverted hexes";
  if (q.scaled_jacobian.min < bounds.min_scaled_jacobian)
    return "a scaled Jacobian of " + format_table_number(q.scaled_jacobian.min, 3, 0) + " (below " +
           format_significant(bounds.min_scaled_jacobian) + ")";
  if (q.condition.max > bounds.max_condition)
    return "a condition number of " + format_table_number(q.condition.max, 2, 0) + " (above " +
           format_significant(bounds.max_condition) + ")";
  return "";
}

}  // namespace

HexMesh grid_mesh_auto_core(const TriSurface& surface, GridMeshOptions options, GridMeshReport* report,
                            AutoCoreChoice* choice, const AutoCoreOptions& bounds) {
  const bool grid_arch_frame = options.arch_frame;
  auto grid_core = [&](std::string reason) {
    options.swept_core = false;
    options.arch_frame = grid_arch_frame;
    *choice = {false, std::move(reason)};
    return grid_mesh(surface, options, report);
  };
  if (options.target_hexes > bounds.swept_up_to_hexes)
    return grid_core(std::to_string(options.target_hexes) + " target hexes: the swept core is for up to " +
                     std::to_string(bounds.swept_up_to_hexes));

  GridMeshOptions swept_options = options;
  swept_options.swept_core = true;
  swept_options.arch_frame = true;
  GridMeshReport swept_report;
  HexMesh swept;
  try {
    swept = grid_mesh(surface, swept_options, &swept_report);
  } catch (const NotAnArchError&) {
    return grid_core("the surface follows no dental arch");
  }
  const QualitySummary& s = swept_report.optimize.phases.back().quality;
  const std::string missed = shortfall(s, bounds);
  if (missed.empty()) {
    *report = std::move(swept_report);
    *choice = {true, ""};
    return swept;
  }
  HexMesh grid = grid_core("");
  report->seconds_total += swept_report.seconds_total;  // the time of both meshes
  const QualitySummary& g = report->optimize.phases.back().quality;
  const bool grid_better = g.inverted != s.inverted ? g.inverted < s.inverted
                                                    : worst_element_measure(g) > worst_element_measure(s);
  if (grid_better) {
    *choice = {false, "the swept core left " + missed + "; the grid core did better"};
    return grid;
  }
  swept_report.seconds_total += report->seconds_total;
  *report = std::move(swept_report);
  *choice = {true, "the swept core left " + missed + ", the grid core no better"};
  return swept;
}

}  // namespace hexbite
