// hexbite quality MESH.vtu [--json] [--worst N]: the quality table of a hex mesh, laid out like the seed
// paper's Table 1, and optionally its N worst hexes with where they are. A Gmsh .msh file is accepted as
// well.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <functional>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "app/commands.h"
#include "app/mesh_inputs.h"
#include "app/option_checks.h"
#include "common/json_text.h"
#include "common/progress.h"
#include "mesher/grid_mesher.h"
#include "mesher/hex_mesh_io.h"
#include "mesher/hex_quality.h"
#include "mesher/hex_quality_worst.h"
#include "postprocess/quality_json.h"

namespace hexbite {

namespace {

struct QualityOptions {
  std::string mesh;
  bool json = false;
  long worst = 0;
};

// Fixed-point for the usual range; scientific once a value would no longer fit the column.
std::string cell(double v) {
  char buf[32];
  if (std::isnan(v))
    std::snprintf(buf, sizeof buf, "%12s", "n/a");
  else if (std::fabs(v) < 1e6)
    std::snprintf(buf, sizeof buf, "%12.4f", v);
  else
    std::snprintf(buf, sizeof buf, "%12.4e", v);
  return buf;
}

std::string row(const char* label, const MeasureStats& s) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%-38s", label);
  return buf + cell(s.min) + cell(s.mean) + cell(s.max) + "\n";
}

// "3: 12  4: 40  5: 100": only the degrees that occur.
std::string degree_line(const std::vector<int>& counts) {
  std::ostringstream out;
  bool first = true;
  for (std::size_t d = 0; d < counts.size(); ++d) {
    if (counts[d] == 0) continue;
    out << (first ? "" : "  ") << d << ": " << counts[d];
    first = false;
  }
  return first ? std::string("none") : out.str();
}

// `label(h)`, when given, follows hex h's number (the Gmsh element tag of a .msh input's hex).
std::string quality_table(const std::string& path, const QualitySummary& s,
                          const std::function<std::string(int)>& label) {
  std::ostringstream out;
  out << "Quality of " << path << ": " << s.hexes << " hexes, " << s.nodes << " nodes\n\n";
  char header[128];
  std::snprintf(header, sizeof header, "%-38s%12s%12s%12s\n", "quality measure", "min", "average", "max");
  out << header;
  out << row("scaled Jacobian", s.scaled_jacobian);
  out << row("condition number (cube = 3)", s.condition);
  out << row("condition number (Verdict, cube = 1)", s.condition_verdict);
  out << row("Oddy", s.oddy);
  out << "\ninverted elements: " << s.inverted << '\n';
  if (s.inverted > 0) {
    out << "  condition number and Oddy cover the " << s.hexes - s.inverted
        << " hexes that are not inverted\n";
    out << "  inverted hexes (0-based):";
    const std::size_t shown = std::min<std::size_t>(s.inverted_hexes.size(), 20);
    for (std::size_t i = 0; i < shown; ++i)
      out << ' ' << s.inverted_hexes[i] << (label ? label(s.inverted_hexes[i]) : std::string());
    if (shown < s.inverted_hexes.size()) out << " ... (" << s.inverted_hexes.size() - shown << " more)";
    out << '\n';
  }
  const NodeDegrees& d = s.node_degree;
  out << "node degree, " << d.interior_nodes << " interior nodes: maximum " << d.max_edges << " edges, "
      << d.max_hexes << " hexes\n";
  out << "  edges per node: " << degree_line(d.edges) << '\n';
  out << "  hexes per node: " << degree_line(d.hexes) << '\n';
  return out.str();
}

// The worst hexes as a small table after the report, with the Gmsh element tags of a .msh input's hexes
// (`element_tags`; none for a .vtu).
std::string worst_table(const std::vector<WorstHex>& worst, const std::vector<long>& element_tags) {
  std::ostringstream out;
  out << "\nworst " << worst.size() << (worst.size() == 1 ? " hex" : " hexes")
      << " (lowest scaled Jacobian first; ties: larger condition number first):\n";
  char line[192];
  // A .msh input's hexes get a column with their Gmsh element tags after the 0-based index.
  std::snprintf(line, sizeof line, "%10s%s%18s%18s   %s\n", "hex",
                element_tags.empty() ? "" : "    Gmsh element", "scaled Jacobian", "condition",
                "centroid (mm)");
  out << line;
  for (const WorstHex& w : worst) {
    char tag[32] = "";
    if (!element_tags.empty()) std::snprintf(tag, sizeof tag, "%16ld", element_tags[w.hex]);
    std::snprintf(line, sizeof line, "%10d%s%18s%18s   (%.2f, %.2f, %.2f)\n", w.hex, tag,
                  cell(w.scaled_jacobian).c_str(), cell(w.condition).c_str(), w.centroid[0], w.centroid[1],
                  w.centroid[2]);
    out << line;
  }
  out << "(hex: 0-based index; condition number k = |A|_F |A^-1|_F, cube = 3, inf for an inverted hex)\n";
  return out.str();
}

nlohmann::json worst_json(const std::vector<WorstHex>& worst, const std::vector<long>& element_tags) {
  nlohmann::json list = nlohmann::json::array();
  for (const WorstHex& w : worst) {
    list.push_back({{"hex", w.hex},
                    {"scaled_jacobian", w.scaled_jacobian},
                    {"condition", w.condition},
                    {"centroid", {w.centroid[0], w.centroid[1], w.centroid[2]}}});
    if (!element_tags.empty()) list.back()["gmsh_element"] = element_tags[w.hex];
  }
  return list;
}

}  // namespace

void add_quality_command(CLI::App& app) {
  auto options = std::make_shared<QualityOptions>();
  CLI::App* cmd = app.add_subcommand(
      "quality",
      "Print the quality of a hex mesh (scaled Jacobian, condition number, Oddy, inverted elements)");
  cmd->add_option("MESH", options->mesh, "Hex mesh file (.vtu, or Gmsh .msh 4.1 / 2.2 ASCII)")->required();
  cmd->add_flag("--json", options->json, "Print one JSON object instead of the table");
  CLI::Option* worst_option =
      cmd->add_option(
             "--worst", options->worst,
             "Also list the N hexes of lowest scaled Jacobian (ties: larger condition number first) with "
             "their index, condition number and centroid (JSON key \"worst\")")
          ->transform(count_in_range(0, 2147483647))
          ->default_val(0);
  cmd->callback([options, worst_option] {
    const bool list_worst = worst_option->count() > 0;
    // Gmsh meshes are read too, so that peer meshers can be measured with exactly the same code.
    const HexMeshInput input = load_hex_mesh_input(options->mesh);
    const HexMesh& mesh = input.mesh;
    const HexQualityField field = compute_hex_quality(mesh);
    const QualitySummary summary = summarize_quality(mesh, field);
    const std::vector<WorstHex> worst = worst_hexes(mesh, field, static_cast<std::size_t>(options->worst));
    if (options->json) {
      // The volume lets benchmarks compare a mesh with its surface (and peers' meshes with ours).
      nlohmann::json j = quality_to_json(summary, hex_mesh_volume(mesh));
      if (list_worst) j["worst"] = worst_json(worst, input.gmsh.elements);
      std::cout << json_text(j) << '\n';
    } else if (!is_quiet()) {  // --quiet: like every other report, only the exit code tells
      std::cout << quality_table(options->mesh, summary, input.hex_label());
      if (!worst.empty()) std::cout << worst_table(worst, input.gmsh.elements);
    }
  });
}

}  // namespace hexbite
