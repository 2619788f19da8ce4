// hexbite quad check Q.obj [--json]
// hexbite quad from-mandible SURFACE [--landmarks L.yaml] [--target-quads N] -o Q.obj [--json]
//   [--refine-at X,Y,Z|LANDMARK [--refine-radius MM] [--refine-levels K]]
// hexbite quad from-mesh MESH.vtu -o Q.obj [--json]: the boundary quad surface of a hex mesh
//
// Reports what the sheet mesher (hexbite mesh --method sheets) needs to know about a quad surface: closed,
// manifold, genus, even quad count, simple, planar and 3-connected graph, the chords with their lengths and
// every self-intersecting chord with the quads it crosses twice; then, geometrically, quads that cross each
// other (mesher/quad_surface_crossings.h) and quad corners on one line or reflex. The report is printed in
// full even when the surface is unusable; then every problem also goes to standard error and the exit code
// is 2.
#include <CLI/CLI.hpp>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/commands.h"
#include "app/mesh_inputs.h"
#include "app/mesh_sheets_surface.h"
#include "app/option_checks.h"
#include "common/error.h"
#include "common/json_text.h"
#include "common/progress.h"
#include "mesher/hex_boundary.h"
#include "mesher/hex_mesh_io.h"
#include "mesher/quad_check.h"
#include "mesher/quad_surface_crossings.h"
#include "mesher/quad_surface_io.h"

namespace hexbite {

namespace {

struct QuadCheckOptions {
  std::string file;
  bool json = false;
};

// The geometric test that comes after the combinatorial ones: quads that cross each other. It needs a
// closed, manifold, consistently oriented surface without degenerate quads; `computed` is false otherwise.
struct Crossings {
  bool computed = false;
  std::vector<std::array<int, 2>> pairs;
};

nlohmann::json report_json(const QuadSurfaceReport& r, const Crossings& crossings) {
  nlohmann::json j;
  j["file"] = r.file;
  j["quads"] = r.quads;
  j["vertices"] = r.vertices;
  j["unused_vertices"] = r.unused_vertices;
  j["edges"] = r.edges;
  j["components"] = r.components;
  j["closed"] = r.closed;
  j["open_edges"] = r.open_edges;
  j["manifold"] = r.manifold;
  j["non_manifold_edges"] = r.non_manifold_edges;
  j["non_manifold_vertices"] = r.non_manifold_vertices;
  j["consistently_oriented"] = r.consistently_oriented;
  j["euler_characteristic"] = r.euler_characteristic;
  j["genus"] = r.genus >= 0 ? nlohmann::json(r.genus) : nlohmann::json();
  j["ball"] = r.ball;
  j["even"] = r.even;
  j["simple"] = r.simple;
  j["degenerate_quads"] = r.degenerate_quads;
  j["quad_pairs_sharing_edges"] = r.quad_pairs_sharing_edges;
  j["duplicate_quads"] = r.duplicate_quads;
  j["planar"] = r.planar;
  j["three_connected"] = r.three_connected;
  if (r.chords_computed) {
    nlohmann::json chords = nlohmann::json::array();
    for (const Chord& c : r.chords)
      chords.push_back(
          {{"length", c.length()}, {"simple", c.simple()}, {"repeated_quads", c.repeated_quads}});
    j["chords"] = chords;
    j["self_intersecting_chords"] = r.self_intersecting_chords;
  } else {
    j["chords"] = nullptr;  // undefined on open or non-manifold surfaces
    j["self_intersecting_chords"] = nullptr;
  }
  j["crossing_quads"] = crossings.computed ? nlohmann::json(crossings.pairs) : nlohmann::json();
  j["problems"] = r.problems;
  j["usable"] = r.usable();
  return j;
}

std::string yes_no(bool b) {
  return b ? "yes" : "no";
}

std::string report_text(const QuadSurfaceReport& r, const Crossings& crossings) {
  std::ostringstream s;
  auto row = [&](const std::string& key, const std::string& value) {
    s << "  " << key << std::string(key.size() < 22 ? 22 - key.size() : 1, ' ') << value << '\n';
  };
  s << "quad surface " << r.file << '\n';
  row("quads", std::to_string(r.quads) + (r.even ? " (even)" : " (odd)"));
  row("vertices", std::to_string(r.vertices) +
                      (r.unused_vertices ? " (+" + std::to_string(r.unused_vertices) + " unused)" : ""));
  row("edges", std::to_string(r.edges));
  row("components", std::to_string(r.components));
  row("closed", yes_no(r.closed) + " (" + std::to_string(r.open_edges) + " open edges)");
  row("manifold", yes_no(r.manifold) + " (" + std::to_string(r.non_manifold_edges) +
                      " edges in more than two quads, " + std::to_string(r.non_manifold_vertices) +
                      " non-manifold vertices)");
  row("oriented", yes_no(r.consistently_oriented));
  row("Euler characteristic",
      std::to_string(r.euler_characteristic) +
          (r.genus >= 0 ? "  (genus " + std::to_string(r.genus) + ")" : "  (genus undefined)"));
  row("ball", yes_no(r.ball));
  row("simple graph", yes_no(r.simple));
  row("planar graph", yes_no(r.planar));
  row("3-connected", yes_no(r.three_connected));
  row("crosses itself", !crossings.computed ? std::string("not tested (needs a closed, oriented manifold)")
                        : crossings.pairs.empty()
                            ? std::string("no")
                            : "yes (" + std::to_string(crossings.pairs.size()) +
                                  (crossings.pairs.size() == 1 ? " pair" : " pairs") + " of quads)");
  if (r.chords_computed) {
    // Lengths as a histogram keeps the line short for surfaces with hundreds of chords.
    std::map<int, int> lengths;
    for (const Chord& c : r.chords) ++lengths[c.length()];
    std::string text;
    for (const auto& [length, n] : lengths)
      text += (text.empty() ? "" : ", ") + std::to_string(n) + " x " + std::to_string(length);
    row("chords", std::to_string(r.chords.size()) + " (count x length: " + text + ")");
    row("self-intersecting", std::to_string(r.self_intersecting_chords.size()) + " chords");
    for (int c : r.self_intersecting_chords) {
      std::string quads;
      for (int q : r.chords[c].repeated_quads) quads += " " + std::to_string(q);
      s << "    chord " << c << " (length " << r.chords[c].length() << ") crosses twice:" << quads << '\n';
    }
  } else {
    row("chords", "undefined (the surface is open, non-manifold or has degenerate quads)");
  }
  s << "problems"
    << (r.problems.empty() ? ": none\n" : " (indices 0-based: the file's n-th vertex or face is n - 1):\n");
  for (const auto& line : r.problems) s << "  - " << line << '\n';
  s << (r.usable() ? "usable for --method sheets: yes" : "usable for --method sheets: no");
  return s.str();
}

void run_quad_check(const QuadCheckOptions& o) {
  const QuadSurface surface = load_quad_surface_input(o.file);
  QuadSurfaceReport report = check_quad_surface(surface, o.file);
  // "usable for --method sheets" means with the embedding, which keeps the boundary as it is: a quad
  // corner on one line with its neighbours, or a reflex one, makes every mesh invalid (it was "usable: yes",
  // and the mesh command then refused the surface or left hexes inverted).
  if (report.closed && report.manifold)
    if (const std::string corner = non_convex_corners_problem(surface); !corner.empty())
      report.problems.push_back(corner);
  // A surface folded over itself passes every combinatorial test, and the mesh command then left hexes
  // inverted.
  Crossings crossings;
  if (report.closed && report.manifold && report.consistently_oriented && report.degenerate_quads == 0) {
    crossings.computed = true;
    crossings.pairs = crossing_quads(surface);
    if (const std::string crossing = crossing_quads_problem(surface, crossings.pairs); !crossing.empty())
      report.problems.push_back(crossing + ": " + kUntangleQuadSurface);
  }
  if (o.json)
    std::cout << json_text(report_json(report, crossings)) << std::endl;
  else
    info(report_text(report, crossings));
  if (!report.usable()) {
    for (const auto& p : report.problems) std::cerr << "hexbite: error: '" << o.file << "': " << p << '\n';
    throw InputError("'" + o.file + "' cannot bound a hex mesh by cycle elimination (" +
                     std::to_string(report.problems.size()) +
                     (report.problems.size() == 1 ? " problem" : " problems") +
                     " above; their indices are 0-based: the file's n-th vertex or face is n - 1)");
  }
}

struct QuadFromMeshOptions {
  std::string mesh;
  std::string output;
  bool json = false;
};

// The boundary quads of a hex mesh (outward, on the mesh's own boundary vertices), e.g. to mesh the same
// boundary again by cycle elimination (hexbite mesh --method sheets --quad-surface), which keeps it exactly.
void run_quad_from_mesh(const QuadFromMeshOptions& o) {
  const HexMeshInput input = load_hex_mesh_input(o.mesh);
  const HexMesh& mesh = input.mesh;
  // An inverted hex's faces point inward, so its boundary quads would not be the outward surface claimed
  // here (a mirrored mesh gives a wholly inward one): refused as bad input, as hexbite refine does.
  require_no_inverted_hexes(input, o.mesh,
                            "whose faces point inward, so its boundary is not an outward quad surface");
  const HexBoundary boundary = extract_boundary(mesh);
  write_quad_obj(o.output, boundary.surface);
  if (o.json) {
    std::cout << json_text(nlohmann::json{{"mesh", o.mesh},
                                          {"hexes", mesh.hexes.size()},
                                          {"quads", boundary.surface.quads.size()},
                                          {"vertices", boundary.surface.vertices.size()},
                                          {"output", o.output}})
              << std::endl;
    return;
  }
  info("Boundary of " + o.mesh + " (" + std::to_string(mesh.hexes.size()) +
       (mesh.hexes.size() == 1 ? " hex): " : " hexes): ") + std::to_string(boundary.surface.quads.size()) +
       " quads, " + std::to_string(boundary.surface.vertices.size()) + " vertices, outward\nwrote " +
       o.output);
}

}  // namespace

void add_quad_commands(CLI::App& app) {
  CLI::App* quad = app.add_subcommand("quad", "Quad surfaces for the sheet mesher");
  quad->require_subcommand(1);
  auto options = std::make_shared<QuadCheckOptions>();
  CLI::App* cmd = quad->add_subcommand(
      "check", "Report on a quad surface: closed, manifold, genus, even, simple, 3-connected, chords");
  cmd->add_option("FILE", options->file, "Quad surface: .obj (quad faces), .vtp or .vtk polydata")
      ->required();
  cmd->add_flag("--json", options->json, "Print the report as one JSON object on standard output");
  cmd->callback([options] { run_quad_check(*options); });

  auto from = std::make_shared<MandibleQuadCommandOptions>();
  CLI::App* fm = quad->add_subcommand(
      "from-mandible",
      "Quad surface of a triangulated mandible: macro-element template placed by landmarks, refined keeping "
      "every chord simple, nodes on the surface");
  fm->add_option("SURFACE", from->surface, "Closed mandible surface (.stl .obj .ply .off .vtp)")->required();
  fm->add_option(
      "--landmarks", from->landmarks,
      "Landmark file (.yaml) in the surface's frame; without it extreme points place the template");
  fm->add_option("--target-quads", from->target_quads, "Wanted number of quads (24 to 200,000)")
      ->default_val(1300)
      ->transform(count_in_range(24, 200000));
  fm->add_option("--units", from->units, "Length unit of the surface and landmark files: mm, cm or m")
      ->default_val("mm");
  fm->add_option("-o,--output", from->output, "Output quad surface (.obj)")
      ->required()
      ->check(output_file({".obj"}));
  fm->add_flag("--json", from->json, "Print the report as one JSON object on standard output");
  add_refine_options(*fm, from->refine);
  fm->callback([from] { run_quad_from_mandible(*from); });

  auto from_mesh = std::make_shared<QuadFromMeshOptions>();
  CLI::App* fh = quad->add_subcommand(
      "from-mesh", "The boundary quad surface of a hex mesh (the quads of one hex each, outward)");
  fh->add_option("MESH", from_mesh->mesh, "Hex mesh (.vtu, or Gmsh .msh 4.1 / 2.2 ASCII)")->required();
  fh->add_option("-o,--output", from_mesh->output, "Output quad surface (.obj)")
      ->required()
      ->check(output_file({".obj"}));
  fh->add_flag("--json", from_mesh->json, "Print the report as one JSON object on standard output");
  fh->callback([from_mesh] { run_quad_from_mesh(*from_mesh); });
}

}  // namespace hexbite
