#include "app/mesh_sheets.h"

#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/mesh_inputs.h"
#include "common/error.h"
#include "common/json_text.h"
#include "common/number_format.h"
#include "common/progress.h"
#include "mesher/cycle_elimination.h"
#include "mesher/hex_mesh_io.h"
#include "mesher/hex_quality.h"
#include "mesher/quad_surface_crossings.h"
#include "postprocess/quality_json.h"

namespace hexbite {

namespace {

std::string histogram_text(const std::vector<int>& counts) {
  std::string s;
  for (std::size_t d = 0; d < counts.size(); ++d)
    if (counts[d] > 0) s += (s.empty() ? "" : ", ") + std::to_string(d) + ": " + std::to_string(counts[d]);
  return s.empty() ? "none" : s;
}

std::string report_text(const MeshSheetsOptions& o, const SheetMeshReport& r) {
  std::ostringstream out;
  char line[256];
  out << "Meshed " << o.quad_surface << " (cycle elimination, " << elimination_order_name(r.order)
      << "): " << r.quads << " boundary quads, " << r.chords << " chords, " << r.eliminations
      << " eliminations (" << r.eliminations_single << " single, " << r.eliminations_k_step << " k-step; "
      << r.external_sheets << " external, " << r.internal_sheets << " internal sheets), " << r.decompositions
      << " decompositions, " << r.hexes << " hexes, " << r.interior_vertices << " interior nodes\n";
  out << look_ahead_text(r);
  if (r.pillow_hexes > 0)
    out << "pillow layer under the boundary: " << r.pillow_hexes << " hexes added, as "
        << r.inverted_without_pillow << " hexes stayed inverted without it\n";
  out << sheet_quality_text(r.quality);
  std::snprintf(line, sizeof line, "time: elimination %.2f s, embedding %.2f s\n", r.seconds_elimination,
                r.seconds_embedding);
  out << line;
  return out.str();
}

}  // namespace

void run_mesh_sheets(const MeshSheetsOptions& o) {
  if (o.quad_surface.empty())
    throw InputError(
        "--method sheets needs a SURFACE (a mandible: the quad template is placed on it) or --quad-surface "
        "Q.obj (a quad surface of a ball)");
  const EliminationOrder order = parse_elimination_order(o.order);
  const QuadSurface surface = load_quad_surface_input(o.quad_surface);
  // A folded surface passes the elimination's combinatorial tests and leaves hexes inverted after the
  // whole run; it is refused first (--allow-invalid meshes it anyway, and the crossing is named as a
  // warning).
  if (const std::string crossing = crossing_quads_problem(surface, crossing_quads(surface));
      !crossing.empty()) {
    if (!o.allow_invalid)
      throw InputError("'" + o.quad_surface + "': " + crossing + ": " + kUntangleQuadSurface +
                       " (--allow-invalid meshes it anyway)");
    std::cerr << "hexbite: warning: '" << o.quad_surface << "': " << crossing
              << " (meshing it anyway: --allow-invalid)\n";
  }
  SheetMeshOptions options;
  options.elimination.order = order;
  SheetMeshReport report;
  HexMesh mesh;
  try {
    mesh = mesh_by_cycle_elimination(surface, options, &report);
  } catch (const InputError& e) {
    throw InputError("'" + o.quad_surface + "': " + e.what());
  }
  const bool valid = report.quality.inverted == 0;
  const bool write = valid || o.allow_invalid;
  if (write) write_hex_mesh(o.output, mesh);
  if (o.json) {
    nlohmann::json j;
    j["quad_surface"] = o.quad_surface;
    j["method"] = "sheets";
    j["order"] = elimination_order_name(order);
    add_sheet_report_json(report, j);
    j["pillow_hexes"] = report.pillow_hexes;
    j["inverted_without_pillow"] = report.inverted_without_pillow;
    j["seconds"] = {{"elimination", report.seconds_elimination}, {"embedding", report.seconds_embedding}};
    j["output"] = write ? nlohmann::json(o.output) : nlohmann::json();
    std::cout << json_text(j) << '\n';
  } else if (!is_quiet()) {
    std::cout << report_text(o, report);
  }
  if (!valid && !o.allow_invalid)
    throw RunError(
        stay_inverted_text(mesh, report.quality.inverted_hexes) +
        "; the quads there may be too bent for the hexes under them (reflex and collinear corners are "
        "refused before the work): check the quad surface there, or mesh the solid with --method grid; no "
        "mesh written (--allow-invalid writes it anyway)");
  if (!o.json) info("wrote " + o.output);
}

void add_sheet_report_json(const SheetMeshReport& r, nlohmann::json& j) {
  j["quads"] = r.quads;
  j["chords"] = r.chords;
  j["eliminations"] = {{"single", r.eliminations_single}, {"k_step", r.eliminations_k_step}};
  j["sheets"] = {{"external", r.external_sheets}, {"internal", r.internal_sheets}};
  j["eliminations_single"] = r.eliminations_single;
  j["eliminations_k_step"] = r.eliminations_k_step;
  j["chords_eliminated"] = r.chords_eliminated;
  j["external_sheets"] = r.external_sheets;
  j["internal_sheets"] = r.internal_sheets;
  j["decompositions"] = r.decompositions;
  j["look_ahead_fallbacks"] = r.look_ahead_fallbacks;
  j["hexes"] = r.hexes;
  j["interior_nodes"] = r.interior_vertices;
  j["quality"] = quality_to_json(r.quality);
}

std::string look_ahead_text(const SheetMeshReport& r) {
  if (r.look_ahead_fallbacks == 0) return {};
  return std::string("the ") + elimination_order_name(r.order) +
         " order ran into a dead end; the look-ahead order completed instead (" +
         std::to_string(r.look_ahead_fallbacks) + (r.look_ahead_fallbacks > 1 ? " times" : " time") + ")\n";
}

std::string sheet_quality_text(const QualitySummary& q) {
  std::ostringstream out;
  out << "interior node degrees (edges): " << histogram_text(q.node_degree.edges) << "; maximum "
      << q.node_degree.max_edges << "\n";
  out << "interior node degrees (hexes): " << histogram_text(q.node_degree.hexes) << "; maximum "
      << q.node_degree.max_hexes << "\n";
  // A measure that could not be taken (the condition number of an inverted hex) reads n/a, not nan.
  const auto f = [](double v, int decimals) { return format_table_number(v, decimals, 0); };
  out << "quality: scaled Jacobian min " << f(q.scaled_jacobian.min, 4) << " mean "
      << f(q.scaled_jacobian.mean, 4) << " max " << f(q.scaled_jacobian.max, 4)
      << "; condition (cube = 3) min " << f(q.condition.min, 3) << " mean " << f(q.condition.mean, 3)
      << " max " << f(q.condition.max, 3) << "; Oddy mean " << f(q.oddy.mean, 3) << " max "
      << f(q.oddy.max, 3) << "; " << q.inverted << " inverted\n";
  return out.str();
}

}  // namespace hexbite
