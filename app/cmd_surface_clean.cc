// hexbite surface clean IN -o OUT [--min-angle 5] [--target-triangles N] [--max-deviation D]
//                               [--units mm|cm|m] [--json]
//
// Reads and checks a closed surface, removes its small-angle triangles (and reduces it to a target
// size when asked) within a Hausdorff bound, writes the result in mm and reports what was done, as
// text for a person or as one JSON object for scripts. Options are validated before the input is
// read, and a failed run never leaves an output file behind.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/commands.h"
#include "app/mesh_inputs.h"
#include "app/option_checks.h"
#include "common/error.h"
#include "common/json_text.h"
#include "common/progress.h"
#include "mesher/surface_clean.h"
#include "mesher/surface_io.h"

namespace hexbite {

namespace {

struct CleanCommandOptions {
  std::string input;
  std::string output;
  std::string units = "mm";
  CleanOptions clean;
  bool json = false;
};

nlohmann::json report_json(const CleanReport& r) {
  nlohmann::json j;
  j["triangles_before"] = r.triangles_before;
  j["triangles_after"] = r.triangles_after;
  j["vertices_before"] = r.vertices_before;
  j["vertices_after"] = r.vertices_after;
  j["min_angle_before_deg"] = r.min_angle_before_deg;
  j["min_angle_after_deg"] = r.min_angle_after_deg;
  j["bad_before"] = r.bad_before;
  j["bad_after"] = r.bad_after;
  j["collapses"] = r.collapses;
  j["flips"] = r.flips;
  j["hausdorff_mm"] = r.hausdorff_mm;
  j["max_deviation_mm"] = r.max_deviation_mm;
  j["volume_before_mm3"] = r.volume_before_mm3;
  j["volume_after_mm3"] = r.volume_after_mm3;
  // A target of 0 means none was asked for; null says so without looking like a count.
  j["target_triangles"] = r.target_triangles > 0 ? nlohmann::json(r.target_triangles) : nlohmann::json();
  j["target_reached"] = r.target_reached;
  j["target_note"] = r.target_note;
  j["seconds"] = r.seconds;
  j["unfixed"] = nlohmann::json::array();
  for (const UnfixedTriangle& u : r.unfixed_triangles)
    j["unfixed"].push_back({{"triangle", u.index},
                            {"min_angle_deg", u.min_angle_deg},
                            {"centroid", {u.centroid[0], u.centroid[1], u.centroid[2]}}});
  return j;
}

std::string fixed(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

std::string report_text(const CleanReport& r, double min_angle_deg, const std::string& output) {
  std::ostringstream s;
  auto row = [&](const std::string& key, const std::string& value) {
    s << "  " << key << std::string(key.size() < 22 ? 22 - key.size() : 1, ' ') << value << '\n';
  };
  s << "surface clean -> " << output << '\n';
  row("triangles", std::to_string(r.triangles_before) + " -> " + std::to_string(r.triangles_after));
  row("vertices", std::to_string(r.vertices_before) + " -> " + std::to_string(r.vertices_after));
  row("minimum angle", fixed(r.min_angle_before_deg, 2) + " -> " + fixed(r.min_angle_after_deg, 2) + " deg");
  row("below " + fixed(min_angle_deg, 1) + " deg",
      std::to_string(r.bad_before) + " -> " + std::to_string(r.bad_after) + " triangles");
  row("operations",
      std::to_string(r.collapses) + " edge contractions, " + std::to_string(r.flips) + " flips");
  row("Hausdorff distance", fixed(r.hausdorff_mm, 4) + " mm (bound " + fixed(r.max_deviation_mm, 4) + " mm)");
  const double change =
      r.volume_before_mm3 != 0 ? 100.0 * (r.volume_after_mm3 / r.volume_before_mm3 - 1.0) : 0.0;
  row("enclosed volume", fixed(r.volume_before_mm3, 1) + " -> " + fixed(r.volume_after_mm3, 1) + " mm^3 (" +
                             (change >= 0 ? "+" : "") + fixed(change, 3) + "%)");
  if (r.target_triangles > 0)
    row("target", std::to_string(r.target_triangles) + " triangles, " +
                      (r.target_reached ? std::string("reached") : "not reached: " + r.target_note));
  row("time", fixed(r.seconds, 2) + " s");
  s << "unfixed:" << (r.unfixed.empty() ? " none" : "");
  for (const auto& line : r.unfixed) s << "\n  - " << line;
  return s.str();
}

void run_clean(const CleanCommandOptions& o) {
  // Options first: a typo there should not wait for a large file to be read.
  validate_clean_options(o.clean);
  const TriSurface surface = load_surface_input(o.input, o.units);
  CleanReport report;
  const TriSurface cleaned = clean_surface(surface, o.clean, &report);
  write_surface(o.output, cleaned);
  if (o.json)
    std::cout << json_text(report_json(report)) << std::endl;
  else
    info(report_text(report, o.clean.min_angle_deg, o.output));
}

}  // namespace

void add_surface_clean_command(CLI::App& surface) {
  auto options = std::make_shared<CleanCommandOptions>();
  CLI::App* cmd = surface.add_subcommand(
      "clean",
      "Remove small-angle triangles by edge contractions and flips (and reduce the size), within a Hausdorff "
      "bound");
  cmd->add_option("IN", options->input, "Closed surface: .stl, .obj, .ply, .off or .vtp")->required();
  cmd->add_option("-o,--output", options->output, "Cleaned surface, in mm (format from the extension)")
      ->required()
      ->check(output_surface_file());
  // Ranges checked while parsing, like every real-valued option: CLI11 alone says "Could not convert:
  // --min-angle = abc" (no range), and the later check wrote the value as "45.000000".
  cmd->add_option("--min-angle", options->clean.min_angle_deg,
                  "Remove triangles with an angle below this, in degrees (0 to 30)")
      ->capture_default_str()
      ->check(number_in_range(0, 30, "from 0 to 30 (degrees; the seed paper uses 5)"));
  cmd->add_option("--target-triangles", options->clean.target_triangles,
                  "Reduce the surface to at most this many triangles (0: no reduction)")
      ->capture_default_str()
      ->transform(count_in_range(0, std::numeric_limits<int>::max()));
  cmd->add_option("--max-deviation", options->clean.max_deviation_mm,
                  "Bound on the Hausdorff distance between the input and the result, in mm")
      ->capture_default_str()
      ->check(number_in_range(std::numeric_limits<double>::min(), std::numeric_limits<double>::max(),
                              "greater than 0 (a distance in mm)"));
  cmd->add_option("--units", options->units, "Length unit of the input's coordinates: mm, cm or m")
      ->capture_default_str();
  cmd->add_flag("--json", options->json, "Print the report as one JSON object on standard output");
  cmd->callback([options] { run_clean(*options); });
}

}  // namespace hexbite
