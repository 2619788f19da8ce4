// The figures of a finished `hexbite run`, read back from its results.json (the contract of
// docs/running.md, "results.json"; app/run_outputs.cc results_json writes it) for reports.
//
// Every key a report needs is checked once, here, so that a report is never half built from a file that
// lacks something: a missing key or one of the wrong type is an InputError naming the file and the key's
// path ("validation.levels[1].hexes"). Keys that only some runs write (mesh.core, mesh.fidelity,
// support_hold) are optional. Cost: linear in the size of the file.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "mesher/vec3.h"

namespace hexbite {

struct ReactionFigures {
  std::string name;
  Vec3 force{0, 0, 0};  // N, the force the support exerts on the bone
  double magnitude = 0;
  bool bite = false;
  bool released = false;  // a contact that would have pulled the bone, left out of the solve
};

struct ProbeFigures {
  std::string name;
  Vec3 at{0, 0, 0};  // where it was evaluated, mm
  double moved_mm = 0;
  bool found = false;
  Vec3 displacement{0, 0, 0};  // mm
  double von_mises = 0;        // MPa
};

// One level's figures (the top level of results.json holds level 0's).
struct LevelFigures {
  int level = 0;
  long hexes = 0, nodes = 0, dofs = 0;
  std::vector<ReactionFigures> reactions;  // in the scenario's order of supports where the file gives it
  std::optional<double> bite_force;        // none with outputs.bite_force: false
  Vec3 applied_force{0, 0, 0};
  double equilibrium_residual = 0;
  double max_displacement = 0;
  Vec3 max_displacement_at{0, 0, 0};
  double von_mises_max = 0, von_mises_p99 = 0;
  Vec3 von_mises_max_at{0, 0, 0};
  double strain_energy = 0;  // mJ
  std::vector<ProbeFigures> probes;
  long iterations = 0;  // CG iterations; 0 for the direct solver
  double solve_seconds = 0;
  long ranks = 1;
};

// min / mean / max of one quality measure; none where the mesh had no element to measure.
struct QualityFigures {
  std::optional<double> min, mean, max;
};

// None where the file has null (JSON has no NaN: a measure that could not be taken).
struct FidelityFigures {
  std::optional<double> hausdorff, hausdorff_mesh_to_surface, hausdorff_surface_to_mesh;  // mm
  std::optional<double> mesh_volume, surface_volume;                                      // mm^3
  std::optional<double> volume_difference;  // (mesh - surface) / surface
};

// The rigid motion the supports of one body hold least (results.json support_hold).
struct SupportHoldFigures {
  bool weak = false;
  double hold = 0;
  bool rotation = false;
  Vec3 direction{0, 0, 0};
  std::optional<Vec3> axis_point;  // rotations
};

// The model as solved (results.json materials, muscles, supports). Keys that a results.json of an older
// hexbite lacks are none.
struct MaterialFigures {
  std::string name;  // of a region; empty for the default
  double E_MPa = 0, poisson = 0;
  std::optional<long> hexes;  // regions: the coarse mesh's hexes that take this material
};

struct MuscleFigures {
  std::string name;
  std::optional<double> activation;
  Vec3 force{0, 0, 0};  // N
  double magnitude = 0, patch_area_mm2 = 0;
};

struct SupportFigures {
  std::string name;
  std::optional<Vec3> center;  // mm
  std::optional<double> radius_mm, spring_N_per_mm3;
  std::optional<std::vector<std::string>> fixed;  // the fixed components, "x" "y" "z"
  bool contact = false;                           // one-sided: pushes the bone, never pulls
  double patch_area_mm2 = 0;
};

// The study a run folder of `hexbite study` belongs to; results.json's `study`.
struct StudyFigures {
  std::string name, file, variant;
  std::string changes;  // the variant's set entries, "path: value; path: value"; empty for the base as it is
};

struct RunFigures {
  std::string scenario, scenario_file, mesh_method, mesh_core;  // mesh_core empty for method sheets
  std::string hexbite_version;                                  // of the run; empty in older files
  std::optional<StudyFigures> study;                            // none for `hexbite run`
  std::optional<MaterialFigures> default_material;              // none in older files
  std::vector<MaterialFigures> material_regions;
  std::vector<MuscleFigures> muscles;    // the active ones
  std::vector<SupportFigures> supports;  // in the scenario's order
  int degree = 1;
  QualityFigures scaled_jacobian, condition, condition_verdict, oddy;
  long inverted = 0;
  std::optional<FidelityFigures> fidelity;
  std::vector<SupportHoldFigures> support_hold;
  LevelFigures coarse;               // the top level: level 0, the mesh of solution.vtu
  std::vector<LevelFigures> levels;  // validation.levels, level 0 first
  // validation.relative_change: (last level - previous) / |last level|; none without a validation level.
  std::optional<double> change_bite_force, change_max_displacement, change_strain_energy;
  // checks: the run's small-displacement limit (10 % of bone_size_mm).
  double max_displacement_limit = 0, bone_size = 0;
};

// Reads RUN_DIR/results.json (`path`). InputError for a missing file (saying to run `hexbite run` first),
// text that is not JSON (with its line and column) and a missing or mistyped key (with its path).
RunFigures read_run_figures(const std::string& path);

}  // namespace hexbite
