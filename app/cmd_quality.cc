// hexbite quality MESH.vtu [--json]: the quality table of a hex mesh, laid out like the seed paper's Table 1.
// A Gmsh .msh file is accepted as well.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>

#include "app/commands.h"
#include "mesher/grid_mesher.h"
#include "mesher/hex_mesh_io.h"
#include "mesher/hex_quality.h"
#include "postprocess/quality_json.h"

namespace hexbite {

namespace {

struct QualityOptions {
  std::string mesh;
  bool json = false;
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

std::string quality_table(const std::string& path, const QualitySummary& s) {
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
    for (std::size_t i = 0; i < shown; ++i) out << ' ' << s.inverted_hexes[i];
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

}  // namespace

void add_quality_command(CLI::App& app) {
  auto options = std::make_shared<QualityOptions>();
  CLI::App* cmd = app.add_subcommand(
      "quality",
      "Print the quality of a hex mesh (scaled Jacobian, condition number, Oddy, inverted elements)");
  cmd->add_option("mesh", options->mesh, "Hex mesh file (.vtu, or Gmsh .msh 4.1 / 2.2 ASCII)")->required();
  cmd->add_flag("--json", options->json, "Print one JSON object instead of the table");
  cmd->callback([options] {
    // Gmsh meshes are read too, so that peer meshers can be measured with exactly the same code.
    const std::string ext = std::filesystem::path(options->mesh).extension().string();
    const HexMesh mesh = (ext == ".msh" || ext == ".MSH") ? read_msh(options->mesh) : read_vtu(options->mesh);
    const QualitySummary summary = summarize_quality(mesh);
    if (options->json)
      // The volume lets benchmarks compare a mesh with its surface (and peers' meshes with ours).
      std::cout << quality_to_json(summary, hex_mesh_volume(mesh)).dump(2) << '\n';
    else
      std::cout << quality_table(options->mesh, summary);
  });
}

}  // namespace hexbite
