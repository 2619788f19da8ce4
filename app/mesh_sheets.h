// `hexbite mesh --method sheets --quad-surface Q.obj -o mesh.vtu`: the sheet mesher (cycle elimination,
// mesher/cycle_elimination.h) behind the mesh command; cmd_mesh.cc only forwards its options here.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "mesher/cycle_elimination.h"

namespace hexbite {

struct MeshSheetsOptions {
  std::string quad_surface;         // .obj, .vtp or .vtk quad surface of a ball
  std::string output;               // .vtu
  std::string order = "geometric";  // or fewest-hexes, look-ahead
  bool json = false;
  bool allow_invalid = false;  // write the mesh even when hexes stay inverted
};

// Reads, meshes, prints the report (text or JSON) and writes the mesh atomically. InputError for a bad
// surface or option, RunError when no chord is feasible or hexes stay inverted (then nothing is written
// unless allow_invalid).
void run_mesh_sheets(const MeshSheetsOptions& options);

// Shared by both sheets commands (this one and app/mesh_sheets_surface.h). The report's counts and quality
// as JSON keys: quads, chords, eliminations {single, k_step}, sheets {external, internal},
// eliminations_single, eliminations_k_step, chords_eliminated, external_sheets, internal_sheets,
// decompositions, look_ahead_fallbacks, hexes, interior_nodes, quality.
void add_sheet_report_json(const SheetMeshReport& report, nlohmann::json& j);
// A line saying that the order ran into a dead end and the look-ahead order completed, or nothing.
std::string look_ahead_text(const SheetMeshReport& report);
// The interior node degree lines (edges, hexes) and the quality line, each ending in a newline.
std::string sheet_quality_text(const QualitySummary& quality);

}  // namespace hexbite
