// hexbite surface check FILE [--json] [--units mm|cm|m] [-o REPAIRED]
//
// Reads a surface, applies the safe repairs and reports what check_surface() found, as text for a
// person or as one JSON object for scripts. A surface that cannot bound a solid is bad input: every
// problem goes to standard error and the exit code is 2; the repaired surface is written only when
// the surface is usable, so a failed check never leaves an output file behind.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/commands.h"
#include "app/option_checks.h"
#include "common/error.h"
#include "common/json_text.h"
#include "common/progress.h"
#include "mesher/surface_check.h"
#include "mesher/surface_io.h"
#include "mesher/units.h"

namespace hexbite {

namespace {

struct CheckOptions {
  std::string file;
  std::string units = "mm";
  std::string output;
  bool json = false;
};

nlohmann::json vec_json(const Vec3& v) {
  return nlohmann::json::array({v[0], v[1], v[2]});
}

nlohmann::json report_json(const SurfaceReport& r) {
  nlohmann::json j;
  j["file"] = r.file;
  j["triangles"] = r.triangles;
  j["vertices"] = r.vertices;
  j["components"] = r.components;
  j["closed"] = r.closed;
  j["open_edges"] = r.open_edges;
  j["manifold"] = r.manifold;
  j["non_manifold_edges"] = r.non_manifold_edges;
  j["non_manifold_vertices"] = r.non_manifold_vertices;
  j["consistently_oriented"] = r.consistently_oriented;
  j["inconsistent_edges"] = r.inconsistent_edges;
  j["outward"] = r.outward;
  j["self_intersections"] = r.self_intersections;
  j["degenerate_triangles"] = r.degenerate_triangles;
  j["euler_characteristic"] = r.euler_characteristic;
  // Undefined values are null rather than a number that could be mistaken for a measurement.
  j["genus"] = r.genus >= 0 ? nlohmann::json(r.genus) : nlohmann::json();
  j["bbox"] = {{"min", vec_json(r.bbox_min)}, {"max", vec_json(r.bbox_max)}};
  j["volume_mm3"] = r.volume_defined() ? nlohmann::json(r.volume_mm3) : nlohmann::json();
  j["min_angle_deg"] = r.min_angle_deg;
  j["min_angle_histogram"] = r.min_angle_histogram;
  j["min_angle_bin_deg"] = 5;
  j["repairs"] = r.repairs;
  j["problems"] = r.problems;
  j["usable"] = r.usable();
  return j;
}

std::string fixed(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

std::string yes_no(bool b) {
  return b ? "yes" : "no";
}

std::string report_text(const SurfaceReport& r) {
  std::ostringstream s;
  auto row = [&](const std::string& key, const std::string& value) {
    s << "  " << key << std::string(key.size() < 22 ? 22 - key.size() : 1, ' ') << value << '\n';
  };
  s << "surface " << r.file << '\n';
  row("triangles", std::to_string(r.triangles));
  row("vertices", std::to_string(r.vertices));
  row("components", std::to_string(r.components));
  row("closed", yes_no(r.closed) + " (" + std::to_string(r.open_edges) + " open edges)");
  row("manifold", yes_no(r.manifold) + " (" + std::to_string(r.non_manifold_edges) + " non-manifold edges, " +
                      std::to_string(r.non_manifold_vertices) + " non-manifold vertices)");
  row("orientation",
      std::string(r.consistently_oriented ? "consistent" : "inconsistent") +
          (r.consistently_oriented ? "" : " (" + std::to_string(r.inconsistent_edges) + " edges)") +
          (r.outward ? ", outward" : ""));
  row("self-intersections", std::to_string(r.self_intersections) + " pairs of triangles");
  row("degenerate triangles", std::to_string(r.degenerate_triangles));
  row("Euler characteristic",
      std::to_string(r.euler_characteristic) +
          (r.genus >= 0 ? "  (genus " + std::to_string(r.genus) + ")" : "  (genus undefined)"));
  const Vec3 size{r.bbox_max[0] - r.bbox_min[0], r.bbox_max[1] - r.bbox_min[1],
                  r.bbox_max[2] - r.bbox_min[2]};
  row("bounding box", "(" + fixed(r.bbox_min[0], 2) + ", " + fixed(r.bbox_min[1], 2) + ", " +
                          fixed(r.bbox_min[2], 2) + ") to (" + fixed(r.bbox_max[0], 2) + ", " +
                          fixed(r.bbox_max[1], 2) + ", " + fixed(r.bbox_max[2], 2) + ") mm");
  row("size", fixed(size[0], 2) + " x " + fixed(size[1], 2) + " x " + fixed(size[2], 2) + " mm");
  if (r.volume_defined())
    row("enclosed volume", fixed(r.volume_mm3, 1) + " mm^3 (" + fixed(r.volume_mm3 / 1000.0, 3) + " cm^3)");
  else if (r.closed && r.genus >= 0)
    row("enclosed volume", "undefined (the components are oriented inconsistently with each other)");
  else
    row("enclosed volume", "undefined (not a closed, consistently oriented manifold)");
  row("minimum angle", fixed(r.min_angle_deg, 2) + " deg");
  s << "  triangles by minimum angle:\n";
  std::size_t largest = 1;
  for (std::size_t n : r.min_angle_histogram) largest = std::max(largest, n);
  for (std::size_t b = 0; b < r.min_angle_histogram.size(); ++b) {
    const std::size_t n = r.min_angle_histogram[b];
    char label[32];
    std::snprintf(label, sizeof label, "    %2zu-%2zu deg %9zu  ", 5 * b, 5 * b + 5, n);
    s << label << std::string((40 * n + largest - 1) / largest, '#') << '\n';
  }
  s << "repairs:" << (r.repairs.empty() ? " none\n" : "\n");
  for (const auto& line : r.repairs) s << "  - " << line << '\n';
  s << "problems:" << (r.problems.empty() ? " none\n" : "\n");
  for (const auto& line : r.problems) s << "  - " << line << '\n';
  s << (r.usable() ? "usable: yes" : "usable: no, the surface cannot bound a solid");
  return s.str();
}

void run_check(const CheckOptions& o) {
  // The unit first: a typo there should not wait for a large file to be read.
  const double scale = unit_to_mm(o.units);
  TriSurface surface;
  SurfaceReport report;
  {
    Progress progress("surface check");
    surface = read_surface(o.file, scale);
    progress.update(0.3, "read");
    report = check_surface(surface, o.file);
    progress.finish();
  }
  // Write first so that the report can say where the repaired surface went; never when unusable.
  const bool write = report.usable() && !o.output.empty();
  if (write) write_surface(o.output, surface);
  if (o.json) {
    nlohmann::json j = report_json(report);
    j["output"] = write ? nlohmann::json(o.output) : nlohmann::json();
    std::cout << json_text(j) << std::endl;
  } else {
    info(report_text(report) + (write ? "\nwrote the repaired surface to " + o.output : ""));
  }

  // Not a problem of the surface, but the likeliest way to get every later number wrong by 1000.
  const std::string size_warning = implausible_size_warning(
      std::max({report.bbox_max[0] - report.bbox_min[0], report.bbox_max[1] - report.bbox_min[1],
                report.bbox_max[2] - report.bbox_min[2]}),
      o.units, "give --units <unit>");
  if (!size_warning.empty()) std::cerr << "hexbite: warning: '" << o.file << "': " << size_warning << '\n';

  if (!report.usable()) {
    for (const auto& p : report.problems) std::cerr << "hexbite: error: '" << o.file << "': " << p << '\n';
    throw InputError("'" + o.file + "' cannot bound a solid (" + std::to_string(report.problems.size()) +
                     (report.problems.size() == 1 ? " problem" : " problems") + " above)" +
                     (o.output.empty() ? "" : "; '" + o.output + "' was not written"));
  }
}

}  // namespace

void add_surface_check_command(CLI::App& surface) {
  auto options = std::make_shared<CheckOptions>();
  CLI::App* cmd = surface.add_subcommand(
      "check",
      "Report on a triangle surface (closed, manifold, oriented, genus, volume, angles), apply safe repairs");
  cmd->add_option("FILE", options->file, "Surface file: .stl (ASCII or binary), .obj, .ply, .off or .vtp")
      ->required();
  cmd->add_flag("--json", options->json, "Print the report as one JSON object on standard output");
  cmd->add_option("--units", options->units,
                  "Length unit of the file's coordinates: mm, cm or m (reports are in mm)")
      ->capture_default_str();
  cmd->add_option("-o,--output", options->output,
                  "Write the repaired surface here (format from the extension), only when it is usable")
      ->check(output_surface_file());
  cmd->callback([options] { run_check(*options); });
}

}  // namespace hexbite
