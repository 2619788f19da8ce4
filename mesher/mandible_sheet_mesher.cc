#include "mesher/mandible_sheet_mesher.h"

#include <algorithm>
#include <chrono>
#include <limits>

#include "common/error.h"
#include "common/progress.h"
#include "mesher/hex_optimize.h"
#include "mesher/hex_pillow.h"
#include "mesher/hex_quality.h"
#include "mesher/surface_projector.h"

namespace hexbite {

namespace {

// Step 3. The pillow layer (pillow_quad_boundary, mesher/hex_pillow.h: every quad vertex gets an inner copy
// 40 % of the way to the mean centroid of its hexes, every quad a hex; the boundary stays the quad surface
// with the same vertex ids); then the interior is smoothed (barycentric) and untangled with the whole
// boundary held (on both mandibles no hex stays inverted), so that the sliding optimization starts valid:
// its own untangling slid boundary nodes up to 13 mm off the quad surface (docs/mandible_quads.md).
void pillow(HexMesh& mesh, const QuadSurface& quads) {
  pillow_quad_boundary(mesh, quads, 0.4);
  std::vector<char> inner(mesh.vertices.size(), 1);
  std::fill(inner.begin(), inner.begin() + quads.vertices.size(), 0);
  barycentric_smoothing(mesh, inner, OptimizeOptions{}.barycentric_iterations);
  untangle(mesh, inner, std::vector<char>(mesh.vertices.size(), 0), nullptr,
           OptimizeOptions{}.max_untangle_sweeps);
}

// Step 4's optimizer. Measured on both mandibles (docs/mandible_quads.md): a tether of a quarter edge (the
// default half edge lets nodes leave the condyles and coronoid tips, 1 to 2 mm more Hausdorff distance for
// 0.006 to 0.02 more mean scaled Jacobian); the worst-element pass, which raises the smallest scaled
// Jacobian, with a reach of half an edge (a quarter: 0.005 to 0.013 less mean scaled Jacobian, 0 to 0.6 mm
// less Hausdorff distance of the boundary), in two rounds (the real jaw's minimum without landmarks 0.274
// to 0.317); last the mean stage, 10 sweeps (mean scaled Jacobian 0.815 to 0.854 on the real jaw, 0.881 to
// 0.905 on the built-in mandible; the minima unchanged on all four inputs).
OptimizeOptions surface_optimizer_options() {
  OptimizeOptions o;
  o.boundary_tether = 0.25;
  o.worst_element_threshold = 0.3;
  o.worst_element_reach = 0.5;
  o.scaled_jacobian_sweeps = 10;
  o.worst_element_rounds = 2;
  o.mean_jacobian_sweeps = 10;
  o.barycentric_iterations = 0;  // pillow() smoothed the interior with the boundary held
  return o;
}

}  // namespace

QuadSurface checked_mandible_quads(const TriSurface& surface, const Landmarks* landmarks, int target_quads,
                                   const std::string& surface_name, const std::string& landmark_file,
                                   MandibleQuadReport* report, QuadSurfaceReport* check,
                                   const LocalRefinementOptions& refinement,
                                   LocalRefinementReport* refinement_report, const InputTerms& terms) {
  MandibleQuadOptions options;
  options.target_quads = target_quads;
  options.terms = terms;
  QuadSurface quads;
  try {
    quads = quad_surface_from_mandible(surface, landmarks, landmark_file, options, report);
  } catch (const InputError& e) {
    throw InputError("'" + surface_name + "': " + e.what());
  }
  if (refinement.enabled())
    quads = refine_quads_locally(quads, SurfaceProjector(surface), report->landmark_vertices, refinement,
                                 refinement_report);
  *check = check_quad_surface(quads, surface_name + " (quad surface)");
  if (!check->usable()) {
    std::string problems;
    for (const auto& p : check->problems) problems += "; " + p;
    throw RunError("the quad surface built for '" + surface_name + "' fails its check" + problems);
  }
  // The placed template can fold over a thin part of the bone: at high densities (from about 2,500 quads on
  // both mandibles, 4 to 282 crossing pairs measured) or with another bone's landmarks. Every combinatorial
  // test passes, and the sheet mesh on it overlapped itself with exit 0.
  if (const std::string crossing = crossing_quads_problem(quads, crossing_quads(quads)); !crossing.empty())
    throw RunError("the quad surface built for '" + surface_name + "' (" +
                   std::to_string(quads.quads.size()) + " quads): " + crossing +
                   ": the placed template folds over a thin part of the bone there (at high densities, or "
                   "when the landmarks do not fit the surface); ask for fewer quads or hexes, or check the "
                   "landmarks");
  if (refinement.enabled()) {
    report->quads = check->quads;
    report->chords = static_cast<int>(check->chords.size());
    report->max_chord_length = 0;
    for (const Chord& c : check->chords)
      report->max_chord_length = std::max(report->max_chord_length, c.length());
    report->mean_edge_mm =  // over every edge: an infinite radius
        mean_edge_near(quads, Vec3{0, 0, 0}, std::numeric_limits<double>::infinity());
  }
  return quads;
}

HexMesh mesh_mandible_by_sheets(const TriSurface& surface, const Landmarks* landmarks,
                                const MandibleSheetOptions& o, MandibleSheetReport* report_out) {
  MandibleSheetReport local;
  MandibleSheetReport& report = report_out ? *report_out : local;
  report = MandibleSheetReport{};
  // The quad count follows from the hex count; past the template's 200,000 quads say so in the user's terms
  // (before: "--target-quads 206362 is out of range", an option of another command that was never given).
  if (const int q = quads_for_target_hexes(o.target_hexes); q > 200000) {
    long most = o.target_hexes;
    while (most > 8 && quads_for_target_hexes(most) > 200000) most = most * 99 / 100;
    while (quads_for_target_hexes(most + 1) <= 200000) ++most;
    throw InputError(
        o.terms.target_hexes + " " + std::to_string(o.target_hexes) + " asks for a quad surface of " +
        std::to_string(q) + " quads, more than the 200,000 of the mandible template: give at " + "most " +
        std::to_string(most) + " hexes with " + o.terms.sheets_method + ", or use " + o.terms.grid_method);
  }
  const QuadSurface quads = checked_mandible_quads(
      surface, landmarks, quads_for_target_hexes(o.target_hexes), o.surface_name, o.landmark_file,
      &report.quad, &report.quad_check, o.refinement, &report.refinement, o.terms);

  // Step 2. Cycle elimination keeps the quad vertices' ids, so the landmark vertices stay valid.
  SheetMeshOptions options;
  options.elimination.order = o.order;
  // The ring chords first, the bite-point refinement's and then those of the placement's fidelity
  // refinement (latest first): their collapse gives back the unrefined quads, whose elimination then runs
  // as without refinement, and the rings become pillow sheets under their patches.
  options.elimination.first_rungs = report.refinement.ring_rungs;
  options.elimination.first_rungs.insert(options.elimination.first_rungs.end(),
                                         report.quad.ring_rungs.begin(), report.quad.ring_rungs.end());
  options.optimize = false;
  SheetMeshReport& sheets = report.sheets;
  HexMesh mesh;
  const std::string where = "cycle elimination on the quad surface of '" + o.surface_name + "' (" +
                            std::to_string(report.quad.quads) + " quads): ";
  try {
    mesh = mesh_by_cycle_elimination(quads, options, &sheets);
  } catch (const InputError& e) {
    throw RunError(where + e.what());
  } catch (const RunError& e) {
    throw RunError(where + e.what());
  }

  // Steps 3 to 5.
  const auto t_embed = std::chrono::steady_clock::now();
  pillow(mesh, quads);
  report.pillow_hexes = static_cast<int>(quads.quads.size());
  std::vector<char> fixed(mesh.vertices.size(), 0);
  for (int v : report.quad.landmark_vertices) fixed[v] = 1;
  const SurfaceProjector projector(surface);
  sheets.optimize = optimize_hex_mesh(mesh, &projector, fixed, surface_optimizer_options());
  if (o.fit_volume) report.volume_fit = fit_boundary_to_volume(mesh, projector, fixed);
  sheets.hexes = static_cast<int>(mesh.hexes.size());
  sheets.interior_vertices = static_cast<int>(mesh.vertices.size() - quads.vertices.size());
  sheets.quality = summarize_quality(mesh);
  report.fidelity = measure_fidelity(mesh, projector);
  sheets.seconds_embedding += seconds_since(t_embed);
  report.inverted = sheets.quality.inverted;
  // The sliding optimization keeps every hex valid but does not see two parts of the boundary meet.
  const QuadSurface boundary{
      std::vector<Vec3>(mesh.vertices.begin(), mesh.vertices.begin() + quads.vertices.size()), quads.quads};
  report.boundary_crossings = crossing_quads(boundary);
  report.boundary_crossing_text =
      crossing_quads_problem(boundary, report.boundary_crossings, "the mesh's boundary, slid on the input,");
  return mesh;
}

}  // namespace hexbite
