// hexbite refine MESH.vtu [--surface SURFACE [--fit-volume]] -o fine.vtu [--units mm|cm|m] [--levels N]
// [--json]
//
// Splits every hex into 8 (every boundary quad into 4), puts the new boundary nodes onto the surface when one
// is given and re-optimizes where that made the quality worse; prints the quality before and after each step
// and the timings. The coarse nodes keep their numbers and positions, so coarse and fine results can be
// compared node by node; a .vtu output gives each child hex its parent's values of the input's own cell
// arrays. An input mesh with inverted hexes is refused up front (exit 2, naming them with
// their centroids); a refined mesh with inverted hexes is a failed run (exit 1, naming them likewise).
// Neither is written.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/carried_arrays.h"
#include "app/commands.h"
#include "app/mesh_inputs.h"
#include "app/option_checks.h"
#include "common/error.h"
#include "common/json_text.h"
#include "common/progress.h"
#include "mesher/boundary_fit.h"
#include "mesher/hex_boundary.h"
#include "mesher/hex_mesh_io.h"
#include "mesher/hex_quality.h"
#include "mesher/hex_refine.h"
#include "mesher/surface_projector.h"
#include "mesher/vec3.h"
#include "postprocess/quality_json.h"

namespace hexbite {

namespace {

// Each level multiplies the hex count by 8; beyond this the mesh would not fit a workstation's memory.
constexpr long long kMaxRefinedHexes = 20000000;

struct RefineCliOptions {
  std::string mesh;
  std::string surface;
  std::string output;
  std::string units = "mm";
  int levels = 1;
  bool fit_volume = false;
  bool json = false;
};

std::string fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

std::string quality_row(const std::string& stage, const QualitySummary& q, double seconds) {
  char line[256];
  std::snprintf(
      line, sizeof line, "%-18s %9d %8.4f %8.4f %8.4f   %8.3f %8.3f %8.3f   %8.3f %10.3f   %8d %8.2f\n",
      stage.c_str(), q.hexes, q.scaled_jacobian.min, q.scaled_jacobian.mean, q.scaled_jacobian.max,
      q.condition.min, q.condition.mean, q.condition.max, q.oddy.mean, q.oddy.max, q.inverted, seconds);
  return line;
}

std::string report_text(const RefineCliOptions& o, const RefineReport& r) {
  std::ostringstream out;
  out << "Refined " << o.mesh << ": " << o.levels << (o.levels == 1 ? " level, " : " levels, ")
      << r.before.hexes << " -> " << r.after.hexes << " hexes, " << r.before.nodes << " -> " << r.after.nodes
      << " nodes\n";
  out << (o.surface.empty() ? std::string("no surface: plain parametric refinement\n")
                            : "new boundary nodes projected onto " + o.surface + "\n");
  out << '\n';
  char header[256];
  std::snprintf(header, sizeof header, "%-18s %9s %8s %8s %8s   %8s %8s %8s   %8s %10s   %8s %8s\n", "stage",
                "hexes", "SJ min", "SJ mean", "SJ max", "k min", "k mean", "k max", "Oddy avg", "Oddy max",
                "inverted", "seconds");
  out << header;
  out << quality_row("input", r.before, 0.0);
  for (std::size_t i = 0; i < r.levels.size(); ++i) {
    const RefineLevelReport& l = r.levels[i];
    const std::string level = "level " + std::to_string(i + 1);
    out << quality_row(level + " split", l.parametric, l.seconds_split);
    if (o.surface.empty()) continue;
    out << quality_row(level + " projected", l.projected, l.seconds_project);
    if (l.optimized) out << quality_row(level + " optimized", l.final_quality, l.seconds_optimize);
  }
  out << "(element scaled Jacobian SJ = minimum over the corners; condition number k = |A|_F |A^-1|_F, cube "
         "= 3, "
         "worst corner; k and Oddy over the hexes that are not inverted)\n\n";
  for (std::size_t i = 0; i < r.levels.size() && !o.surface.empty(); ++i) {
    const RefineLevelReport& l = r.levels[i];
    out << "level " << i + 1 << ": " << l.projected_nodes << " boundary nodes projected (largest move "
        << fmt("%.4f", l.max_projection) << " mm), " << l.backed_off_nodes
        << " backed off to avoid inverting a hex, " << l.damaged_hexes << " hexes damaged; "
        << (l.optimized ? "re-optimized " + std::to_string(l.optimized_hexes) + " hexes around them (" +
                              std::to_string(l.optimize.iterations) + " Newton sweeps)"
                        : std::string("not re-optimized (projection damaged nothing)"))
        << '\n';
    if (l.off_surface_nodes > 0)
      out << "  warning: " << l.off_surface_nodes << " new boundary nodes stay off the surface (up to "
          << fmt("%.3f", l.max_surface_distance)
          << " mm) because moving them onto it would invert a hex; the coarse boundary is far from the "
             "surface "
             "there\n";
  }
  if (r.volume_fit) out << "volume fit (input nodes kept): " << describe(*r.volume_fit) << '\n';
  double split = 0, project = 0, optimize = 0;
  for (const RefineLevelReport& l : r.levels) {
    split += l.seconds_split;
    project += l.seconds_project;
    optimize += l.seconds_optimize;
  }
  out << "time: split " << fmt("%.2f", split) << " s, projection " << fmt("%.2f", project)
      << " s, optimization " << fmt("%.2f", optimize) << " s, total (with quality measurements) "
      << fmt("%.2f", r.seconds_total) << " s\n";
  return out.str();
}

nlohmann::json report_json(const RefineCliOptions& o, const RefineReport& r, bool written) {
  nlohmann::json j;
  j["mesh"] = o.mesh;
  j["surface"] = o.surface.empty() ? nlohmann::json() : nlohmann::json(o.surface);
  j["levels"] = o.levels;
  j["before"] = quality_to_json(r.before);
  j["after"] = quality_to_json(r.after);
  nlohmann::json levels = nlohmann::json::array();
  for (const RefineLevelReport& l : r.levels) {
    nlohmann::json level = {
        {"hexes", l.hexes},
        {"nodes", l.nodes},
        {"projected_nodes", l.projected_nodes},
        {"backed_off_nodes", l.backed_off_nodes},
        {"max_projection_mm", l.max_projection},
        {"max_surface_distance_mm", l.max_surface_distance},
        {"split", quality_to_json(l.parametric)},
        {"projected", quality_to_json(l.projected)},
        {"damaged_hexes", l.damaged_hexes},
        {"off_surface_nodes", l.off_surface_nodes},
        {"optimized", l.optimized},
        {"optimized_hexes", l.optimized_hexes},
        {"final", quality_to_json(l.final_quality)},
        {"seconds",
         {{"split", l.seconds_split}, {"project", l.seconds_project}, {"optimize", l.seconds_optimize}}}};
    if (l.optimized)
      level["optimizer"] = {{"untangle_sweeps", l.optimize.untangle_sweeps},
                            {"iterations", l.optimize.iterations},
                            {"rounds", l.optimize.rounds},
                            {"energy_before", l.optimize.energy_before},
                            {"energy_after", l.optimize.energy_after}};
    levels.push_back(level);
  }
  j["level_reports"] = levels;
  j["volume_fit"] = r.volume_fit ? volume_fit_to_json(*r.volume_fit) : nlohmann::json();
  j["seconds_total"] = r.seconds_total;
  j["output"] = written ? nlohmann::json(o.output) : nlohmann::json();
  return j;
}

// The mesh must be one made from the surface: its boundary nodes lie on it (up to the volume fit's offset,
// a fraction of an edge). A mesh of another solid, or a surface in other units than --units says, would
// otherwise be "refined" onto it, every new boundary node dragged tens of millimetres.
void require_mesh_on_surface(const HexMeshInput& input, const SurfaceProjector& surface,
                             const RefineCliOptions& o) {
  const HexMesh& coarse = input.mesh;
  const HexBoundary boundary = extract_boundary(coarse);
  double edges = 0;
  long count = 0;
  for (const auto& q : boundary.surface.quads)
    for (int i = 0; i < 4; ++i, ++count)
      edges +=
          vec3::norm(vec3::sub(boundary.surface.vertices[q[(i + 1) % 4]], boundary.surface.vertices[q[i]]));
  if (count == 0) return;
  const double limit = 0.5 * edges / static_cast<double>(count);
  long far = 0;
  double farthest = 0;
  int worst = -1;
  for (int v : boundary.boundary_vertices) {
    const double d = surface.closest(coarse.vertices[v]).distance;
    if (d > limit) ++far;
    if (d > farthest) farthest = d, worst = v;
  }
  if (far * 10 <= static_cast<long>(boundary.boundary_vertices.size())) return;
  std::ostringstream text;
  text.precision(3);
  text << "'" << o.mesh << "' does not lie on '" << o.surface << "': " << far << " of "
       << boundary.boundary_vertices.size() << " boundary nodes are farther than half a mean boundary edge ("
       << limit << " mm) from it, up to " << farthest << " mm (node " << worst << input.node_suffix(worst)
       << ", at (" << coarse.vertices[worst][0] << ", " << coarse.vertices[worst][1] << ", "
       << coarse.vertices[worst][2] << ") mm)";
  // A mesh of no bone's size is the one off in scale: --units cannot fix it, as it sets the surface's unit.
  const double extent = largest_extent(coarse.vertices);
  if (!mesh_size_warning(extent).empty())
    text << "; the mesh is " << extent
         << " mm across, no bone's size: hex mesh files are read in mm, so scale the mesh to millimetres "
            "where it was made (--units sets the unit of the surface only)";
  else
    text << "; give the surface the mesh was made from, in its units (--units, now " << o.units << ")";
  throw InputError(text.str());
}

// The input's cell arrays for the refined mesh: the children of hex h are hexes h << shift to
// ((h + 1) << shift) - 1 (refine_to_surface), and each gets h's values.
std::vector<MeshArray> arrays_of_children(const std::vector<MeshArray>& arrays, std::size_t hexes,
                                          int shift) {
  std::vector<int> parent_of;
  for (std::size_t h = 0; h < (hexes << shift); ++h) parent_of.push_back(static_cast<int>(h >> shift));
  std::vector<MeshArray> out;
  for (const MeshArray& a : arrays) out.push_back(array_tuples(a, parent_of));
  return out;
}

void run_refine(const RefineCliOptions& o) {
  if (o.fit_volume && o.surface.empty())
    throw InputError("--fit-volume fits the refined boundary to the volume of the --surface: give --surface");
  std::vector<MeshArray> cell_arrays, point_arrays;
  std::vector<std::string> not_read;
  const HexMeshInput input = load_hex_mesh_input(o.mesh, &cell_arrays, &point_arrays, &not_read);
  const HexMesh& coarse = input.mesh;
  const long long refined = static_cast<long long>(coarse.hexes.size()) << (3 * o.levels);
  if (refined > kMaxRefinedHexes)
    throw InputError("--levels " + std::to_string(o.levels) + " would turn the " +
                     std::to_string(coarse.hexes.size()) + " hexes of " + o.mesh + " into " +
                     std::to_string(refined) + " hexes, more than " + std::to_string(kMaxRefinedHexes) +
                     "; use fewer levels");
  // Every child of an inverted hex is inverted too, so refining an inverted mesh can only fail at the end.
  require_no_inverted_hexes(input, o.mesh, "which refinement cannot repair");
  std::unique_ptr<SurfaceProjector> projector;
  if (!o.surface.empty()) {
    projector = std::make_unique<SurfaceProjector>(load_surface_input(o.surface, o.units));
    require_mesh_on_surface(input, *projector, o);
  }

  RefineOptions options;
  options.levels = o.levels;
  options.fit_volume = o.fit_volume;
  RefineReport report;
  const HexMesh fine = refine_to_surface(coarse, projector.get(), options, &report);
  const bool valid = report.after.inverted == 0;
  if (valid) {
    const CellArrays cells = split_cell_arrays(coarse, cell_arrays);
    write_hex_mesh(o.output, fine, arrays_of_children(cells.own, coarse.hexes.size(), 3 * o.levels));
    warn_arrays_not_carried(o.mesh, o.output, "refine", cells, point_arrays, false, not_read);
    input.warn_physical_groups_not_carried(o.mesh, o.output, "refine");
  }

  if (o.json)
    std::cout << json_text(report_json(o, report, valid)) << '\n';
  else if (!is_quiet())
    std::cout << report_text(o, report);
  if (!valid) {
    throw RunError(std::to_string(report.after.inverted) + " hexes of the refined mesh are inverted: " +
                   hex_list_text(fine, report.after.inverted_hexes, 20,
                                 [&](int h) {
                                   const int parent = h >> (3 * o.levels);
                                   return " (in input hex " + std::to_string(parent) +
                                          input.element_suffix(parent) + ")";
                                 }) +
                   "; no mesh written");
  }
  if (!o.json) info("wrote " + o.output);
}

}  // namespace

void add_refine_command(CLI::App& app) {
  auto o = std::make_shared<RefineCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "refine",
      "Split every hex into 8 (boundary nodes onto the surface), for coarse-against-fine validation");
  cmd->add_option("MESH", o->mesh, "Hex mesh (.vtu, or Gmsh .msh 4.1 / 2.2 ASCII)")->required();
  cmd->add_option(
      "--surface", o->surface,
      "Closed surface the mesh fills (.stl .obj .ply .off .vtp); new boundary nodes are projected "
      "onto it. Without it the refinement is purely parametric");
  cmd->add_option("-o,--output", o->output,
                  "Refined mesh: .vtu (with per-hex quality arrays), .inp (Abaqus / CalculiX) or .msh (Gmsh)")
      ->required()
      ->check(output_hex_mesh_file());
  CLI::Option* units = cmd->add_option("--units", o->units, "Length unit of the --surface file: mm, cm or m")
                           ->default_val("mm");
  cmd->add_flag("--fit-volume", o->fit_volume,
                "After the refinement, move the new boundary nodes off the --surface until the boundary "
                "quads straddle it (for a mesh made with hexbite mesh --fit-volume; the input's nodes stay)");
  cmd->add_option("--levels", o->levels, "Number of refinement levels (each multiplies the hexes by 8)")
      ->transform(count_in_range(1, 4))
      ->default_val(1);
  cmd->add_flag("--json", o->json, "Print one JSON object instead of the tables");
  cmd->callback([o, units] {
    // The mesh is read in mm whatever --units says: without a surface it would be silently ignored.
    if (units->count() > 0 && o->surface.empty())
      throw InputError(
          "--units is the unit of the --surface file and the mesh is read in mm: give --surface, "
          "or leave --units out");
    run_refine(*o);
  });
}

}  // namespace hexbite
