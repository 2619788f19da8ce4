// Scenario files: what to simulate (geometry, landmarks, mesh settings, materials, muscles, supports,
// solver settings, outputs and probes), read from YAML with strict validation. The format is documented
// key by key in docs/scenario-format.md; every error is an InputError "FILE:LINE:COLUMN: what is wrong;
// what to do". Names used as points are kept unresolved by load_scenario() because the landmarks only
// exist once the geometry is built; resolve_points() turns them into coordinates afterwards.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "mesher/hex_mesh.h"
#include "mesher/landmarks.h"
#include "mesher/mandible_generator.h"
#include "mesher/tri_surface.h"

namespace hexbite {

// Where something was written in a scenario file; line and column count from 1.
struct SourceLocation {
  std::string file;  // the scenario path as given to load_scenario() (or a study file, scenarios/study.h)
  int line = 0;
  int column = 0;
  // What the place belongs to when the file alone does not say it: a study's variant ("variant
  // 'soft_bone'"). Empty for a scenario run on its own.
  std::string note;

  // "FILE:LINE:COLUMN", or "FILE:LINE:COLUMN: NOTE": the prefix of every scenario error message.
  std::string str() const;
};

// A point in millimetres, written either as coordinates [x, y, z] or as a name: a landmark, an extra
// point of the scenario's landmarks.points, or "<muscle>.insertion" / "<muscle>.origin".
struct PointRef {
  std::string name;  // empty when the point was given as coordinates
  Vec3 xyz{};        // the coordinates: as written, or filled in by resolve_points()
  bool resolved = false;
  SourceLocation where;
};

enum class GeometrySource { kMandible, kSurface, kCt };

struct GeometrySpec {
  GeometrySource source = GeometrySource::kMandible;
  MandibleParameters mandible;  // kMandible: zero fields mean the variant's defaults (complete_parameters)
  std::string file;             // kSurface, kCt: resolved against the scenario file's folder
  std::string units = "mm";     // kSurface, kCt: the file's length unit
  double scale_to_mm = 1.0;     // kSurface, kCt: unit_to_mm(units)
  bool units_given = false;     // kCt: `units` is written; else the unit the volume states, or mm
  double threshold = 0;         // kCt: the iso-value of the bone surface
  std::string dicom_series;     // kCt, a folder holding several DICOM series: the one to read
  SourceLocation where;
};

struct NamedPoint {
  std::string name;
  Vec3 xyz{};
  SourceLocation where;
};

struct LandmarkSpec {
  std::string file;          // empty: the built-in mandible's own landmarks (or none for other geometry)
  std::string units = "mm";  // the landmark file's unit; defaults to the surface's or CT's unit
  double scale_to_mm = 1.0;  // unit_to_mm(units)
  std::vector<NamedPoint> points;  // extra named points (mm), usable wherever a point is expected
  SourceLocation where;
};

enum class MeshMethod { kGrid, kSheets };
enum class MeshCore { kGrid, kSwept, kAuto };

// The most validation levels a run takes (scenario mesh.validation_levels, run and study --levels). Each
// level multiplies the mesh by 8: four levels of the default mesh would be ten million hexes.
constexpr int kMaxValidationLevels = 3;

struct MeshSettings {
  MeshMethod method = MeshMethod::kGrid;
  int target_hexes = 2500;
  int validation_levels = 1;            // each level is one 8-way refinement solved again
  SourceLocation method_at;             // where `method` was written (empty when it was left at its default)
  SourceLocation validation_levels_at;  // where `validation_levels` was written (empty: the default)
  // method sheets only: refine the quad surface around every bite support's point
  // (mesher/quad_local_refinement.h), with this patch radius and number of rings.
  bool refine_at_bite = false;
  double refine_radius_mm = 8.0;
  int refine_levels = 3;
  SourceLocation refine_at_bite_at;  // where refine_at_bite was written
  // boundary nodes moved off the surface until the mesh's volume matches (mesher/boundary_fit.h), on the
  // coarse mesh and on every validation level.
  bool fit_volume = false;
  // method grid only: lay the overlay grid along the dental arch (GridMeshOptions::arch_frame).
  bool arch_frame = false;
  SourceLocation grid_frame_at;  // where grid_frame was written
  // method grid only: the core, grid, swept (across the dental arch, GridMeshOptions::swept_core; implies
  // the arch frame) or auto (mesher/auto_core.h: the swept core for coarse meshes of a mandible, else the
  // grid core in grid_frame).
  MeshCore core = MeshCore::kGrid;
  SourceLocation core_at;  // where core was written
};

struct MaterialSpec {
  double E_MPa = 11000;
  double poisson = 0.28;
  SourceLocation E_MPa_at;    // where `E_MPa` was written (empty: the default)
  SourceLocation poisson_at;  // where `poisson` was written (empty: the default)
};

enum class RegionShape { kSphere, kBox };

// A part of the bone with another material, e.g. an implant site or a resorbed region.
struct MaterialRegion {
  std::string name;
  RegionShape shape = RegionShape::kSphere;
  PointRef center;  // kSphere
  double radius_mm = 0;
  PointRef min, max;  // kBox: opposite corners, min below max in every coordinate
  MaterialSpec material;
  SourceLocation where;
  SourceLocation radius_at;  // where a sphere's radius_mm was written: a study's line when the study set it
};

struct Materials {
  MaterialSpec default_material;
  std::vector<MaterialRegion> regions;  // where regions overlap, the later one in the file wins
};

struct Muscle {
  std::string name;
  PointRef insertion;  // centre of the insertion patch; default "<name>.insertion"
  double radius_mm = 10;
  // The line of action: toward `origin` (default "<name>.origin") or along `direction` (exactly one).
  std::optional<PointRef> origin;
  std::optional<Vec3> direction;      // as written; never zero
  std::optional<double> max_force_N;  // empty until resolve_points() takes it from the landmarks
  double activation = 0;
  Vec3 line_of_action{};  // unit vector, filled in by resolve_points()
  SourceLocation where;
  SourceLocation name_at;    // where the name was written when not at `where` (empty: at where)
  SourceLocation radius_at;  // where radius_mm was written (empty: the default), as Support::radius_at
  std::string pattern_key;   // the activation_pattern key it came from ("superficial_masseter"), or empty
};

struct Support {
  std::string name;
  PointRef at;  // centre of the support patch
  double radius_mm = 0;
  std::array<bool, 3> fixed{true, true, true};  // fixed displacement components x, y, z
  std::optional<double> spring_N_per_mm3;       // an elastic foundation instead of fixed components
  bool bite = false;  // the bite force is the magnitude of the summed reaction of the bite supports
  // A one-sided contact (an antagonist tooth, a nut): it may push the bone but never pull it. A contact
  // whose reaction would pull is released and the level solved again without it (run_pipeline.h).
  bool contact = false;
  SourceLocation where;
  // Where the name was written: a study that renames the support (supports.x.name) wrote it in the study
  // file, and a clash of names is named there. The same for the radius and the spring (messages about a
  // patch that selects nothing, or a spring the CalculiX export cannot write), and the fixed components (a
  // warning that the supports hold the bone weakly).
  SourceLocation name_at, radius_at, spring_at, fixed_at;
};

enum class LinearSolverChoice { kAuto, kCgAmg, kDirect };

struct SolverSpec {
  int degree = 1;
  LinearSolverChoice linear_solver = LinearSolverChoice::kAuto;
  double tolerance = 1e-10;  // relative residual
  int max_iterations = 10000;
  SourceLocation where;  // where the `solver` mapping was written (empty: all defaults)
  // Where tolerance and max_iterations were written (empty: defaults). A study that sets one is named at
  // its own line; a failed solve named the base's `solver` line.
  SourceLocation tolerance_at, max_iterations_at;
  // Where linear_solver was written (empty: the default), for a direct solver that the memory cannot hold.
  SourceLocation linear_solver_at;
};

struct Outputs {
  bool vtu = true;
  bool inp = false;
  bool bite_force = true;  // report bite_force_N; requires at least one bite support
};

struct Probe {
  std::string name;
  PointRef at;
  SourceLocation where;
  SourceLocation name_at;  // as Support::name_at
};

struct Scenario {
  std::string path;  // the scenario file as given
  int format_version = 1;
  std::string name;
  std::string description;
  GeometrySpec geometry;
  LandmarkSpec landmarks;
  MeshSettings mesh;
  Materials materials;
  std::vector<Muscle> muscles;  // the explicit list first, then the activation_pattern's muscles
  std::vector<Support> supports;
  SolverSpec solver;
  Outputs outputs;
  std::vector<Probe> probes;
};

// Reads and validates a scenario file. Everything that can be checked without the geometry is checked
// here (keys, types, ranges, duplicate names, supports); throws InputError "FILE:LINE:COLUMN: ...".
// (A study's variants are validated the same way from their merged trees: scenarios/study.h.)
Scenario load_scenario(const std::string& path);

// Turns every named point into coordinates using `landmarks` and the scenario's extra points, fills in
// the muscles' defaults from the landmarks (insertion, origin, max_force_N) and their unit lines of
// action. Throws InputError at the name's file and line, listing the closest known names, for an unknown
// name, a muscle the landmarks do not know, a zero line of action or a box with min not below max.
// Calling it again is harmless.
void resolve_points(Scenario& scenario, const Landmarks& landmarks);

// The material at a point (after resolve_points): the last region containing it, else the default.
MaterialSpec material_at(const Materials& materials, const Vec3& x);

// The index of the region whose material applies at a point (the last one containing it), or -1 for the
// default material.
int region_at(const Materials& materials, const Vec3& x);

// How far a point lies outside a region (0 inside), in mm.
double distance_outside(const MaterialRegion& region, const Vec3& x);

// A muscle's force vector in N (after resolve_points): activation x max force along the line of action.
Vec3 muscle_force(const Muscle& muscle);

// The boundary quads of a patch: those whose centroid lies within `radius` of `center` (sorted indices).
std::vector<int> select_patch_quads(const QuadSurface& boundary, const Vec3& center, double radius);

// select_patch_quads(), but a patch that selects no surface facet is an InputError at `where` (the
// scenario entry of the muscle, support or region) that names `what` and says how far the nearest facet is.
std::vector<int> require_patch_quads(const QuadSurface& boundary, const Vec3& center, double radius,
                                     const SourceLocation& where, const std::string& what);

}  // namespace hexbite
