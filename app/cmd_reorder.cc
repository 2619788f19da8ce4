// hexbite reorder MESH.vtu -o out.vtu --method bfs|rcm [--from x,y,z | --landmarks L.yaml] [--json]
//
// Renumbers the hexes and nodes of a mesh to shrink the bandwidth and profile of the stiffness matrix:
// breadth-first from the boundary hex nearest a point (the seed paper starts at the left condyle), or reverse
// Cuthill-McKee. Prints the bandwidth and profile of the nodal adjacency before and after. The geometry is
// unchanged; the input's own cell and point arrays are carried over in the new order.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "app/carried_arrays.h"
#include "app/commands.h"
#include "app/mesh_inputs.h"
#include "app/option_checks.h"
#include "common/error.h"
#include "common/json_text.h"
#include "common/paths.h"
#include "common/progress.h"
#include "mesher/hex_mesh_io.h"
#include "mesher/hex_quality.h"
#include "mesher/hex_reorder.h"
#include "mesher/landmarks.h"

namespace hexbite {

namespace {

// The landmark the seed paper starts its breadth-first order from.
constexpr const char* kStartLandmark = "left_condyle_tmj_point";

struct ReorderOptions {
  std::string mesh;
  std::string output;
  std::string method = "bfs";
  std::string from;
  std::string landmarks;
  bool json = false;
};

Vec3 parse_point(const std::string& text) {
  Vec3 p{};
  std::istringstream in(text);
  char comma1 = 0, comma2 = 0;
  std::string rest;
  if (!(in >> p[0] >> comma1 >> p[1] >> comma2 >> p[2]) || comma1 != ',' || comma2 != ',' || (in >> rest))
    throw InputError("--from expects a point as x,y,z in mm (for example 51.8,31.5,79.6), not '" + text +
                     "'");
  return p;
}

// The arrays in the new order.
std::vector<MeshArray> permute_arrays(const std::vector<MeshArray>& arrays, const std::vector<int>& order) {
  std::vector<MeshArray> out;
  for (const MeshArray& a : arrays) out.push_back(array_tuples(a, order));
  return out;
}

void run_reorder(const ReorderOptions& o) {
  if (o.method == "rcm" && (!o.from.empty() || !o.landmarks.empty()))
    throw InputError(
        "--from and --landmarks choose where the breadth-first order starts; --method rcm picks "
        "its own start, so leave them out or use --method bfs");
  std::vector<MeshArray> cell_arrays, point_arrays;
  std::vector<std::string> not_read;
  const HexMeshInput input = load_hex_mesh_input(o.mesh, &cell_arrays, &point_arrays, &not_read);
  const HexMesh& mesh = input.mesh;

  const auto t0 = std::chrono::steady_clock::now();
  ReorderResult r;
  std::string start_text;
  nlohmann::json start_json;
  if (o.method == "bfs") {
    int start = -1;
    if (!o.from.empty() || !o.landmarks.empty()) {
      Vec3 point{};
      if (!o.from.empty()) {
        point = parse_point(o.from);
      } else {
        const Landmarks landmarks = read_landmarks(o.landmarks);
        const std::optional<Vec3> found = landmarks.find(kStartLandmark);
        if (!found) {
          std::string names;
          for (const auto& [name, p] : landmarks.points) names += (names.empty() ? "" : ", ") + name;
          throw InputError("landmark file " + o.landmarks + " has no " + kStartLandmark +
                           " (it has: " + (names.empty() ? std::string("no points") : names) +
                           "); give the start point with --from x,y,z instead");
        }
        point = *found;
      }
      start = nearest_boundary_hex(mesh, point);
      char buf[160];
      std::snprintf(buf, sizeof buf, "the boundary hex nearest (%.2f, %.2f, %.2f) mm", point[0], point[1],
                    point[2]);
      start_text = buf;
      start_json["point"] = point;
    } else {
      start = smallest_x_boundary_hex(mesh);
      start_text = "the boundary hex with the smallest x";
    }
    r = reorder_breadth_first(mesh, start);
    start_json["hex"] = start;
  } else {
    r = reorder_reverse_cuthill_mckee(mesh);
  }
  const double seconds = seconds_since(t0);
  const CellArrays cells = split_cell_arrays(mesh, cell_arrays);
  write_hex_mesh(o.output, r.mesh, permute_arrays(cells.own, r.hex_order),
                 permute_arrays(point_arrays, r.node_order));
  warn_arrays_not_carried(o.mesh, o.output, "reorder", cells, point_arrays, true, not_read);
  input.warn_physical_groups_not_carried(o.mesh, o.output, "reorder");

  if (o.json) {
    nlohmann::json j;
    j["mesh"] = o.mesh;
    j["output"] = o.output;
    j["method"] = o.method;
    j["hexes"] = mesh.hexes.size();
    j["nodes"] = mesh.vertices.size();
    j["start"] = o.method == "bfs" ? start_json : nlohmann::json();
    j["before"] = {{"bandwidth", r.before.bandwidth}, {"profile", r.before.profile}};
    j["after"] = {{"bandwidth", r.after.bandwidth}, {"profile", r.after.profile}};
    j["seconds"] = seconds;
    std::cout << json_text(j) << '\n';
    return;
  }
  if (is_quiet()) return;
  std::ostringstream out;
  out << "Reordered " << o.mesh << " (" << mesh.hexes.size() << " hexes, " << mesh.vertices.size()
      << " nodes) by "
      << (o.method == "bfs" ? "breadth-first order from " + start_text + " (input hex " +
                                  std::to_string(r.start_hex) + input.element_suffix(r.start_hex) + ")"
                            : std::string("reverse Cuthill-McKee"))
      << "\n\n";
  char line[128];
  std::snprintf(line, sizeof line, "%-34s %14s %14s\n", "nodal adjacency (nodes per hex)", "before", "after");
  out << line;
  std::snprintf(line, sizeof line, "%-34s %14lld %14lld\n", "bandwidth", r.before.bandwidth,
                r.after.bandwidth);
  out << line;
  std::snprintf(line, sizeof line, "%-34s %14lld %14lld\n", "profile", r.before.profile, r.after.profile);
  out << line;
  out << "(in nodes; with 3 interleaved displacement components the matrix bandwidth is 3 b + 2)\n";
  std::snprintf(line, sizeof line, "time: %.3f s\n", seconds);
  out << line;
  std::cout << out.str();
  info("wrote " + o.output);
}

}  // namespace

void add_reorder_command(CLI::App& app) {
  auto o = std::make_shared<ReorderOptions>();
  CLI::App* cmd = app.add_subcommand(
      "reorder",
      "Renumber hexes and nodes (breadth-first or reverse Cuthill-McKee) to shrink the matrix bandwidth");
  cmd->add_option("MESH", o->mesh, "Hex mesh (.vtu, or Gmsh .msh 4.1 / 2.2 ASCII)")->required();
  cmd->add_option(
         "-o,--output", o->output,
         "Reordered mesh: .vtu (the input's arrays carried over), .inp (Abaqus / CalculiX) or .msh (Gmsh)")
      ->required()
      ->check(output_hex_mesh_file());
  cmd->add_option(
         "--method", o->method,
         "bfs: breadth-first from a boundary hex (the seed paper's order); rcm: reverse Cuthill-McKee")
      ->check(CLI::IsMember({"bfs", "rcm"}))
      ->default_val("bfs");
  auto* from = cmd->add_option(
      "--from", o->from, "Start the breadth-first order at the boundary hex nearest this point, x,y,z in mm");
  auto* landmarks =
      cmd->add_option("--landmarks", o->landmarks,
                      std::string("Landmark file (YAML, mm); the order starts at ") + kStartLandmark);
  from->excludes(landmarks);
  cmd->add_flag("--json", o->json, "Print one JSON object instead of the table");
  cmd->callback([o] { run_reorder(*o); });
}

}  // namespace hexbite
