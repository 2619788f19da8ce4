// hexbite mesh SURFACE --method grid --target-hexes N -o mesh.vtu [--units mm|cm|m] [--landmarks L.yaml]
// [--fit-volume] [--json] [--allow-invalid]
// hexbite mesh SURFACE --method sheets [--landmarks L.yaml] --target-hexes N -o mesh.vtu [--refine-at
// X,Y,Z|LANDMARK [--refine-radius MM] [--refine-levels K]] (a mandible:
// app/mesh_sheets_surface.h) or hexbite mesh --method sheets --quad-surface Q.obj -o mesh.vtu
// (app/mesh_sheets.h)
//
// Meshes a closed triangulated solid with hexahedra (overlay grid + pillow layer + optimization) and prints
// the quality per phase (like the seed paper's Table 1), the timings and the geometric fidelity. A mesh
// that stays inverted is a failed run (exit 1, naming the inverted hexes with their centroids) and is not
// written unless --allow-invalid asks for it. With --landmarks, the surface regions that the cell size
// cannot resolve are named by their nearest landmark and muscle insertion. --fit-volume then moves the
// boundary nodes off the surface until the mesh holds the surface's volume (mesher/boundary_fit.h).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <sstream>

#include "app/commands.h"
#include "app/mesh_inputs.h"
#include "app/mesh_sheets.h"
#include "app/mesh_sheets_surface.h"
#include "app/option_checks.h"
#include "common/error.h"
#include "common/json_text.h"
#include "common/progress.h"
#include "mesher/auto_core.h"
#include "mesher/boundary_fit.h"
#include "mesher/grid_mesher.h"
#include "mesher/hex_mesh_io.h"
#include "mesher/hex_quality.h"
#include "mesher/tri_surface.h"
#include "postprocess/quality_json.h"

namespace hexbite {

namespace {

struct MeshOptions {
  std::string surface;
  std::string method = "grid";
  long target = 2500;
  std::string output;
  std::string units = "mm";
  bool json = false;
  bool allow_invalid = false;
  bool fit_volume = false;
  std::string grid_frame = "axes";  // --method grid: axes or arch (mesher/arch_frame.h)
  std::string core = "grid";  // --method grid: grid, swept (mesher/swept_core.h) or auto (mesher/auto_core.h)
  double margin = GridMeshOptions{}.margin;  // given: that margin everywhere, on three grids
  std::string quad_surface;                  // --method sheets
  std::string order = "geometric";           // --method sheets
  std::string landmarks;                     // --method sheets on a SURFACE; names unresolved parts for grid
  RefineCommandOptions refine;               // --method sheets on a SURFACE
  // The options given on the command line (count() > 0, so never a default), by name: "--margin", "surface".
  std::set<std::string> given;
  bool was_given(const std::string& name) const { return given.count(name) > 0; }
};

std::string fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

std::string phase_table(const OptimizeReport& r) {
  std::ostringstream out;
  char line[256];
  std::snprintf(line, sizeof line, "%-12s %8s %8s %8s   %8s %8s %8s   %8s %10s   %8s %8s\n", "phase",
                "SJ min", "SJ mean", "SJ max", "k min", "k mean", "k max", "Oddy avg", "Oddy max", "inverted",
                "seconds");
  out << line;
  for (const PhaseQuality& p : r.phases) {
    const QualitySummary& q = p.quality;
    std::snprintf(line, sizeof line,
                  "%-12s %8.4f %8.4f %8.4f   %8.3f %8.3f %8.3f   %8.3f %10.3f   %8d %8.2f\n", p.phase.c_str(),
                  q.scaled_jacobian.min, q.scaled_jacobian.mean, q.scaled_jacobian.max, q.condition.min,
                  q.condition.mean, q.condition.max, q.oddy.mean, q.oddy.max, q.inverted, p.seconds);
    out << line;
  }
  out << "(element scaled Jacobian SJ = minimum over the corners; condition number k = |A|_F |A^-1|_F, "
         "cube = 3, worst corner; k and Oddy over the hexes that are not inverted)\n";
  return out.str();
}

// The frame of the kept grid: the swept core's is the arch's (--core auto may keep it with --grid-frame
// axes).
std::string grid_frame_used(const MeshOptions& o, const GridMeshReport& r) {
  return r.swept ? "arch" : r.principal_frame ? "principal" : r.face_frame ? "faces" : o.grid_frame;
}

// A retry's count of inverted hexes, null when that frame was not tried.
nlohmann::json tried_count(int inverted) {
  return inverted >= 0 ? nlohmann::json(inverted) : nlohmann::json();
}

// --core auto's line: which core it kept, and why when not simply the swept one.
std::string auto_core_line(const AutoCoreChoice& choice) {
  return std::string("--core auto kept the ") + (choice.swept ? "swept" : "grid") + " core" +
         (choice.reason.empty() ? "" : " (" + choice.reason + ")");
}

std::string report_text(const MeshOptions& o, const HexMesh& mesh, const GridMeshReport& r,
                        const std::optional<AutoCoreChoice>& choice) {
  std::ostringstream out;
  const MeshFidelity& f = r.fidelity;
  out << "Meshed " << o.surface << " (grid + pillow"
      << (grid_frame_used(o, r) == "arch"        ? ", along the arch"
          : grid_frame_used(o, r) == "principal" ? ", along the principal axes"
          : grid_frame_used(o, r) == "faces"     ? ", along the largest flat faces"
                                                 : "")
      << (r.swept ? ", swept core" : "") << "): " << mesh.hexes.size() << " hexes (" << r.core_hexes
      << " core + " << r.pillow_hexes << " pillow), " << mesh.vertices.size() << " nodes; target " << o.target
      << "\n";
  out << "cell size " << fmt("%.3f", r.cell_size) << " mm, grid " << r.grid[0] << " x " << r.grid[1] << " x "
      << r.grid[2] << (r.swept ? " (along the arch x layers across x up)" : "") << ", "
      << (r.swept ? std::to_string(r.cells_in_dropped_components) + " columns dropped for a manifold core"
                  : std::to_string(r.cells_added_for_manifold) + " cells added for a manifold core")
      << (r.attempts > 1 ? ", the best of " + std::to_string(r.attempts) + " grids" : std::string()) << "\n";
  if (choice) out << auto_core_line(*choice) << '\n';
  if (r.principal_retry) out << principal_retry_text(*r.principal_retry) << '\n';
  out << '\n' << phase_table(r.optimize) << '\n';
  out << "optimizer: " << r.optimize.untangle_sweeps << " untangling sweeps, " << r.optimize.iterations
      << " Newton sweeps in " << r.optimize.rounds << " rounds; sum of squared condition numbers "
      << fmt("%.6g", r.optimize.energy_before) << " -> " << fmt("%.6g", r.optimize.energy_after) << '\n';
  out << "time: core " << fmt("%.2f", r.seconds_core) << " s, pillow " << fmt("%.2f", r.seconds_pillow)
      << " s, optimization " << fmt("%.2f", r.seconds_optimize) << " s, fidelity "
      << fmt("%.2f", r.seconds_fidelity) << " s, total " << fmt("%.2f", r.seconds_total) << " s\n";
  out << "fidelity: Hausdorff distance " << fmt("%.3f", f.hausdorff) << " mm (mesh -> surface "
      << fmt("%.3f", f.hausdorff_mesh_to_surface) << ", surface -> mesh "
      << fmt("%.3f", f.hausdorff_surface_to_mesh) << "), mean edge length " << fmt("%.3f", f.mean_edge_length)
      << " mm\n";
  out << "volume: mesh " << fmt("%.1f", f.mesh_volume) << " mm^3, surface " << fmt("%.1f", f.surface_volume)
      << " mm^3, difference " << fmt("%+.2f", 100.0 * f.volume_difference) << " %\n";
  if (r.volume_fit) out << "volume fit: " << describe(*r.volume_fit) << '\n';
  if (!f.unresolved.empty()) {
    out << "not resolved at this size (" << f.unresolved.size()
        << (f.unresolved.size() == 1 ? " region):\n" : " regions):\n");
    for (const std::string& line : unresolved_listing(f.unresolved)) out << "  " << line << '\n';
  }
  return out.str();
}

nlohmann::json report_json(const MeshOptions& o, const HexMesh& mesh, const GridMeshReport& r,
                           const std::optional<AutoCoreChoice>& choice, bool written) {
  nlohmann::json j;
  j["surface"] = o.surface;
  j["method"] = o.method;
  j["target_hexes"] = o.target;
  j["hexes"] = mesh.hexes.size();
  j["nodes"] = mesh.vertices.size();
  j["core_hexes"] = r.core_hexes;
  j["pillow_hexes"] = r.pillow_hexes;
  j["cell_size_mm"] = r.cell_size;
  j["grid"] = r.grid;
  j["cells_added_for_manifold"] = r.cells_added_for_manifold;
  j["cells_in_dropped_components"] = r.cells_in_dropped_components;
  j["grid_attempts"] = r.attempts;
  j["grid_frame"] = grid_frame_used(o, r);
  j["principal_retry"] =
      r.principal_retry
          ? nlohmann::json{{"axes_inverted", r.principal_retry->axes_inverted},
                           {"principal_inverted", tried_count(r.principal_retry->principal_inverted)},
                           {"faces_inverted", tried_count(r.principal_retry->faces_inverted)},
                           {"kept", r.principal_retry->kept},
                           {"kept_frame", r.principal_retry->kept_frame}}
          : nlohmann::json();
  j["core"] = r.swept ? "swept" : "grid";
  j["core_requested"] = o.core;
  if (choice) j["core_reason"] = choice->reason;
  j["landmarks"] = o.landmarks.empty() ? nlohmann::json() : nlohmann::json(o.landmarks);
  nlohmann::json phases = nlohmann::json::array();
  for (const PhaseQuality& p : r.optimize.phases)
    phases.push_back({{"phase", p.phase}, {"seconds", p.seconds}, {"quality", quality_to_json(p.quality)}});
  j["phases"] = phases;
  j["optimizer"] = {{"untangle_sweeps", r.optimize.untangle_sweeps},
                    {"iterations", r.optimize.iterations},
                    {"rounds", r.optimize.rounds},
                    {"energy_before", r.optimize.energy_before},
                    {"energy_after", r.optimize.energy_after}};
  j["seconds"] = {{"core", r.seconds_core},
                  {"pillow", r.seconds_pillow},
                  {"optimize", r.seconds_optimize},
                  {"fidelity", r.seconds_fidelity},
                  {"total", r.seconds_total}};
  j["fidelity"] = fidelity_to_json(r.fidelity);
  j["volume_fit"] = r.volume_fit ? volume_fit_to_json(*r.volume_fit) : nlohmann::json();
  j["inverted"] = r.optimize.inverted;
  j["output"] = written ? nlohmann::json(o.output) : nlohmann::json();
  return j;
}

// The three paths of `hexbite mesh`: the overlay grid on a SURFACE, the sheet mesher on a mandible SURFACE
// (through the quad template placed on it) and the sheet mesher on a --quad-surface.
enum class MeshPath { grid, sheets_on_surface, sheets_on_quads };

// An option given on the command line that the chosen path would ignore is refused (exit 2) rather than
// ignored, so that a user tuning it learns that it does nothing there: "<name> <value> <what>, but <why>:
// drop <name>, or <instead>". Nothing is read or meshed before.
void refuse_ignored_options(const MeshOptions& o, MeshPath path) {
  struct IgnoredOption {
    bool ignored;  // given, and the chosen path ignores it
    std::string name, value, what, why, instead;
  };
  const bool grid = path == MeshPath::grid, quads = path == MeshPath::sheets_on_quads;
  const IgnoredOption options[] = {
      {grid && o.was_given("--quad-surface"), "--quad-surface", o.quad_surface,
       "is the boundary that --method sheets keeps exactly",
       "--method grid meshes a triangulated SURFACE with an overlay grid", "use --method sheets"},
      {quads && o.was_given("surface"), "the SURFACE", o.surface,
       "is meshed by --method grid, or by --method sheets through the mandible quad template placed on it",
       "--method sheets with --quad-surface meshes that quad surface alone",
       "drop --quad-surface to mesh the SURFACE"},
      {!grid && o.was_given("--grid-frame"), "--grid-frame", o.grid_frame,
       "lays the overlay grid of --method grid", "--method sheets has no grid", "use --method grid"},
      {!grid && o.was_given("--margin"), "--margin", fmt("%g", o.margin),
       "chooses the core cells of the overlay grid of --method grid", "--method sheets has no grid",
       "use --method grid"},
      {!grid && o.was_given("--core"), "--core", o.core, "chooses the core of --method grid",
       "--method sheets has no grid", "use --method grid"},
      {grid && o.core == "swept" && o.was_given("--margin"), "--margin", fmt("%g", o.margin),
       "chooses the core cells of the overlay grid", "--core swept takes columns of the bone's side view",
       "use --core grid"},
      {grid && o.was_given("--order"), "--order", o.order,
       "orders the cycle elimination of the sheet mesher, --method sheets",
       "--method grid eliminates no sheets (it fills an overlay grid)", "use --method sheets"},
      {quads && o.was_given("--target-hexes"), "--target-hexes", std::to_string(o.target),
       "sets the size of the mesh of a SURFACE",
       "the hex count of a mesh of --quad-surface follows from its quads (the quad surface is kept exactly "
       "as the boundary)",
       "give a finer or coarser quad surface (hexbite quad from-mandible --target-quads)"},
      {quads && o.was_given("--landmarks"), "--landmarks", o.landmarks,
       "places the mandible quad template on a SURFACE (--method sheets) and names the parts too thin for "
       "the cells (--method grid)",
       "a mesh of --quad-surface places no template and has no SURFACE to compare with",
       "give them to hexbite quad from-mandible, which places the template"},
      {quads && o.was_given("--units"), "--units", o.units,
       "is the length unit of the SURFACE file (converted to mm)",
       "a --quad-surface is meshed in its own coordinates, without conversion",
       "give it to hexbite quad from-mandible, which writes the quad surface in mm"},
      {quads && o.was_given("--fit-volume"), "--fit-volume", "", "moves boundary nodes off the SURFACE",
       "a mesh of --quad-surface keeps that quad surface exactly as its boundary",
       "mesh the triangulated SURFACE"},
      {path != MeshPath::sheets_on_surface && o.was_given("--refine-at"), "--refine-at", o.refine.at,
       "refines the quad surface that --method sheets places on a mandible SURFACE",
       grid ? "--method grid places no quad surface" : "a --quad-surface is meshed as it is",
       "run --method sheets on the SURFACE"}};
  for (const IgnoredOption& g : options)
    if (g.ignored)
      throw InputError(g.name + (g.value.empty() ? "" : " " + g.value) + " " + g.what + ", but " + g.why +
                       ": drop " + g.name + ", or " + g.instead);
}

void run_mesh(const MeshOptions& o) {
  refuse_ignored_options(o, o.method == "grid"       ? MeshPath::grid
                            : o.quad_surface.empty() ? MeshPath::sheets_on_surface
                                                     : MeshPath::sheets_on_quads);
  if (o.method == "sheets" && o.quad_surface.empty() && !o.surface.empty())
    return run_mesh_sheets_surface({{o.surface, o.landmarks, o.units, 0, o.output, o.json, o.refine},
                                    o.target,
                                    o.order,
                                    o.allow_invalid,
                                    o.fit_volume});
  if (o.method == "sheets")
    return run_mesh_sheets({o.quad_surface, o.output, o.order, o.json, o.allow_invalid});
  if (o.surface.empty()) throw InputError("--method grid needs the SURFACE to mesh");
  if (o.core == "swept" && o.grid_frame == "axes")
    throw InputError(
        "--core swept sweeps the core across the dental arch, so it needs --grid-frame arch: "
        "drop --grid-frame axes, or use --core grid");
  const auto [surface, landmarks] = load_mesh_inputs(o.surface, o.units, o.landmarks);

  GridMeshOptions options;
  options.target_hexes = o.target;
  options.margin = o.margin;
  options.fit_volume = o.fit_volume;
  options.arch_frame = o.grid_frame == "arch";
  options.swept_core = o.core == "swept";
  // An explicit margin is a request for that core: no automatic choice of cores for fine cells.
  if (o.was_given("--margin")) options.thick_margin_cells = std::numeric_limits<double>::infinity();
  GridMeshReport report;
  std::optional<AutoCoreChoice> choice;
  HexMesh mesh;
  if (o.core == "auto")
    mesh = grid_mesh_auto_core(surface, options, &report, &choice.emplace());
  else
    mesh = grid_mesh(surface, options, &report);
  if (landmarks) name_unresolved_parts(*landmarks, report.fidelity.unresolved);
  const QualitySummary& final_quality = report.optimize.phases.back().quality;
  const bool valid = final_quality.inverted == 0;
  const bool write = valid || o.allow_invalid;
  if (write) write_hex_mesh(o.output, mesh);
  // The cell size search stops after 8 trials; on a thin plate, or a solid of a few cells, the count jumps
  // between cell sizes and can end far from the target (a 1 mm plate of 100 x 100 mm: 2,912 hexes for 500).
  const double ratio = double(mesh.hexes.size()) / double(o.target);
  if (write && (ratio > 2.0 || ratio < 0.5)) {
    std::ostringstream text;
    text.precision(ratio < 10 ? 2 : 3);
    text << "hexbite: warning: the mesh has " << mesh.hexes.size() << " hexes, " << ratio
         << " times --target-hexes " << o.target
         << ": no cell size tried came closer (the hex count of a thin or small solid jumps between cell "
            "sizes); another --target-hexes may come closer\n";
    std::cerr << text.str();
  }

  if (o.json)
    std::cout << json_text(report_json(o, mesh, report, choice, write)) << '\n';
  else if (!is_quiet())
    std::cout << report_text(o, mesh, report, choice);
  if (!valid) {
    if (o.allow_invalid) {
      std::cerr << "hexbite: warning: wrote " << o.output << " with "
                << hex_count_text(final_quality.inverted) << " inverted on purpose (--allow-invalid): "
                << hex_list_text(mesh, final_quality.inverted_hexes) << '\n';
      return;
    }
    throw RunError(stay_inverted_text(mesh, final_quality.inverted_hexes) +
                   "; no mesh written (--allow-invalid writes it anyway" +
                   (report.swept         ? "; the grid core, --core grid, may mesh it valid)"
                    : options.arch_frame ? "; the axis-aligned grid, --grid-frame axes, may mesh it valid)"
                                         : ")"));
  }
  if (!o.json) info("wrote " + o.output);
}

}  // namespace

void add_mesh_command(CLI::App& app) {
  auto o = std::make_shared<MeshOptions>();
  CLI::App* cmd = app.add_subcommand("mesh", "Mesh a closed triangulated solid with hexahedra");
  cmd->add_option(
      "surface", o->surface,
      "Closed surface (.stl .obj .ply .off .vtp); for --method grid, or a mandible for --method sheets");
  cmd->add_option("--quad-surface", o->quad_surface,
                  "Quad surface of a ball (.obj .vtp .vtk), for --method sheets");
  cmd->add_option(
      "--landmarks", o->landmarks,
      "Landmark file (.yaml) of the SURFACE: places the mandible quad template for --method sheets, and "
      "names the parts too thin for the cell size by their nearest landmark for --method grid");
  cmd->add_option("--order", o->order,
                  "Elimination order for --method sheets: geometric, fewest-hexes or look-ahead")
      ->capture_default_str();
  cmd->add_option(
         "--method", o->method,
         "Meshing method: grid (overlay grid + pillow layer) or sheets (cycle elimination of --quad-surface, "
         "or of the mandible quad template placed on the SURFACE)")
      ->check(CLI::IsMember({"grid", "sheets"}));
  cmd->add_option("--target-hexes", o->target, "Wanted number of hexes (8 to 5,000,000)")
      ->default_val(2500)
      ->transform(count_in_range(kMinTargetHexes, kMaxTargetHexes));
  cmd->add_option("-o,--output", o->output,
                  "Output mesh: .vtu (with per-hex quality arrays), .inp (Abaqus / CalculiX: nodes and C3D8 "
                  "elements) or .msh (Gmsh 4.1)")
      ->required()
      ->check(output_hex_mesh_file());
  cmd->add_option("--units", o->units, "Length unit of the surface and landmark files: mm, cm or m")
      ->default_val("mm");
  cmd->add_option("--margin", o->margin,
                  "Core cells of the overlay grid (--method grid) have their centre at least this many "
                  "cell sizes inside the surface (negative: at most that far outside), on every grid; the "
                  "pillow layer fills the rest (smaller keeps thinner parts in the core). Without it the "
                  "mesher chooses: -0.4, and for fine cells the better of two cores (docs/meshing.md)")
      ->check(number_in_range(-0.8, 2.0, "from -0.8 to 2"))
      ->default_val(o->margin);
  cmd->add_option("--grid-frame", o->grid_frame,
                  "Frame of the overlay grid for --method grid: axes, or arch (along the dental arch of a "
                  "whole mandible in the mandible frame; docs/meshing.md)")
      ->check(CLI::IsMember({"axes", "arch"}))
      ->capture_default_str();
  cmd->add_option("--core", o->core,
                  "Core of --method grid: grid (cells of the overlay grid), swept (a grid over the "
                  "bone's side view swept across the dental arch, one hex across the bone per column: "
                  "better shaped coarse meshes of a whole mandible; implies --grid-frame arch), or auto "
                  "(swept up to 10,000 target hexes, the grid core in --grid-frame where the surface follows "
                  "no arch or the swept mesh misses scaled Jacobian 0.3 or condition number 10, and above "
                  "10,000; docs/meshing.md)")
      ->check(CLI::IsMember({"grid", "swept", "auto"}))
      ->capture_default_str();
  cmd->add_flag("--fit-volume", o->fit_volume,
                "Move the boundary nodes off the SURFACE along their normals until the "
                "boundary quads straddle it (the mesh's volume matches the surface's; nodes end up to a "
                "quarter edge from the surface)");
  cmd->add_flag("--json", o->json, "Print one JSON object instead of the table");
  cmd->add_flag("--allow-invalid", o->allow_invalid, "Write the mesh even when hexes stay inverted");
  add_refine_options(*cmd, o->refine);
  cmd->callback([o, cmd] {
    for (const CLI::Option* option : cmd->get_options())
      if (option->count() > 0) o->given.insert(option->get_name());
    // The swept core lies along the arch: --core swept alone implies --grid-frame arch.
    if (o->core == "swept" && !o->was_given("--grid-frame")) o->grid_frame = "arch";
    run_mesh(*o);
  });
}

}  // namespace hexbite
