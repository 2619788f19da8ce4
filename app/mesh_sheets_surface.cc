#include "app/mesh_sheets_surface.h"

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/mesh_inputs.h"
#include "app/mesh_sheets.h"
#include "app/option_checks.h"
#include "common/error.h"
#include "common/json_text.h"
#include "common/progress.h"
#include "mesher/cycle_elimination.h"
#include "mesher/grid_mesher.h"
#include "mesher/hex_mesh_io.h"
#include "mesher/hex_quality.h"
#include "mesher/mandible_sheet_mesher.h"
#include "mesher/quad_check.h"
#include "mesher/quad_surface_io.h"
#include "mesher/quad_surface_placement.h"
#include "postprocess/quality_json.h"

namespace hexbite {

namespace {

nlohmann::json quad_json(const MandibleQuadReport& r, const QuadSurfaceReport& check) {
  nlohmann::json landmark_nodes = nlohmann::json::object();
  for (const auto& [name, d] : r.landmark_nodes) landmark_nodes[name] = d;
  return {{"macro_quads", r.macro_quads},
          {"quads", r.quads},
          {"vertices", check.vertices},
          {"chords", r.chords},
          {"max_chord_length", r.max_chord_length},
          {"self_intersecting_chords", check.self_intersecting_chords.size()},
          {"ball", check.ball},
          {"even", check.even},
          {"simple", check.simple},
          {"three_connected", check.three_connected},
          {"placement", r.placement},
          {"matched_points", r.matched_points},
          {"warp_residual_mm", r.warp_residual_mm},
          {"landmark_node_distance_mm", landmark_nodes},
          {"max_vertex_distance_mm", r.max_vertex_distance_mm},
          {"quads_to_surface_mm", r.quads_to_surface_mm},
          {"surface_to_quads_mm", r.surface_to_quads_mm},
          {"hausdorff_mm", r.hausdorff_mm},
          {"worst_quad_point", r.worst_quad_point},
          {"worst_surface_point", r.worst_surface_point},
          {"mean_edge_mm", r.mean_edge_mm},
          {"folded_quads", r.folded_quads},
          {"fidelity_rings",
           {{"rounds", r.fidelity_rounds},
            {"undone_rounds", r.fidelity_undone_rounds},
            {"quads_added", r.fidelity_quads_added}}},
          {"seconds", r.seconds}};
}

std::string quad_text(const std::string& surface, const MandibleQuadReport& r,
                      const QuadSurfaceReport& check) {
  char line[512];
  std::ostringstream out;
  std::snprintf(line, sizeof line,
                "Quad surface of %s: %d quads from %d macro quads (placed by %s, %zu points, warp residual "
                "%.2f mm), %d vertices, mean edge %.2f mm\n",
                surface.c_str(), r.quads, r.macro_quads, r.placement.c_str(), r.matched_points.size(),
                r.warp_residual_mm, check.vertices, r.mean_edge_mm);
  out << line;
  std::snprintf(
      line, sizeof line,
      "chords: %d (longest %d quads, %zu self-intersecting); ball %s, even %s, simple %s, 3-connected "
      "%s\n",
      r.chords, r.max_chord_length, check.self_intersecting_chords.size(), check.ball ? "yes" : "no",
      check.even ? "yes" : "no", check.simple ? "yes" : "no", check.three_connected ? "yes" : "no");
  out << line;
  std::snprintf(
      line, sizeof line,
      "distance to the input: vertices %.2g mm, quads -> surface %.3f mm, surface -> quads %.3f mm, "
      "Hausdorff %.3f mm; %d folded quads; %.2f s\n",
      r.max_vertex_distance_mm, r.quads_to_surface_mm, r.surface_to_quads_mm, r.hausdorff_mm, r.folded_quads,
      r.seconds);
  out << line;
  if (r.fidelity_rounds > 0) {
    std::snprintf(line, sizeof line,
                  "fidelity rings: %d rounds, +%d quads around the regions still farther than %.1f mm\n",
                  r.fidelity_rounds, r.fidelity_quads_added, r.fidelity_goal_mm);
    out << line;
  } else if (r.fidelity_undone_rounds > 0) {
    std::snprintf(line, sizeof line,
                  "fidelity rings: %d rounds undone (they did not bring the quads within %.1f mm)\n",
                  r.fidelity_undone_rounds, r.fidelity_goal_mm);
    out << line;
  }
  std::snprintf(line, sizeof line,
                "farthest: quads from the surface at (%.1f, %.1f, %.1f) mm, surface from the quads at (%.1f, "
                "%.1f, %.1f) mm\n",
                r.worst_quad_point[0], r.worst_quad_point[1], r.worst_quad_point[2], r.worst_surface_point[0],
                r.worst_surface_point[1], r.worst_surface_point[2]);
  out << line;
  return out.str();
}

// The refinement point of --refine-at: "X,Y,Z" in mm, or the name of a point of the landmark file.
LocalRefinementOptions refinement_options(const RefineCommandOptions& r, const Landmarks* landmarks,
                                          const std::string& landmark_file) {
  LocalRefinementOptions options;
  if (r.at.empty()) return options;
  options.radius_mm = r.radius_mm;
  options.levels = r.levels;
  options.point_names = {"--refine-at " + r.at};
  Vec3 p{};
  char rest = 0;
  if (std::sscanf(r.at.c_str(), "%lf,%lf,%lf%c", &p[0], &p[1], &p[2], &rest) == 3) {
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
      throw InputError("--refine-at '" + r.at +
                       "' is not a point: X, Y and Z must be finite numbers in mm (e.g. --refine-at "
                       "-27.9,-16.8,49.3), or give a landmark name with --landmarks L.yaml");
    options.points = {p};
    return options;
  }
  if (!landmarks)
    throw InputError("--refine-at '" + r.at +
                     "' is not X,Y,Z and no --landmarks file was given to look it up in: give the point as "
                     "X,Y,Z in mm (e.g. --refine-at -27.9,-16.8,49.3) or add --landmarks L.yaml");
  const std::optional<Vec3> named = landmarks->find(r.at);
  if (!named) {
    std::string names;
    for (const auto& [name, q] : landmarks->points) names += (names.empty() ? "" : ", ") + name;
    throw InputError("--refine-at '" + r.at + "' is not a point of the landmark file '" + landmark_file +
                     "': give one of its landmarks (" + names + "), a '<muscle>.insertion', or X,Y,Z in mm");
  }
  options.points = {*named};
  return options;
}

nlohmann::json refinement_json(const RefineCommandOptions& r, const LocalRefinementReport& report) {
  if (report.sites.empty()) return nullptr;
  const LocalRefinementSite& site = report.sites.front();
  return {{"at", r.at},
          {"point", site.point},
          {"on_surface", site.on_surface},
          {"radius_mm", r.radius_mm},
          {"levels", report.levels},
          {"patch_quads", report.patch_quads},
          {"patch_perimeter", report.patch_perimeter},
          {"quads_added", report.quads_added},
          {"vertices_added", report.vertices_added},
          {"moved_vertices", report.moved_vertices},
          {"relax_sweeps", report.relax_sweeps},
          {"folded_quads", report.folded_quads},
          {"edges_near_before", site.edges_before},
          {"edges_near_after", site.edges_after},
          {"mean_edge_near_before_mm", site.mean_edge_before_mm},
          {"mean_edge_near_after_mm", site.mean_edge_after_mm},
          {"seconds", report.seconds}};
}

std::string refinement_text(const RefineCommandOptions& r, const LocalRefinementReport& report) {
  if (report.sites.empty()) return "";
  const LocalRefinementSite& site = report.sites.front();
  char line[512];
  std::snprintf(line, sizeof line,
                "Local refinement at %s (%.1f, %.1f, %.1f) mm: %d rings of %d quads around a patch of %d "
                "quads (+%d quads); mean edge within %.1f mm %.2f -> %.2f mm (%d -> %d edges); %d folded "
                "quads; %.2f s\n",
                r.at.c_str(), site.on_surface[0], site.on_surface[1], site.on_surface[2], report.levels,
                report.patch_perimeter, report.patch_quads, report.quads_added, r.radius_mm,
                site.mean_edge_before_mm, site.mean_edge_after_mm, site.edges_before, site.edges_after,
                report.folded_quads, report.seconds);
  return line;
}

}  // namespace

void add_refine_options(CLI::App& cmd, RefineCommandOptions& o) {
  CLI::Option* at = cmd.add_option(
      "--refine-at", o.at,
      "Refine the quad surface locally around this point (the bite point): X,Y,Z in mm, or a name in the "
      "--landmarks file such as right_first_molar_bite_point");
  // number_in_range, as the other real options: CLI::Range answered "Value abc not in range 1.000000 to
  // 30.000000" and let NaN through to a third wording.
  char range[64];
  std::snprintf(range, sizeof range, "from %g to %g (mm)", kMinRefineRadiusMm, kMaxRefineRadiusMm);
  cmd.add_option("--refine-radius", o.radius_mm, "Radius of the refined patch around --refine-at, in mm")
      ->check(number_in_range(kMinRefineRadiusMm, kMaxRefineRadiusMm, range))
      ->capture_default_str()
      ->needs(at);
  cmd.add_option("--refine-levels", o.levels,
                 "Rings of quads added around the patch; each makes the quads inside it smaller")
      ->transform(count_in_range(1, kMaxRefineLevels))
      ->capture_default_str()
      ->needs(at);
}

void run_quad_from_mandible(const MandibleQuadCommandOptions& o) {
  const auto [surface, landmarks] = load_mesh_inputs(o.surface, o.units, o.landmarks);
  const LocalRefinementOptions refinement = refinement_options(o.refine, landmarks.get(), o.landmarks);
  MandibleQuadReport report;
  QuadSurfaceReport check;
  LocalRefinementReport refinement_report;
  QuadSurface quads;
  const InputTerms terms = quad_command_terms(o.units);
  try {
    quads = checked_mandible_quads(surface, landmarks.get(), o.target_quads, o.surface, o.landmarks, &report,
                                   &check, refinement, &refinement_report, terms);
  } catch (const RunError& e) {
    throw RunError(std::string(e.what()) + "; use " + terms.grid_method + " for this surface");
  }
  write_quad_obj(o.output, quads);
  if (o.json) {
    nlohmann::json j = quad_json(report, check);
    j["surface"] = o.surface;
    j["landmarks"] = o.landmarks.empty() ? nlohmann::json() : nlohmann::json(o.landmarks);
    j["target_quads"] = o.target_quads;
    j["local_refinement"] = refinement_json(o.refine, refinement_report);
    j["output"] = o.output;
    std::cout << json_text(j) << '\n';
  } else if (!is_quiet()) {
    std::cout << quad_text(o.surface, report, check) << refinement_text(o.refine, refinement_report);
    info("wrote " + o.output);
  }
}

void run_mesh_sheets_surface(const MeshSheetsSurfaceOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  const MandibleQuadCommandOptions& qo = o.quad;
  MandibleSheetOptions options;
  options.target_hexes = o.target_hexes;
  options.order = parse_elimination_order(o.order);
  options.surface_name = qo.surface;
  options.landmark_file = qo.landmarks;
  const auto [surface, landmarks] = load_mesh_inputs(qo.surface, qo.units, qo.landmarks);
  options.refinement = refinement_options(qo.refine, landmarks.get(), qo.landmarks);
  options.fit_volume = o.fit_volume;
  options.terms = mesh_command_terms(qo.units);
  MandibleSheetReport sheet_report;
  HexMesh mesh;
  try {
    mesh = mesh_mandible_by_sheets(surface, landmarks.get(), options, &sheet_report);
  } catch (const RunError& e) {
    throw RunError(std::string(e.what()) + "; use --method grid");
  }
  const EliminationOrder order = options.order;
  const MandibleQuadReport& quad_report = sheet_report.quad;
  const QuadSurfaceReport& check = sheet_report.quad_check;
  const SheetMeshReport& report = sheet_report.sheets;
  const MeshFidelity& fidelity = sheet_report.fidelity;
  const double total_seconds = seconds_since(t0);
  const bool valid = sheet_report.inverted == 0 && sheet_report.boundary_crossings.empty();
  const bool write = valid || o.allow_invalid;
  if (write) write_hex_mesh(qo.output, mesh);
  const QualitySummary& q = report.quality;
  if (qo.json) {
    nlohmann::json j;
    j["surface"] = qo.surface;
    j["landmarks"] = qo.landmarks.empty() ? nlohmann::json() : nlohmann::json(qo.landmarks);
    j["method"] = "sheets";
    j["order"] = elimination_order_name(order);
    j["target_hexes"] = o.target_hexes;
    j["quad_surface"] = quad_json(quad_report, check);
    j["local_refinement"] = refinement_json(qo.refine, sheet_report.refinement);
    add_sheet_report_json(report, j);
    j["pillow_hexes"] = sheet_report.pillow_hexes;
    j["boundary_crossings"] = sheet_report.boundary_crossings.size();
    j["seconds"] = {{"quad_surface", quad_report.seconds},
                    {"elimination", report.seconds_elimination},
                    {"embedding", report.seconds_embedding},
                    {"total", total_seconds}};
    j["fidelity"] = {{"hausdorff_mm", fidelity.hausdorff},
                     {"mesh_to_surface_mm", fidelity.hausdorff_mesh_to_surface},
                     {"surface_to_mesh_mm", fidelity.hausdorff_surface_to_mesh},
                     {"volume_difference", fidelity.volume_difference}};
    j["volume_fit"] =
        sheet_report.volume_fit ? volume_fit_to_json(*sheet_report.volume_fit) : nlohmann::json();
    j["output"] = write ? nlohmann::json(qo.output) : nlohmann::json();
    std::cout << json_text(j) << '\n';
  } else if (!is_quiet()) {
    std::ostringstream out;
    out << quad_text(qo.surface, quad_report, check) << refinement_text(qo.refine, sheet_report.refinement);
    char line[512];
    std::snprintf(
        line, sizeof line,
        "Cycle elimination (%s): %d eliminations (%d single, %d k-step; %d external, %d internal sheets), "
        "%d hexes with the pillow layer (%d under the quads), %d interior nodes\n",
        elimination_order_name(order), report.eliminations, report.eliminations_single,
        report.eliminations_k_step, report.external_sheets, report.internal_sheets, report.hexes,
        sheet_report.pillow_hexes, report.interior_vertices);
    out << line << look_ahead_text(report);
    out << sheet_quality_text(q);
    std::snprintf(
        line, sizeof line,
        "mesh boundary (slid on the input) to the input: Hausdorff %.3f mm (mesh -> surface %.3f mm, "
        "surface -> mesh %.3f mm), volume %+.1f %%\n",
        fidelity.hausdorff, fidelity.hausdorff_mesh_to_surface, fidelity.hausdorff_surface_to_mesh,
        100.0 * fidelity.volume_difference);
    out << line;
    if (sheet_report.volume_fit) out << "volume fit: " << describe(*sheet_report.volume_fit) << '\n';
    std::snprintf(line, sizeof line,
                  "time: quad surface %.2f s, elimination %.2f s, embedding %.2f s, total %.2f s\n",
                  quad_report.seconds, report.seconds_elimination, report.seconds_embedding, total_seconds);
    out << line;
    std::cout << out.str();
  }
  if (!sheet_report.boundary_crossings.empty()) {
    // Which quads cross depends on the target either way: the built-in mandible without landmarks crosses
    // at 1,400-1,500 target hexes and meshes at 1,600-4,000.
    const std::string text = sheet_report.boundary_crossing_text +
                             "; try another --target-hexes (more or fewer: which quads cross depends on it)" +
                             (qo.landmarks.empty() ? ", give the surface's --landmarks L.yaml," : "") +
                             " or use --method grid";
    if (!o.allow_invalid) throw RunError(text + "; no mesh written (--allow-invalid writes it anyway)");
    std::cerr << "hexbite: warning: wrote " << qo.output << " on purpose (--allow-invalid): " << text << '\n';
  }
  if (sheet_report.inverted > 0 && !o.allow_invalid)
    throw RunError(stay_inverted_text(mesh, q.inverted_hexes) +
                   "; no mesh written (--allow-invalid writes it anyway)");
  if (!qo.json) info("wrote " + qo.output);
}

}  // namespace hexbite
