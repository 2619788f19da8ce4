#include "app/mesh_sheets_surface.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "common/error.h"
#include "common/progress.h"
#include "mesher/cycle_elimination.h"
#include "mesher/grid_mesher.h"
#include "mesher/hex_mesh_io.h"
#include "mesher/landmarks.h"
#include "mesher/quad_check.h"
#include "mesher/quad_surface_io.h"
#include "mesher/quad_surface_placement.h"
#include "mesher/surface_check.h"
#include "mesher/surface_projector.h"
#include "mesher/units.h"
#include "postprocess/quality_json.h"

namespace hexbite {

namespace {

// Builds and checks the quad surface; the check failing is a defect of the template or its placement
// (RunError), not of the user's input. `surface` receives the input triangulation (in mm).
QuadSurface build_checked_quads(const MandibleQuadCommandOptions& o, MandibleQuadReport* report,
                                QuadSurfaceReport* check, TriSurface* surface_out) {
  const double scale = unit_to_mm(o.units);
  TriSurface& surface = *surface_out;
  surface = load_closed_surface(o.surface, scale);
  std::unique_ptr<Landmarks> landmarks;
  if (!o.landmarks.empty()) landmarks = std::make_unique<Landmarks>(read_landmarks(o.landmarks, scale));
  MandibleQuadOptions options;
  options.target_quads = o.target_quads;
  QuadSurface quads;
  try {
    quads = quad_surface_from_mandible(surface, landmarks.get(), o.landmarks, options, report);
  } catch (const InputError& e) {
    throw InputError("'" + o.surface + "': " + e.what());
  }
  *check = check_quad_surface(quads, o.surface + " (quad surface)");
  if (!check->usable()) {
    std::string problems;
    for (const auto& p : check->problems) problems += "; " + p;
    throw RunError("the quad surface built for '" + o.surface + "' fails its check" + problems +
                   "; use --method grid for this surface");
  }
  return quads;
}

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
  std::snprintf(line, sizeof line,
                "farthest: quads from the surface at (%.1f, %.1f, %.1f) mm, surface from the quads at (%.1f, "
                "%.1f, %.1f) mm\n",
                r.worst_quad_point[0], r.worst_quad_point[1], r.worst_quad_point[2], r.worst_surface_point[0],
                r.worst_surface_point[1], r.worst_surface_point[2]);
  out << line;
  return out.str();
}

std::string histogram_text(const std::vector<int>& counts) {
  std::string s;
  for (std::size_t d = 0; d < counts.size(); ++d)
    if (counts[d] > 0) s += (s.empty() ? "" : ", ") + std::to_string(d) + ": " + std::to_string(counts[d]);
  return s.empty() ? "none" : s;
}

// "hex 12 at (1.0, 2.0, 3.0) mm, ...": the first 10 inverted hexes with their centroids.
std::string inverted_list(const HexMesh& mesh, const std::vector<int>& inverted) {
  std::ostringstream out;
  const std::size_t shown = std::min<std::size_t>(inverted.size(), 10);
  for (std::size_t i = 0; i < shown; ++i) {
    Vec3 c{0, 0, 0};
    for (int v : mesh.hexes[inverted[i]])
      for (int a = 0; a < 3; ++a) c[a] += mesh.vertices[v][a] / 8.0;
    char buf[128];
    std::snprintf(buf, sizeof buf, "%shex %d at (%.1f, %.1f, %.1f) mm", i ? ", " : "", inverted[i], c[0],
                  c[1], c[2]);
    out << buf;
  }
  if (shown < inverted.size()) out << " and " << inverted.size() - shown << " more";
  return out.str();
}

// A pillow layer under the boundary: every boundary vertex v < quads.vertices.size() gets an inner copy,
// which takes its place in the hexes, and every boundary quad a hex between it and the copies of its
// corners. The boundary stays the quad surface (the same vertex ids and quads); no hex has more than one
// face on it afterwards, which removes the hexes wrapped around thin rims and tips. The copy starts 40 % of
// the way from v to the mean centroid of v's hexes.
void pillow(HexMesh& mesh, const QuadSurface& quads) {
  const int n = static_cast<int>(quads.vertices.size());
  std::vector<Vec3> inward(n, Vec3{0, 0, 0});
  std::vector<int> count(n, 0);
  for (const auto& hex : mesh.hexes) {
    Vec3 c{0, 0, 0};
    for (int v : hex)
      for (int a = 0; a < 3; ++a) c[a] += mesh.vertices[v][a] / 8.0;
    for (int v : hex)
      if (v < n) {
        for (int a = 0; a < 3; ++a) inward[v][a] += c[a];
        ++count[v];
      }
  }
  const int first = static_cast<int>(mesh.vertices.size());
  for (int v = 0; v < n; ++v) {
    Vec3 p = mesh.vertices[v];
    if (count[v] > 0)
      for (int a = 0; a < 3; ++a) p[a] += 0.4 * (inward[v][a] / count[v] - p[a]);
    mesh.vertices.push_back(p);
  }
  for (auto& hex : mesh.hexes)
    for (int& v : hex)
      if (v < n) v += first;
  for (const auto& q : quads.quads)
    mesh.hexes.push_back({q[0] + first, q[1] + first, q[2] + first, q[3] + first, q[0], q[1], q[2], q[3]});
}

// The optimizer for the pillowed mesh, whose boundary nodes slide on the input surface. Measured on both
// mandibles (docs/mandible_quads.md): a tether of a quarter edge (the default half edge lets nodes leave the
// condyles and coronoid tips, 1 to 2 mm more Hausdorff distance for 0.006 to 0.02 more mean scaled
// Jacobian) and the worst-element pass, which raises the smallest scaled Jacobian.
OptimizeOptions surface_optimizer_options() {
  OptimizeOptions o;
  o.boundary_tether = 0.25;
  o.worst_element_threshold = 0.3;
  o.scaled_jacobian_sweeps = 10;
  return o;
}

}  // namespace

void run_quad_from_mandible(const MandibleQuadCommandOptions& o) {
  MandibleQuadReport report;
  QuadSurfaceReport check;
  TriSurface surface;
  const QuadSurface quads = build_checked_quads(o, &report, &check, &surface);
  write_quad_obj(o.output, quads);
  if (o.json) {
    nlohmann::json j = quad_json(report, check);
    j["surface"] = o.surface;
    j["landmarks"] = o.landmarks.empty() ? nlohmann::json() : nlohmann::json(o.landmarks);
    j["target_quads"] = o.target_quads;
    j["output"] = o.output;
    std::cout << j.dump(2) << '\n';
  } else if (!is_quiet()) {
    std::cout << quad_text(o.surface, report, check);
    info("wrote " + o.output);
  }
}

void run_mesh_sheets_surface(const MeshSheetsSurfaceOptions& o) {
  if (o.target_hexes < 8 || o.target_hexes > 5000000)
    throw InputError("--target-hexes " + std::to_string(o.target_hexes) +
                     " is out of range: give a number from 8 to 5,000,000");
  const auto t0 = std::chrono::steady_clock::now();
  const EliminationOrder order = parse_elimination_order(o.order);
  MandibleQuadCommandOptions qo = o.quad;
  qo.target_quads = quads_for_target_hexes(o.target_hexes);
  MandibleQuadReport quad_report;
  QuadSurfaceReport check;
  TriSurface surface;
  const QuadSurface quads = build_checked_quads(qo, &quad_report, &check, &surface);

  // The boundary quads are our own construction, so the optimizer may let them slide on the input: only the
  // landmark nodes stay where they are (cycle elimination keeps the quad vertices' ids). The sheet mesher
  // itself only smooths the interior (its optimizer would hold the whole boundary fixed).
  SheetMeshOptions options;
  options.elimination.order = order;
  options.optimize = false;
  SheetMeshReport report;
  HexMesh mesh;
  try {
    mesh = mesh_by_cycle_elimination(quads, options, &report);
  } catch (const InputError& e) {
    throw RunError("cycle elimination on the quad surface of '" + qo.surface + "' (" +
                   std::to_string(quad_report.quads) + " quads): " + e.what() + "; use --method grid");
  } catch (const RunError& e) {
    throw RunError("cycle elimination on the quad surface of '" + qo.surface + "' (" +
                   std::to_string(quad_report.quads) + " quads): " + e.what() + "; use --method grid");
  }
  const auto t_embed = std::chrono::steady_clock::now();
  pillow(mesh, quads);
  std::vector<char> fixed(mesh.vertices.size(), 0);
  for (int v : quad_report.landmark_vertices) fixed[v] = 1;
  const SurfaceProjector projector(surface);
  report.optimize = optimize_hex_mesh(mesh, &projector, fixed, surface_optimizer_options());
  report.hexes = static_cast<int>(mesh.hexes.size());
  report.interior_vertices = static_cast<int>(mesh.vertices.size() - quads.vertices.size());
  report.quality = summarize_quality(mesh);
  const MeshFidelity fidelity = measure_fidelity(mesh, projector);
  report.seconds_embedding += seconds_since(t_embed);
  const double total_seconds = seconds_since(t0);
  const bool valid = report.quality.inverted == 0;
  const bool write = valid || o.allow_invalid;
  if (write) write_vtu(qo.output, mesh);
  const QualitySummary& q = report.quality;
  if (qo.json) {
    nlohmann::json j;
    j["surface"] = qo.surface;
    j["landmarks"] = qo.landmarks.empty() ? nlohmann::json() : nlohmann::json(qo.landmarks);
    j["method"] = "sheets";
    j["order"] = elimination_order_name(order);
    j["target_hexes"] = o.target_hexes;
    j["quad_surface"] = quad_json(quad_report, check);
    j["quads"] = report.quads;
    j["chords"] = report.chords;
    j["eliminations"] = {{"single", report.eliminations_single}, {"k_step", report.eliminations_k_step}};
    j["sheets"] = {{"external", report.external_sheets}, {"internal", report.internal_sheets}};
    j["eliminations_single"] = report.eliminations_single;
    j["eliminations_k_step"] = report.eliminations_k_step;
    j["chords_eliminated"] = report.chords_eliminated;
    j["external_sheets"] = report.external_sheets;
    j["internal_sheets"] = report.internal_sheets;
    j["hexes"] = report.hexes;
    j["pillow_hexes"] = report.quads;
    j["interior_nodes"] = report.interior_vertices;
    j["seconds"] = {{"quad_surface", quad_report.seconds},
                    {"elimination", report.seconds_elimination},
                    {"embedding", report.seconds_embedding},
                    {"total", total_seconds}};
    j["quality"] = quality_to_json(q);
    j["fidelity"] = {{"hausdorff_mm", fidelity.hausdorff},
                     {"mesh_to_surface_mm", fidelity.hausdorff_mesh_to_surface},
                     {"surface_to_mesh_mm", fidelity.hausdorff_surface_to_mesh},
                     {"volume_difference", fidelity.volume_difference}};
    j["output"] = write ? nlohmann::json(qo.output) : nlohmann::json();
    std::cout << j.dump(2) << '\n';
  } else if (!is_quiet()) {
    std::ostringstream out;
    out << quad_text(qo.surface, quad_report, check);
    char line[512];
    std::snprintf(
        line, sizeof line,
        "Cycle elimination (%s): %d eliminations (%d single, %d k-step; %d external, %d internal sheets), "
        "%d hexes with the pillow layer (%d under the quads), %d interior nodes\n",
        elimination_order_name(order), report.eliminations, report.eliminations_single,
        report.eliminations_k_step, report.external_sheets, report.internal_sheets, report.hexes,
        report.quads, report.interior_vertices);
    out << line;
    out << "interior node degrees (edges): " << histogram_text(q.node_degree.edges) << "; maximum "
        << q.node_degree.max_edges << "\n";
    std::snprintf(line, sizeof line,
                  "quality: scaled Jacobian min %.4f mean %.4f max %.4f; condition (cube = 3) min %.3f mean "
                  "%.3f max %.3f; Oddy mean %.3f max %.3f; %d inverted\n",
                  q.scaled_jacobian.min, q.scaled_jacobian.mean, q.scaled_jacobian.max, q.condition.min,
                  q.condition.mean, q.condition.max, q.oddy.mean, q.oddy.max, q.inverted);
    out << line;
    std::snprintf(
        line, sizeof line,
        "mesh boundary (slid on the input) to the input: Hausdorff %.3f mm (mesh -> surface %.3f mm, "
        "surface -> mesh %.3f mm), volume %+.1f %%\n",
        fidelity.hausdorff, fidelity.hausdorff_mesh_to_surface, fidelity.hausdorff_surface_to_mesh,
        100.0 * fidelity.volume_difference);
    out << line;
    std::snprintf(line, sizeof line,
                  "time: quad surface %.2f s, elimination %.2f s, embedding %.2f s, total %.2f s\n",
                  quad_report.seconds, report.seconds_elimination, report.seconds_embedding, total_seconds);
    out << line;
    std::cout << out.str();
  }
  if (!valid && !o.allow_invalid)
    throw RunError(std::to_string(q.inverted) +
                   " hexes stay inverted after optimization: " + inverted_list(mesh, q.inverted_hexes) +
                   "; no mesh written (--allow-invalid writes it anyway)");
  if (!qo.json) info("wrote " + qo.output);
}

}  // namespace hexbite
