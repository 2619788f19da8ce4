// The end-to-end bite simulation behind `hexbite run`: scenario -> geometry and landmarks -> hex mesh ->
// boundary patches -> per-hex materials -> elasticity solve -> validation levels (the mesh refined 8-way onto
// the surface, every patch and every hex's material carried over from the coarser level, solved again).
//
// Input: a loaded Scenario (scenarios/scenario.h) and the number of validation levels.
// Output: one LevelResult per level (level 0 is the coarse mesh) with the mesh, the patches, the problem's
// materials and the solution, plus the geometry's fidelity and the stage timings. Nothing is written here:
// app/run_outputs.h turns a RunResult into results.json, VTU files and the CalculiX deck.
// Errors: InputError for anything the scenario got wrong (with its file and line), before the first solve;
// RunError when a mesh stays inverted or the linear solver fails.
// MPI: collective. Every rank builds the same geometry and meshes (all steps are deterministic) and calls the
// solver together; every rank receives the complete solution.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "app/rigid_support.h"
#include "mesher/grid_mesher.h"
#include "mesher/hex_mesh.h"
#include "mesher/hex_quality.h"
#include "scenarios/scenario.h"
#include "solver/elasticity.h"

namespace hexbite {

// The boundary faces of one scenario patch on one mesh, as mesh vertex ids (outward, counter-clockwise).
struct MeshPatch {
  std::string name;
  std::vector<BoundaryQuad> faces;
  double area_mm2 = 0.0;  // with the solver's 2 x 2 Gauss rule on the bilinear quads
};

struct LevelResult {
  int level = 0;  // 0 = the coarse mesh, k = refined k times
  HexMesh mesh;
  QualitySummary quality;
  std::vector<MeshPatch> muscle_patches;   // the muscles with activation > 0, in scenario order
  std::vector<Vec3> muscle_forces;         // N, total force of each of those muscles
  std::vector<MeshPatch> support_patches;  // every support, in scenario order
  std::vector<Vec3> contact_directions;    // per support: what a contact resists (app/contact_supports.h)
  std::vector<Vec3> probe_points;          // every probe, moved into the mesh when just outside it
  std::vector<Material> hex_material;      // one per hex
  std::vector<int> region_hexes;  // per material region (scenario order): the hexes it gives its material
  ElasticitySolution solution;
  double seconds_mesh = 0.0;   // meshing (level 0) or refinement (levels > 0)
  double seconds_solve = 0.0;  // the solver call
};

struct RunResult {
  Scenario scenario;      // with every point resolved
  MeshFidelity fidelity;  // of the coarse mesh against the bone surface
  std::string
      mesh_core;  // method grid: the core the coarse mesh has, "grid" or "swept" (mesh.core auto picks)
  std::vector<LevelResult> levels;
  std::vector<RigidMode>
      support_hold;  // per body of the coarse mesh: the rigid motion its supports hold least
  double seconds_geometry = 0.0;
  double seconds_total = 0.0;
};

// The consistent nodal forces of a uniform traction on bilinear quads: for every quad, the integral of each
// corner's shape function times the traction, by the 2 x 2 Gauss rule (what the Q1 solver assembles).
// Returns one (vertex id, force) entry per vertex touched, sorted by vertex id, with `traction` in MPa.
std::vector<std::pair<int, Vec3>> consistent_nodal_forces(const HexMesh& mesh,
                                                          const std::vector<BoundaryQuad>& faces,
                                                          const Vec3& traction);

// The area of a patch of bilinear quads by the same 2 x 2 Gauss rule.
double patch_area(const HexMesh& mesh, const std::vector<BoundaryQuad>& faces);

// Runs the pipeline. `levels` validation levels follow the coarse solve. Throws as described above.
RunResult run_pipeline(Scenario scenario, int levels);

// run_pipeline() in two halves, for a caller that checks several scenarios before it solves any (a study,
// app/cmd_study.cc): prepare_run() does everything but the solves (geometry, points, meshes and patches of
// every level, and every check that needs them), so its InputErrors come before any solve; its result has
// no solutions yet. solve_run() then solves every level. seconds_total adds up the time of both.
// `in_study`: the scenario is a study's variant, which runs in one process: advice to use mpirun names
// `hexbite run` of the variant's scenario.
RunResult prepare_run(Scenario scenario, int levels, bool in_study = false);
void solve_run(RunResult& result);

// The checks of a solved run that no scenario check can make in advance: applied forces and reactions
// balance at every level (relative residual at most 1e-8), and the largest displacement stays below 10 % of
// the bone's size (linear elasticity). Throws RunError naming the level, the figure and what to check;
// `results` names the results in question for the message ("the results in out").
void require_trustworthy(const RunResult& result, const std::string& results);

// The limits of those checks for this run (results.json's `checks`, so that a report of a failed run's
// kept files can say so): the relative equilibrium residual (1e-8) and the largest displacement, 10 % of
// the coarse mesh's largest extent (`bone_size_mm`).
struct TrustLimits {
  double equilibrium_residual = 0;
  double max_displacement_mm = 0;
  double bone_size_mm = 0;
};
TrustLimits trust_limits(const RunResult& result);

}  // namespace hexbite
