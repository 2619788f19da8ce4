#include "app/run_pipeline.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <string>

#include "app/contact_supports.h"
#include "app/rigid_support.h"
#include "common/error.h"
#include "common/progress.h"
#include "common/system_memory.h"
#include "mesher/arch_frame.h"
#include "mesher/auto_core.h"
#include "mesher/boundary_fit.h"
#include "mesher/ct_surface.h"
#include "mesher/grid_mesher.h"
#include "mesher/hex_boundary.h"
#include "mesher/hex_point_location.h"
#include "mesher/hex_quality.h"
#include "mesher/hex_refine.h"
#include "mesher/landmarks.h"
#include "mesher/mandible_generator.h"
#include "mesher/mandible_sheet_mesher.h"
#include "mesher/surface_check.h"
#include "mesher/surface_projector.h"
#include "mesher/tri_surface.h"
#include "mesher/union_find.h"
#include "mesher/units.h"
#include "mesher/vec3.h"
#include "postprocess/report_format.h"
#include "solver/mpi_session.h"

namespace hexbite {

namespace {

// Applied forces plus reactions must vanish; the solver's tolerance (1e-10 by default) leaves residuals
// of order 1e-11, so 1e-8 separates a converged solve from wrong bookkeeping with a wide margin.
constexpr double kEquilibriumTolerance = 1e-8;

// Linear elasticity assumes displacements small against the body: a largest displacement beyond this
// fraction of the bone's size (about 10 mm on a mandible, whose bite moves it by about 0.1 mm) comes from
// a Young's modulus or a force in the wrong unit, or from supports that barely hold the bone, and the
// figures mean nothing.
constexpr double kMaxDisplacementFraction = 0.1;

// Below this many degrees of freedom `linear_solver: auto` factorizes (MUMPS): on this machine that is
// faster than setting up the AMG hierarchy, and above it the factorization's fill-in makes CG + AMG win.
constexpr long long kDirectSolverMaxDofs = 30000;

struct Geometry {
  TriSurface surface;
  Landmarks landmarks;
  std::string volume_unit;  // a CT volume: the unit its file states (VolumeInfo::length_unit)
};

// A warning on standard error, from rank 0 only (every rank builds the same geometry).
void warn(const std::string& line) {
  if (MpiSession::rank() == 0) std::cerr << "hexbite: warning: " << line << ".\n";
}

Geometry build_geometry(const Scenario& s) {
  Geometry g;
  switch (s.geometry.source) {
    case GeometrySource::kMandible: {
      GeneratedMandible m = generate_mandible(s.geometry.mandible);
      g.surface = std::move(m.surface);
      g.landmarks = std::move(m.landmarks);
      break;
    }
    case GeometrySource::kSurface:
      try {
        g.surface = load_closed_surface(s.geometry.file, s.geometry.scale_to_mm);
      } catch (const InputError& e) {
        // The file's own problem (not closed, not a surface format), named at the scenario's geometry as
        // every scenario error is (and as the CT source is below); the message names the file.
        const std::string what = e.what();
        throw InputError(s.geometry.where.str() + ": " +
                         (what.find(s.geometry.file) == std::string::npos ? s.geometry.file + ": " : "") +
                         what);
      }
      break;
    case GeometrySource::kCt: {
      CtExtraction dropped;
      VolumeInfo source;
      try {
        VoxelVolume volume = read_volume(s.geometry.file, &source, s.geometry.dicom_series);
        g.volume_unit = source.length_unit;
        if (s.geometry.units_given) rescale_volume_units(volume, source.length_unit, s.geometry.units);
        g.surface = surface_from_volume(volume, s.geometry.threshold, &dropped);
      } catch (const InputError& e) {
        const std::string what = e.what();
        // read_volume names the file; the threshold's messages speak of "the volume".
        throw InputError(s.geometry.where.str() + ": " +
                         (what.find(s.geometry.file) == std::string::npos ? s.geometry.file + ": " : "") +
                         what);
      }
      for (const std::string& sentence : source.warnings) warn(s.geometry.file + ": " + sentence);
      for (const std::string& sentence : describe_dropped(dropped, s.geometry.threshold))
        warn(s.geometry.file + ": " + sentence);
      // Marching cubes gives a closed surface by construction, but the same checks as for a surface file
      // catch a threshold that produced something that cannot bound a solid.
      const SurfaceReport report = check_surface(g.surface, s.geometry.file);
      if (!report.usable()) {
        char threshold[32];
        std::snprintf(threshold, sizeof threshold, "%g", s.geometry.threshold);
        throw InputError(s.geometry.where.str() + ": the surface of " + s.geometry.file + " at threshold " +
                         threshold + " cannot bound a solid: " + report.problems.front() +
                         "; try another threshold");
      }
      break;
    }
  }
  if (s.geometry.source != GeometrySource::kMandible && !g.surface.vertices.empty()) {
    // A file in centimetres read as millimetres (a mandible of 12 mm) solves without complaint, stresses a
    // hundred times too large; so does one in mm read as m. The bounds are those of a mandible. A CT
    // volume's lengths are in the unit its file states (a NIfTI header, DICOM's mm) unless `units` says
    // otherwise; a MetaImage states none.
    const bool ct = s.geometry.source == GeometrySource::kCt;
    const std::string read_as =
        !ct || s.geometry.units_given || g.volume_unit.empty() ? s.geometry.units : g.volume_unit;
    const std::string size_warning = unit_mismatch_warning(
        largest_extent(g.surface), read_as,
        std::string("write units: <unit> in geometry.") + (ct ? "ct" : "surface") + " (" +
            (ct && !g.volume_unit.empty() && !s.geometry.units_given
                 ? "it overrides the unit the file states, " + g.volume_unit + "; "
                 : "") +
            "a landmarks.file without units of its own follows it)");
    if (!size_warning.empty()) warn(s.geometry.where.str() + ": " + s.geometry.file + ": " + size_warning);
  }
  if (!s.landmarks.file.empty()) {
    g.landmarks = read_landmarks(s.landmarks.file, s.landmarks.scale_to_mm);
    for (const std::string& warning :
         {landmark_fit_warning(g.landmarks, g.surface, s.landmarks.file, s.landmarks.units,
                               "write units: <unit> in landmarks"),
          landmark_side_warning(g.landmarks, s.landmarks.file)})
      if (!warning.empty()) warn(s.landmarks.where.str() + ": " + warning);
  }
  return g;
}

// The line a run prints for mesh.fit_volume.
void info_volume_fit(const BoundaryFitReport& fit, const MeshFidelity& fidelity) {
  char line[200];
  std::snprintf(
      line, sizeof line,
      "mesh.fit_volume: %d of %d boundary nodes moved, up to %.2f mm off the surface; volume %+.2f %%",
      fit.moved_nodes, fit.boundary_nodes, fit.max_node_offset, 100.0 * fidelity.volume_difference);
  info(line);
}

// "2 hexes inverted: hex 12 at (...) mm, ...", for a mesh that cannot be solved on.
std::string inverted_hexes_text(const HexMesh& mesh) {
  const QualitySummary q = summarize_quality(mesh);
  return hex_count_text(q.inverted_hexes.size()) + " inverted: " + hex_list_text(mesh, q.inverted_hexes);
}

// `method: grid`. A mesh that stays inverted cannot be solved on.
HexMesh mesh_by_grid(const Scenario& s, const Geometry& geometry, MeshFidelity* fidelity, std::string* core) {
  GridMeshOptions options;
  options.target_hexes = s.mesh.target_hexes;
  options.fit_volume = s.mesh.fit_volume;
  options.arch_frame = s.mesh.arch_frame;
  options.swept_core = s.mesh.core == MeshCore::kSwept;
  GridMeshReport report;
  HexMesh mesh;
  try {
    if (s.mesh.core == MeshCore::kAuto) {
      AutoCoreChoice choice;
      mesh = grid_mesh_auto_core(geometry.surface, options, &report, &choice);
      info(std::string("mesh.core auto: the ") + (choice.swept ? "swept" : "grid") + " core" +
           (choice.reason.empty() ? "" : " (" + choice.reason + ")"));
    } else {
      mesh = grid_mesh(geometry.surface, options, &report);
    }
  } catch (const NotAnArchError& e) {
    // A bone that follows no arch is the fault of the scenario's grid_frame, or of its swept core (other
    // input errors are not).
    if (s.mesh.grid_frame_at.line == 0)
      throw InputError(s.mesh.core_at.str() + ": mesh.core swept: " + e.what());
    throw InputError(s.mesh.grid_frame_at.str() + ": mesh.grid_frame arch: " + e.what());
  }
  if (report.principal_retry) info("mesh: " + principal_retry_text(*report.principal_retry));
  if (report.volume_fit) info_volume_fit(*report.volume_fit, report.fidelity);
  name_unresolved_parts(geometry.landmarks, report.fidelity.unresolved);
  *fidelity = report.fidelity;
  *core = report.swept ? "swept" : "grid";
  // The first ten; results.json lists every one (mesh.fidelity.unresolved).
  for (const std::string& line : unresolved_listing(report.fidelity.unresolved))
    info("not resolved: " + line);
  if (report.optimize.inverted > 0)
    throw RunError(s.path + ": at mesh.target_hexes = " + std::to_string(s.mesh.target_hexes) +
                   " the grid mesher left " + inverted_hexes_text(mesh) + "; try another target" +
                   (s.mesh.core == MeshCore::kSwept ? " or core: grid"
                    : s.mesh.arch_frame             ? " or grid_frame: axes"
                                                    : ""));
  return mesh;
}

// `method: sheets`: the mandible template placed by the geometry's landmarks (the built-in mandible's own or
// the landmark file's), or by the surface's extreme points when there are none. Landmarks that lack the
// template's points, or a bone that is not a mandible, are the scenario's fault (InputError at `method`,
// which a scenario asking for sheets has written).
HexMesh mesh_by_sheets(const Scenario& s, const Geometry& geometry, MeshFidelity* fidelity) {
  const bool has_landmarks = !geometry.landmarks.points.empty() || !geometry.landmarks.muscles.empty();
  MandibleSheetOptions options;
  options.target_hexes = s.mesh.target_hexes;
  options.surface_name =
      s.geometry.source == GeometrySource::kMandible ? "the built-in mandible" : s.geometry.file;
  options.landmark_file = !s.landmarks.file.empty() ? s.landmarks.file
                          : has_landmarks           ? "the built-in mandible's landmarks"
                                                    : "";
  if (s.mesh.refine_at_bite) {
    options.refinement.radius_mm = s.mesh.refine_radius_mm;
    options.refinement.levels = s.mesh.refine_levels;
    for (const Support& support : s.supports)
      if (support.bite) {
        options.refinement.points.push_back(support.at.xyz);
        options.refinement.point_names.push_back(support.at.where.str() + ": the bite support " +
                                                 support.name + "'s point (mesh.refine_at_bite)");
      }
  }
  options.fit_volume = s.mesh.fit_volume;
  options.terms = scenario_terms(s.geometry.units);
  MandibleSheetReport report;
  HexMesh mesh;
  try {
    mesh = mesh_mandible_by_sheets(geometry.surface, has_landmarks ? &geometry.landmarks : nullptr, options,
                                   &report);
  } catch (const LocalRefinementError&) {
    throw;  // a bite point off the bone: the message starts with the support's line (point_names above)
  } catch (const InputError& e) {
    // The message says what to do in the scenario's terms (options.terms).
    throw InputError(s.mesh.method_at.str() +
                     ": mesh.method 'sheets' cannot place its mandible template: " + e.what());
  } catch (const RunError& e) {
    throw RunError(std::string("the sheet mesher failed: ") + e.what() + "; use method: grid");
  }
  *fidelity = report.fidelity;
  if (report.volume_fit) info_volume_fit(*report.volume_fit, report.fidelity);
  for (const LocalRefinementSite& site : report.refinement.sites) {
    char line[256];
    std::snprintf(
        line, sizeof line,
        "mesh.refine_at_bite: %d rings at (%.1f, %.1f, %.1f) mm, mean quad edge within %.1f mm %.2f "
        "-> %.2f mm (+%d quads in all)",
        report.refinement.levels, site.on_surface[0], site.on_surface[1], site.on_surface[2],
        s.mesh.refine_radius_mm, site.mean_edge_before_mm, site.mean_edge_after_mm,
        report.refinement.quads_added);
    info(line);
  }
  if (!report.boundary_crossings.empty())
    throw RunError(s.path +
                   ": the sheet mesher's mesh at mesh.target_hexes = " + std::to_string(s.mesh.target_hexes) +
                   ": " + report.boundary_crossing_text + "; try another target or method: grid");
  if (report.inverted > 0)
    throw RunError(s.path + ": at mesh.target_hexes = " + std::to_string(s.mesh.target_hexes) +
                   " the sheet mesher left " + inverted_hexes_text(mesh) +
                   "; try another target or method: grid");
  return mesh;
}

// Degrees of freedom of vector FE_Q(degree) on the mesh: 3 per vertex, and for Q2 also 3 per edge, face and
// hex (the support points of the triquadratic element).
long long count_dofs(const HexMesh& mesh, int degree) {
  long long nodes = static_cast<long long>(mesh.vertices.size());
  if (degree == 2) {
    static constexpr int kEdges[12][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6},
                                          {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
    std::vector<std::array<int, 2>> edges;
    std::vector<std::array<int, 4>> faces;
    edges.reserve(12 * mesh.hexes.size());
    faces.reserve(6 * mesh.hexes.size());
    for (const auto& hex : mesh.hexes) {
      for (const auto& e : kEdges)
        edges.push_back({std::min(hex[e[0]], hex[e[1]]), std::max(hex[e[0]], hex[e[1]])});
      for (const auto& f : kHexFaces) {
        std::array<int, 4> key{hex[f[0]], hex[f[1]], hex[f[2]], hex[f[3]]};
        std::sort(key.begin(), key.end());
        faces.push_back(key);
      }
    }
    std::sort(edges.begin(), edges.end());
    std::sort(faces.begin(), faces.end());
    nodes += std::unique(edges.begin(), edges.end()) - edges.begin();
    nodes += std::unique(faces.begin(), faces.end()) - faces.begin();
    nodes += static_cast<long long>(mesh.hexes.size());
  }
  return 3 * nodes;
}

// Peak memory of a solve per degree of freedom, matrix and AMG hierarchy included (docs/solver.md: 5.1 kB
// measured on a Q1 block of 204,828 DoFs).
constexpr double kBytesPerDof = 5e3;

// Address space a direct solve needs besides its matrix and factors: OpenBLAS's work buffer of 128 MB per
// thread, which this OpenBLAS, when it cannot allocate it, retries forever (measured on the shipped
// scenario's level 0 under ulimit -v: the process maps about 1.0 GB before the solve; at 1.1 GB it hung
// inside MUMPS, at 1.2 GB it solved, at 1.0 GB MUMPS itself failed).
constexpr double kDirectSolverHeadroom = 0.5e9;

// Why the memory left (machine_memory(): under ulimit -v the address space left) cannot hold a direct solve
// of `dofs` unknowns, or "" when it can. Collective under mpirun: every rank takes the same decision, from
// the rank with the least room (one rank solving with MUMPS and another with CG ended in std::terminate,
// helper AA).
std::string direct_solver_room_problem(double dofs) {
  const MemoryLimit memory = machine_memory();
  const double needed = kDirectSolverHeadroom + kBytesPerDof * dofs / MpiSession::size();
  const double own = memory.bytes > 0 ? memory.bytes : std::numeric_limits<double>::infinity();
  const double least = MpiSession::min_over_ranks(own);
  if (least >= needed) return "";
  char text[512];
  std::snprintf(text, sizeof text, "the direct solver needs about %.2g GB, more than the %.2g GB of %s",
                needed / 1e9, least / 1e9,
                least < own ? "another rank's memory, the least of the ranks'" : memory.source.c_str());
  return text;
}

// Where the scenario chose its linear solver, for a message about the direct solver: the linear_solver
// line (a study's own line when the study set it), else the `solver` mapping, else the file.
std::string linear_solver_place(const Scenario& s) {
  const SourceLocation& at = s.solver.linear_solver_at.line ? s.solver.linear_solver_at : s.solver.where;
  return at.line ? at.str() : s.path;
}

// A scenario that asks for the direct solver where it has no room: refused at linear_solver_place().
[[noreturn]] void refuse_direct_solver(const Scenario& s, int level, double dofs,
                                       const std::string& problem) {
  char where[160];
  std::snprintf(where, sizeof where,
                ": solver.linear_solver direct, level %d (%.0f degrees of freedom): ", level, dofs);
  throw InputError(linear_solver_place(s) + where + problem +
                   "; set solver.linear_solver: cg_amg (or auto), which needs far less, or raise the limit");
}

// Each validation level multiplies the problem by 8 (a Q2 problem of the shipped 4,000 hexes has 7 million
// DoFs at level 2): a last level whose solve needs more than this machine's memory (or the container's
// cgroup limit, when lower), even shared by all ranks, is refused before the refinement, instead of ending
// minutes later in bad_alloc or the kernel's out-of-memory kill.
void require_levels_fit_memory(const Scenario& s, const HexMesh& coarse, int levels, bool in_study) {
  const double dofs = static_cast<double>(count_dofs(coarse, s.solver.degree)) * std::pow(8.0, levels);
  if (s.solver.linear_solver == LinearSolverChoice::kDirect)
    if (const std::string problem = direct_solver_room_problem(dofs); !problem.empty())
      refuse_direct_solver(s, levels, dofs, problem);  // before any solve (a study: before any variant's)
  if (levels == 0) return;
  const double needed = kBytesPerDof * dofs / MpiSession::size();
  const MemoryLimit memory = machine_memory();
  if (memory.bytes <= 0 || needed <= memory.bytes) return;
  // The levels come from --levels or else from the scenario, where they may be left at their default.
  std::string what = "--levels ";
  if (levels == s.mesh.validation_levels)
    what = (s.mesh.validation_levels_at.line ? s.mesh.validation_levels_at.str() : s.path) +
           ": mesh.validation_levels" + (s.mesh.validation_levels_at.line ? " " : " (by default) ");
  char text[1024];
  std::snprintf(
      text, sizeof text,
      "%d would solve level %d on %.0f hexes with about %.3g million degrees of freedom (degree %d), "
      "which needs about %.3g GB (%.0f kB per degree of freedom%s), more than the %.3g GB of %s; use fewer "
      "levels, a smaller mesh.target_hexes%s, or %s",
      levels, levels, static_cast<double>(coarse.hexes.size()) * std::pow(8.0, levels), dofs / 1e6,
      s.solver.degree, needed / 1e9, kBytesPerDof / 1e3,
      MpiSession::size() > 1 ? ", shared by the ranks" : "", memory.bytes / 1e9, memory.source.c_str(),
      s.solver.degree > 1 ? " or solver.degree 1" : "",
      in_study
          ? "run this variant's scenario alone with mpirun hexbite run on several machines (a study runs "
            "in one process)"
          : "mpirun on several machines");
  throw InputError(what + text);
}

// Calls f(shape function values at the 4 corners, |x_u x x_v| times the Gauss weight) at the 2 x 2 Gauss
// points of the bilinear quad through the four vertices.
template <typename F>
void for_each_gauss_point(const HexMesh& mesh, const BoundaryQuad& quad, F&& f) {
  const double g = 0.5 / std::sqrt(3.0);
  for (double u : {0.5 - g, 0.5 + g})
    for (double v : {0.5 - g, 0.5 + g}) {
      // Corners in order around the quad: (0,0), (1,0), (1,1), (0,1) on the unit square, weights 1/4.
      const std::array<double, 4> N{(1 - u) * (1 - v), u * (1 - v), u * v, (1 - u) * v};
      const std::array<double, 4> Nu{-(1 - v), 1 - v, v, -v};
      const std::array<double, 4> Nv{-(1 - u), -u, u, 1 - u};
      Vec3 xu{0, 0, 0}, xv{0, 0, 0};
      for (int a = 0; a < 4; ++a)
        for (int d = 0; d < 3; ++d) {
          xu[d] += Nu[a] * mesh.vertices[quad[a]][d];
          xv[d] += Nv[a] * mesh.vertices[quad[a]][d];
        }
      const Vec3 n{xu[1] * xv[2] - xu[2] * xv[1], xu[2] * xv[0] - xu[0] * xv[2],
                   xu[0] * xv[1] - xu[1] * xv[0]};
      f(N, 0.25 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]));
    }
}

// The boundary quads that a scenario patch selects, as mesh vertex ids.
MeshPatch select_patch(const HexMesh& mesh, const HexBoundary& boundary, const std::string& name,
                       const Vec3& center, double radius, const SourceLocation& where,
                       const std::string& what) {
  MeshPatch patch;
  patch.name = name;
  for (int q : require_patch_quads(boundary.surface, center, radius, where, what)) {
    const auto& quad = boundary.surface.quads[q];
    patch.faces.push_back({boundary.boundary_vertices[quad[0]], boundary.boundary_vertices[quad[1]],
                           boundary.boundary_vertices[quad[2]], boundary.boundary_vertices[quad[3]]});
  }
  patch.area_mm2 = patch_area(mesh, patch.faces);
  return patch;
}

// Where a patch's or a probe's point was written, for an error about the point (a patch that selects no
// facet, a probe far outside): a study that set only the point ("supports.nut.at") wrote it in the study
// file, not at the item in the base scenario. The item's place when the point has none of its own.
const SourceLocation& point_place(const PointRef& point, const SourceLocation& item) {
  return point.where.line > 0 ? point.where : item;
}

// Where a patch or a sphere that holds nothing is named: at its radius when a study set it (written in
// another file than the item; the base's point is not what changed), else at its point.
const SourceLocation& sphere_place(const SourceLocation& radius_at, const PointRef& point,
                                   const SourceLocation& item) {
  return radius_at.line && radius_at.file != item.file ? radius_at : point_place(point, item);
}

constexpr double kProbeMaxOutsideMm = 5.0;

// Probe points named by landmarks lie on the bone surface, and the mesh's boundary (bilinear faces through
// nodes on the surface) runs up to a millimetre or two inside it, so such a point is often just outside the
// mesh. A point that no hex holds is moved to the nearest point inside a hex near it (its unit coordinates
// clamped just inside the unit cube: mesher/hex_point_location.h), so that the solver evaluates it exactly
// there; results.json reports that point and the distance moved. (It was moved onto the fan-triangulated
// boundary and 1 % toward the hex's centre, which on a warped boundary quad could still lie outside the
// curved hex: evaluated 0.02 mm elsewhere, or, 0.6 mm out, not at all, with zeros written.) A point farther
// outside than kProbeMaxOutsideMm is refused at its line, on the coarse mesh (`coarse`) only: a refined
// level's boundary lies elsewhere by a fraction of a millimetre, and a probe 4.997 mm from the coarse mesh
// was refused at level 1 as "5.0 mm outside ... within 5 mm".
std::vector<Vec3> probe_points_in_mesh(const HexMesh& mesh, const HexBoundary& boundary,
                                       const std::vector<Probe>& probes, bool coarse) {
  std::vector<Vec3> points;
  if (probes.empty()) return points;
  const SurfaceProjector mesh_boundary(fan_triangles(boundary.surface));
  std::vector<std::array<Vec3, 2>> boxes(mesh.hexes.size());  // each hex's bounding box
  for (std::size_t h = 0; h < mesh.hexes.size(); ++h) {
    boxes[h] = {mesh.vertices[mesh.hexes[h][0]], mesh.vertices[mesh.hexes[h][0]]};
    for (int v : mesh.hexes[h])
      for (int a = 0; a < 3; ++a) {
        boxes[h][0][a] = std::min(boxes[h][0][a], mesh.vertices[v][a]);
        boxes[h][1][a] = std::max(boxes[h][1][a], mesh.vertices[v][a]);
      }
  }
  // The hexes whose bounding box, grown by `margin`, holds p.
  const auto hexes_near = [&](const Vec3& p, double margin) {
    std::vector<int> near;
    for (std::size_t h = 0; h < boxes.size(); ++h) {
      bool in = true;
      for (int a = 0; a < 3; ++a) in &= p[a] >= boxes[h][0][a] - margin && p[a] <= boxes[h][1][a] + margin;
      if (in) near.push_back(static_cast<int>(h));
    }
    return near;
  };
  for (const Probe& probe : probes) {
    const Vec3& p = probe.at.xyz;
    const double scale = 1e-9 * (1.0 + vec3::norm(p));
    const std::vector<int> holding = hexes_near(p, scale);
    if (std::any_of(holding.begin(), holding.end(), [&](int h) { return hex_holds(mesh, h, p); })) {
      points.push_back(p);
      continue;
    }
    const SurfacePoint foot = mesh_boundary.closest(p);
    // A point on the bone's surface lies at most a millimetre or two outside the mesh; one much farther
    // away is a typo or a point of another frame, and its values would be those of an unrelated place.
    const double outside = mesh_boundary.inside(p) ? 0.0 : vec3::norm(vec3::sub(foot.point, p));
    if (coarse && outside > kProbeMaxOutsideMm) {
      char buf[400];
      std::snprintf(
          buf, sizeof buf,
          ": probe '%s' at (%.2f, %.2f, %.2f) lies %.2f mm outside the mesh (nearest boundary point "
          "(%.2f, %.2f, %.2f)); a probe must be in the bone or within %.0f mm of it: check its "
          "coordinates and units",
          probe.name.c_str(), p[0], p[1], p[2], outside, foot.point[0], foot.point[1], foot.point[2],
          kProbeMaxOutsideMm);
      throw InputError(point_place(probe.at, probe.where).str() + buf);
    }
    // The trilinear hexes bulge beyond their fan-triangulated faces by a fraction of a millimetre; 2 mm
    // more than the distance to the triangles takes in every hex the nearest point can lie in.
    std::vector<int> near = hexes_near(p, outside + 2.0);
    near.push_back(boundary.quad_face[foot.triangle / 4][0]);  // the hex behind the nearest triangle
    const PointInHex inside = nearest_point_inside(mesh, near, p);
    if (inside.hex < 0)
      throw RunError(point_place(probe.at, probe.where).str() + ": probe '" + probe.name +
                     "' could not be placed in a hex of the mesh near it; move it into the bone");
    points.push_back(inside.point);
  }
  return points;
}

// A coarser level's patch on its refinement: the 4 children of each of its quads, so that every level of
// the validation solves for the same patch. Selected anew on the fine boundary (facet centres within the
// radius), the patches changed with the level (the lateral bite's nut from 57 to 44 mm2), and the change
// between levels mixed that with the discretization error it is meant to show.
MeshPatch refined_patch(const HexMesh& fine, const RefinementMap& map, const MeshPatch& coarse) {
  MeshPatch patch;
  patch.name = coarse.name;
  for (const BoundaryQuad& quad : coarse.faces)
    for (const auto& child : child_quads(map, quad)) patch.faces.push_back(child);
  patch.area_mm2 = patch_area(fine, patch.faces);
  return patch;
}

// The coarse mesh's materials: a hex takes a region's material by its centre. A region that wins no hex
// changes nothing, which must not pass for a simulated implant or resorption site: InputError at its line.
void assign_materials(const Scenario& s, LevelResult& r) {
  const std::size_t regions = s.materials.regions.size();
  std::vector<int> hexes_of_region(regions, 0);
  std::vector<double> nearest_centre(regions, std::numeric_limits<double>::infinity());
  r.hex_material.reserve(r.mesh.hexes.size());
  for (std::size_t h = 0; h < r.mesh.hexes.size(); ++h) {
    const Vec3 centre = hex_centroid(r.mesh, static_cast<int>(h));
    const int region = region_at(s.materials, centre);
    const MaterialSpec& m = region < 0 ? s.materials.default_material
                                       : s.materials.regions[static_cast<std::size_t>(region)].material;
    r.hex_material.push_back({m.E_MPa, m.poisson});
    if (region >= 0) ++hexes_of_region[static_cast<std::size_t>(region)];
    for (std::size_t i = 0; i < regions; ++i)
      nearest_centre[i] = std::min(nearest_centre[i], distance_outside(s.materials.regions[i], centre));
  }
  r.region_hexes = hexes_of_region;
  for (std::size_t i = 0; i < regions; ++i) {
    if (hexes_of_region[i] > 0) continue;
    const MaterialRegion& region = s.materials.regions[i];
    char buf[300];
    if (nearest_centre[i] > 0)
      std::snprintf(
          buf, sizeof buf,
          "the nearest hex centre is %.1f mm outside it: move it into the bone or enlarge it, or make "
          "the mesh finer (mesh.target_hexes)",
          nearest_centre[i]);
    else
      std::snprintf(buf, sizeof buf,
                    "every hex centre inside it takes the material of a later region that overlaps it: "
                    "reorder or reshape the regions");
    const SourceLocation& at = region.shape == RegionShape::kSphere
                                   ? sphere_place(region.radius_at, region.center, region.where)
                                   : region.where;
    throw InputError(at.str() + ": material region '" + region.name + "' holds no hex of the " +
                     std::to_string(r.mesh.hexes.size()) + "-hex mesh, so it would change nothing; " + buf);
  }
}

// A refined level's materials: every hex takes its parent's (fine hex f lies in coarse hex f / 8,
// mesher/hex_refine.h), so that every level solves the same material distribution, as it does the same
// patches. By their own centres the children of a small region's hexes fell outside it: a 0.5 mm sphere
// holding one coarse hex held none at level 1, and a 1 mm box's 23 coarse hexes became 110 fine ones, not
// 184.
void inherit_materials(const LevelResult& coarser, LevelResult& r) {
  r.hex_material.reserve(r.mesh.hexes.size());
  for (std::size_t f = 0; f < r.mesh.hexes.size(); ++f) r.hex_material.push_back(coarser.hex_material[f / 8]);
  r.region_hexes = coarser.region_hexes;
  for (int& hexes : r.region_hexes) hexes *= 8;
}

// Everything of a level that depends only on its mesh: quality, patches and materials. A refined level
// (`coarser` given, the level it was refined from once) takes its patches and materials from that level's.
LevelResult prepare_level(const Scenario& s, int level, HexMesh mesh, const LevelResult* coarser = nullptr) {
  LevelResult r;
  r.level = level;
  r.mesh = std::move(mesh);
  r.quality = summarize_quality(r.mesh);
  const HexBoundary boundary = extract_boundary(r.mesh);
  const RefinementMap map = coarser ? refinement_map(coarser->mesh) : RefinementMap{};
  for (const Muscle& m : s.muscles) {
    if (m.activation <= 0) continue;
    r.muscle_patches.push_back(
        coarser ? refined_patch(r.mesh, map, coarser->muscle_patches[r.muscle_patches.size()])
                : select_patch(r.mesh, boundary, m.name, m.insertion.xyz, m.radius_mm,
                               sphere_place(m.radius_at, m.insertion, m.where),
                               "the insertion patch of muscle '" + m.name + "'"));
    r.muscle_forces.push_back(muscle_force(m));
  }
  for (const Support& sup : s.supports)
    r.support_patches.push_back(
        coarser ? refined_patch(r.mesh, map, coarser->support_patches[r.support_patches.size()])
                : select_patch(r.mesh, boundary, sup.name, sup.at.xyz, sup.radius_mm,
                               sphere_place(sup.radius_at, sup.at, sup.where), "support '" + sup.name + "'"));
  // Here, not before the solve: a contact that cannot push, or a probe far outside the mesh, must not cost a
  // study its earlier variants.
  r.contact_directions.assign(s.supports.size(), Vec3{0, 0, 0});
  for (std::size_t i = 0; i < s.supports.size(); ++i)
    if (s.supports[i].contact)
      r.contact_directions[i] = contact_direction(s.supports[i], r.support_patches[i], r.mesh);
  r.probe_points = probe_points_in_mesh(r.mesh, boundary, s.probes, /*coarse=*/coarser == nullptr);
  if (coarser)
    inherit_materials(*coarser, r);
  else
    assign_materials(s, r);
  return r;
}

// A node in the patches of two fixed supports that hold the same component gives its whole reaction to one
// of them (solver/elasticity.cc), so the reactions of both, and the bite force when only one is a
// bite, would depend on the order of the list (a bite patch reaching a condyle's patch took its whole
// reaction). InputError at the later support's line.
void require_fixed_supports_apart(const Scenario& s, const LevelResult& r) {
  std::map<int, std::size_t> first_support;  // node -> the first fixed support whose patch holds it
  for (std::size_t i = 0; i < s.supports.size(); ++i) {
    const Support& later = s.supports[i];
    if (later.spring_N_per_mm3) continue;         // a spring's reaction is its own traction
    std::map<std::size_t, std::set<int>> shared;  // earlier support -> the nodes it shares with this one
    for (const BoundaryQuad& face : r.support_patches[i].faces)
      for (int v : face) {
        const auto [it, fresh] = first_support.emplace(v, i);
        if (fresh || it->second == i) continue;
        const Support& earlier = s.supports[it->second];
        for (int a = 0; a < 3; ++a)
          if (earlier.fixed[a] && later.fixed[a]) shared[it->second].insert(v);
      }
    if (shared.empty()) continue;
    const auto& [j, nodes] = *shared.begin();
    const Support& earlier = s.supports[j];
    std::string components;
    for (int a = 0; a < 3; ++a)
      if (earlier.fixed[a] && later.fixed[a])
        components += std::string(components.empty() ? "" : ", ") + "xyz"[a];
    throw InputError(later.where.str() + ": the patch of support '" + later.name + "' shares " +
                     std::to_string(nodes.size()) + " nodes of the " + std::to_string(r.mesh.hexes.size()) +
                     "-hex mesh with that of support '" + earlier.name + "' (line " +
                     std::to_string(earlier.where.line) + "), and both fix " + components +
                     " there: the reaction of a shared node counts for one of them only, so the reactions" +
                     (earlier.bite != later.bite ? " and the bite force" : "") +
                     " would depend on the order of the supports; reduce radius_mm or move a point until the "
                     "patches are apart, or make them one support");
  }
}

// A muscle whose insertion patch lies wholly on nodes that fixed supports hold in x, y and z pulls on
// nothing that can move: its force goes straight into the supports' reactions (a support patch of 1000 mm
// gave zero displacement and the muscles' total as the bite force, with exit 0). InputError at the
// muscle's line.
void require_muscles_load_the_bone(const Scenario& s, const LevelResult& r) {
  std::map<int, std::array<bool, 3>> fixed;  // node -> components held by fixed supports
  for (std::size_t i = 0; i < s.supports.size(); ++i) {
    if (s.supports[i].spring_N_per_mm3) continue;
    for (const BoundaryQuad& face : r.support_patches[i].faces)
      for (int v : face)
        for (int a = 0; a < 3; ++a) fixed[v][a] = fixed[v][a] || s.supports[i].fixed[a];
  }
  const auto held = [&](int v) {
    const auto it = fixed.find(v);
    return it != fixed.end() && it->second[0] && it->second[1] && it->second[2];
  };
  std::size_t patch = 0;
  for (const Muscle& m : s.muscles) {
    if (m.activation <= 0) continue;
    const std::vector<BoundaryQuad>& faces = r.muscle_patches[patch++].faces;
    if (std::all_of(faces.begin(), faces.end(),
                    [&](const BoundaryQuad& f) { return std::all_of(f.begin(), f.end(), held); }))
      throw InputError(
          m.where.str() + ": the insertion patch of muscle '" + m.name +
          "' lies wholly on nodes that the fixed supports hold in x, y and z, so its force would go "
          "straight into their reactions and load nothing; reduce the supports' radius_mm or move "
          "their points off the insertion");
  }
}

// The separate bodies of a mesh: hexes connected through shared nodes (the fragments of a fractured
// mandible, or parts that the mesher could not join), numbered in the order of their first hex.
struct Bodies {
  int count = 0;
  std::vector<int> of_vertex;  // -1 for a vertex of no hex
  std::vector<long> hexes;     // per body
  std::vector<Vec3> centre;    // per body: the mean of its hexes' centroids
};

Bodies split_bodies(const HexMesh& mesh) {
  UnionFind pieces(mesh.vertices.size());
  for (const auto& hex : mesh.hexes)
    for (int c = 1; c < 8; ++c) pieces.unite(hex[0], hex[c]);
  Bodies b;
  std::map<std::size_t, int> body_of_root;
  b.of_vertex.assign(mesh.vertices.size(), -1);
  for (std::size_t h = 0; h < mesh.hexes.size(); ++h) {
    const auto [it, fresh] = body_of_root.emplace(pieces.find(mesh.hexes[h][0]), b.count);
    if (fresh) ++b.count, b.hexes.push_back(0), b.centre.push_back({0, 0, 0});
    const int body = it->second;
    ++b.hexes[body];
    b.centre[body] = vec3::add(b.centre[body], hex_centroid(mesh, static_cast<int>(h)));
    for (int v : mesh.hexes[h]) b.of_vertex[v] = body;
  }
  for (int body = 0; body < b.count; ++body)
    b.centre[body] = vec3::scale(b.centre[body], 1.0 / b.hexes[body]);
  return b;
}

// The components a support holds: all three for an elastic (spring) support, else its fixed ones.
std::array<bool, 3> held_components(const Support& support) {
  if (support.spring_N_per_mm3) return {true, true, true};
  return support.fixed;
}

// Per body, the components that the supports' patches on it hold; the supports flagged in `left_out` (the
// released contacts; empty: none) do not count.
std::vector<std::array<bool, 3>> held_per_body(const Scenario& s, const LevelResult& r, const Bodies& bodies,
                                               const std::vector<bool>& left_out = {}) {
  std::vector<std::array<bool, 3>> held(bodies.count, {false, false, false});
  for (std::size_t i = 0; i < s.supports.size(); ++i) {
    if (!left_out.empty() && left_out[i]) continue;
    for (const auto& face : r.support_patches[i].faces)
      for (int v : face) {
        std::array<bool, 3>& h = held[bodies.of_vertex[v]];
        for (int a = 0; a < 3; ++a) h[a] = h[a] || held_components(s.supports[i])[a];
      }
  }
  return held;
}

// Every separate body of the mesh must be held by supports in x, y and z; a body that nothing holds can
// move freely, the stiffness matrix is singular, and the solve would end in an equilibrium failure with
// displacements of 1e12 mm. InputError naming the body and the supports' lines.
void require_every_body_held(const Scenario& s, const LevelResult& r, const Bodies& bodies) {
  if (bodies.count < 2) return;
  const std::vector<std::array<bool, 3>> held = held_per_body(s, r, bodies);
  for (int b = 0; b < bodies.count; ++b) {
    if (held[b][0] && held[b][1] && held[b][2]) continue;
    std::string how = "is touched by no support";
    if (held[b][0] || held[b][1] || held[b][2]) {
      how = "is held by the supports only in";
      for (int a = 0; a < 3; ++a)
        if (held[b][a]) how += std::string(" ") + "xyz"[a];
    }
    char text[512];
    std::snprintf(
        text, sizeof text,
        "the mesh has %d separate bodies (parts that share no node), and body %d (%ld hexes, around "
        "(%.1f, %.1f, %.1f) mm) %s, so it can move freely and the problem is singular: add a "
        "support on it, or make the geometry one piece",
        bodies.count, b + 1, bodies.hexes[b], bodies.centre[b][0], bodies.centre[b][1], bodies.centre[b][2],
        how.c_str());
    throw InputError(s.supports.empty() ? std::string(text) : s.supports.front().where.str() + ": " + text);
  }
}

// Where a warning that the supports hold the bone weakly is named: at the fixed components that a study set
// (what it changed), else at the first support.
const SourceLocation& hold_place(const Scenario& s) {
  for (const Support& sup : s.supports)
    if (sup.fixed_at.line && sup.fixed_at.file != sup.where.file) return sup.fixed_at;
  return s.supports.front().where;
}

// The weakest rigid motion of every body against its supports; a warning for each weak one, after
// `context` ("level 1, with contact 'x' released: "). The supports flagged in `left_out` do not count.
std::vector<RigidMode> check_support_hold(const Scenario& s, const LevelResult& r, const Bodies& bodies,
                                          const std::vector<bool>& left_out = {},
                                          const std::string& context = "") {
  const HexMesh& mesh = r.mesh;
  std::vector<std::vector<HeldPoint>> held(bodies.count);
  for (std::size_t i = 0; i < s.supports.size(); ++i) {
    if (!left_out.empty() && left_out[i]) continue;
    std::vector<std::size_t> first(bodies.count);  // a patch may reach over several bodies
    std::vector<double> area(bodies.count, 0.0);
    for (int b = 0; b < bodies.count; ++b) first[b] = held[b].size();
    for (const BoundaryQuad& quad : r.support_patches[i].faces) {
      const int body = bodies.of_vertex[quad[0]];
      for_each_gauss_point(mesh, quad, [&](const std::array<double, 4>& N, double da) {
        Vec3 x{0, 0, 0};
        for (int a = 0; a < 4; ++a) x = vec3::add(x, vec3::scale(mesh.vertices[quad[a]], N[a]));
        held[body].push_back({x, da, held_components(s.supports[i])});
        area[body] += da;
      });
    }
    for (int b = 0; b < bodies.count; ++b)  // each support's weights sum to 1 on each body
      for (std::size_t k = first[b]; k < held[b].size(); ++k) held[b][k].weight /= area[b];
  }
  std::vector<std::vector<BodyPoint>> volume(bodies.count);
  for (std::size_t h = 0; h < mesh.hexes.size(); ++h)
    volume[bodies.of_vertex[mesh.hexes[h][0]]].push_back(
        {hex_centroid(mesh, static_cast<int>(h)), hex_volume(mesh, static_cast<int>(h))});
  std::vector<RigidMode> modes;
  for (int b = 0; b < bodies.count; ++b) {
    modes.push_back(weakest_rigid_mode(held[b], volume[b]));
    const RigidMode& m = modes.back();
    if (!is_weak(m)) continue;
    char text[256] = "";  // which body, when there are several
    if (bodies.count > 1)
      std::snprintf(text, sizeof text, "body %d of %d (%ld hexes, around (%.1f, %.1f, %.1f) mm): ", b + 1,
                    bodies.count, bodies.hexes[b], bodies.centre[b][0], bodies.centre[b][1],
                    bodies.centre[b][2]);
    // The points as the report writes them (format_point): a small component is not "-0.00".
    const std::string motion =
        "the supports hold the bone only weakly against a rotation about the axis through " +
        format_point(m.axis_point) + " mm along " + format_point(m.direction, 2) +
        ": only the extent of their patches resists it";
    // Numbers into a small buffer, the sentence as a string (a fixed buffer cut it when it grew).
    char values[64];
    std::snprintf(values, sizeof values, "hold %.2g, below %.2g", m.rho, kWeakSupportHold);
    warn(hold_place(s).str() + ": " + context + text + motion + " (" + values +
         "; the shipped scenarios 0.33 to 1.28), so the displacements and stresses depend mostly on how the "
         "patches resist that rotation. A body clamped at one end (a cantilever) is held so by design; "
         "otherwise fix more components of a support, or add a support away from that axis");
  }
  return modes;
}

// "'floor', 'shelf'": the names of the supports flagged in `flags`.
std::string flagged_names(const Scenario& s, const std::vector<bool>& flags) {
  std::string names;
  for (std::size_t i = 0; i < s.supports.size(); ++i)
    if (flags[i]) names += (names.empty() ? "'" : ", '") + s.supports[i].name + "'";
  return names;
}

// Without the released contacts, the supports must still hold every body in x, y and z (as the scenario's
// own check asks of all of them): else the loads lift it off its contacts and nothing holds it (the solve
// gave displacements of 1e12 mm and an equilibrium failure).
void check_held_without_released(const Scenario& s, const LevelResult& r, const std::vector<bool>& released) {
  if (std::none_of(released.begin(), released.end(), [](bool b) { return b; })) return;
  const Bodies bodies = split_bodies(r.mesh);
  const std::vector<std::array<bool, 3>> held = held_per_body(s, r, bodies, released);
  for (int b = 0; b < bodies.count; ++b) {
    std::string loose;
    for (int axis = 0; axis < 3; ++axis)
      if (!held[b][axis]) loose += std::string(loose.empty() ? "" : ", ") + "xyz"[axis];
    if (loose.empty()) continue;
    char body[160] = " it";
    if (bodies.count > 1)
      std::snprintf(body, sizeof body, " body %d of %d (%ld hexes, around (%.1f, %.1f, %.1f) mm)", b + 1,
                    bodies.count, bodies.hexes[b], bodies.centre[b][0], bodies.centre[b][1],
                    bodies.centre[b][2]);
    throw RunError(s.supports.front().where.str() + ": level " + std::to_string(r.level) + ": the contact " +
                   flagged_names(s, released) + " would pull the bone, and without it no support holds" +
                   body + " along " + loose +
                   ": the loads lift the bone off its contacts; check the muscles' directions, or hold the "
                   "bone with a support that is not a contact");
  }
}

// solve_elasticity(p) on `dofs` degrees of freedom. The direct solver needs address space that an
// address-space limit (ulimit -v) may not leave: when solver.linear_solver is auto, it chose the direct
// solver for a small problem, and CG with AMG, which gives the same answer with far less memory, solves
// instead (too little room before the solve, or MUMPS failing in it: under ulimit -v 1.0 GB it did); the
// run's CG iterations then show it. A scenario that asked for the direct solver is refused before the solve.
ElasticitySolution solve_or_fall_back(const Scenario& s, ElasticityProblem& p, int level, long long dofs) {
  const bool automatic = s.solver.linear_solver == LinearSolverChoice::kAuto;
  const auto fall_back = [&](const std::string& why) {
    warn("level " + std::to_string(level) + " (" + std::to_string(dofs) + " degrees of freedom): " + why +
         "; solving with CG and AMG instead (solver.linear_solver: auto)");
    p.solver.linear_solver = LinearSolver::kCgAmg;
  };
  if (p.solver.linear_solver == LinearSolver::kDirect) {
    // Checked again here: the run maps more by now than when require_levels_fit_memory() looked.
    if (const std::string problem = direct_solver_room_problem(static_cast<double>(dofs)); !problem.empty()) {
      if (!automatic) refuse_direct_solver(s, level, static_cast<double>(dofs), problem);
      fall_back(problem);
    }
  }
  try {
    return solve_elasticity(p);
  } catch (const DirectSolverError& e) {
    if (!automatic) throw;
    fall_back(e.what());
    return solve_elasticity(p);
  }
}

void solve_level(const Scenario& s, LevelResult& r) {
  ElasticityProblem p;
  p.mesh = &r.mesh;
  p.hex_material = r.hex_material;
  for (std::size_t i = 0; i < r.muscle_patches.size(); ++i)
    p.loads.push_back({r.muscle_patches[i].name, r.muscle_patches[i].faces, r.muscle_forces[i]});
  for (std::size_t i = 0; i < s.supports.size(); ++i) {
    const Support& sup = s.supports[i];
    SupportPatch patch;
    patch.name = sup.name;
    patch.faces = r.support_patches[i].faces;
    patch.is_bite = sup.bite;
    if (sup.spring_N_per_mm3) {
      patch.spring_stiffness = *sup.spring_N_per_mm3;  // an elastic foundation acts on all components
    } else {
      patch.components = sup.fixed;
    }
    p.supports.push_back(std::move(patch));
  }
  p.probes = r.probe_points;
  p.degree = s.solver.degree;
  const long long dofs = count_dofs(r.mesh, s.solver.degree);
  switch (s.solver.linear_solver) {
    case LinearSolverChoice::kAuto:
      p.solver.linear_solver = dofs < kDirectSolverMaxDofs ? LinearSolver::kDirect : LinearSolver::kCgAmg;
      break;
    case LinearSolverChoice::kCgAmg:
      p.solver.linear_solver = LinearSolver::kCgAmg;
      break;
    case LinearSolverChoice::kDirect:
      p.solver.linear_solver = LinearSolver::kDirect;
      break;
  }
  p.solver.relative_tolerance = s.solver.tolerance;
  p.solver.max_iterations = s.solver.max_iterations;

  // One-sided contacts: solved held, released where they would pull, and solved again until the set
  // settles (app/contact_supports.h); a set seen before would cycle.
  const std::vector<SupportPatch> all_supports = std::move(p.supports);
  std::vector<bool> released(s.supports.size(), false);
  std::set<std::vector<bool>> seen;
  const auto start = std::chrono::steady_clock::now();
  for (;;) {
    seen.insert(released);
    p.supports.clear();
    for (std::size_t i = 0; i < s.supports.size(); ++i)
      if (!released[i]) p.supports.push_back(all_supports[i]);
    check_held_without_released(s, r, released);
    Progress progress("solve level " + std::to_string(r.level));
    try {
      r.solution = solve_or_fall_back(s, p, r.level, dofs);
    } catch (const DirectSolverError& e) {
      throw RunError(linear_solver_place(s) + ": level " + std::to_string(r.level) + " (" +
                     std::to_string(dofs) + " degrees of freedom): " + e.what() +
                     "; give the process more memory, or set solver.linear_solver: cg_amg (or auto), which "
                     "needs far less");
    } catch (const RunError& e) {
      // The solver speaks of its own options: name the level and the scenario's settings.
      char settings[160];
      std::snprintf(settings, sizeof settings,
                    "; the scenario's solver.max_iterations is %d, solver.tolerance %g",
                    s.solver.max_iterations, s.solver.tolerance);
      // At the setting that ends the iterations when one was written (a study's own line), else the
      // `solver` mapping.
      const SourceLocation& at =
          s.solver.max_iterations_at.line ? s.solver.max_iterations_at : s.solver.where;
      throw RunError((at.line ? at.str() : s.path) + ": level " + std::to_string(r.level) + " (" +
                     std::to_string(dofs) + " degrees of freedom): " + e.what() + settings);
    }
    progress.finish(std::to_string(r.solution.dofs) + " DoFs");
    // The reactions in the scenario's order, the released contacts' zero.
    std::vector<SupportReaction> reactions;
    for (std::size_t i = 0, k = 0; i < s.supports.size(); ++i)
      reactions.push_back(released[i]
                              ? SupportReaction{s.supports[i].name, s.supports[i].bite, {0, 0, 0}, 0, true}
                              : r.solution.reactions[k++]);
    r.solution.reactions = std::move(reactions);
    const std::vector<bool> before = released;
    if (!update_released_contacts(s.supports, r.support_patches, r.contact_directions, r.solution, released))
      break;
    std::vector<bool> changed(s.supports.size(), false);
    for (std::size_t i = 0; i < s.supports.size(); ++i) {
      changed[i] = released[i] != before[i];
      if (changed[i])
        info("level " + std::to_string(r.level) + ": contact '" + s.supports[i].name +
             (released[i] ? "' would pull the bone: released" : "' touches again: held") + ", solving again");
    }
    if (seen.count(released) != 0) {
      const std::size_t first =
          static_cast<std::size_t>(std::find(changed.begin(), changed.end(), true) - changed.begin());
      throw RunError(
          s.supports[first].where.str() + ": level " + std::to_string(r.level) + ": the contact " +
          flagged_names(s, changed) +
          " does not settle: held, it pulls the bone; released, its patch moves into what it touches "
          "(a patch that tilts: part of it pulls, part pushes): make its patch smaller, or remove "
          "'contact'");
    }
  }
  r.seconds_solve = seconds_since(start);
}

}  // namespace

double patch_area(const HexMesh& mesh, const std::vector<BoundaryQuad>& faces) {
  double area = 0.0;
  for (const BoundaryQuad& quad : faces)
    for_each_gauss_point(mesh, quad, [&](const std::array<double, 4>&, double da) { area += da; });
  return area;
}

std::vector<std::pair<int, Vec3>> consistent_nodal_forces(const HexMesh& mesh,
                                                          const std::vector<BoundaryQuad>& faces,
                                                          const Vec3& traction) {
  std::map<int, Vec3> forces;
  for (const BoundaryQuad& quad : faces)
    for_each_gauss_point(mesh, quad, [&](const std::array<double, 4>& N, double da) {
      for (int a = 0; a < 4; ++a) {
        Vec3& f = forces.try_emplace(quad[a], Vec3{0, 0, 0}).first->second;
        for (int d = 0; d < 3; ++d) f[d] += N[a] * traction[d] * da;
      }
    });
  return {forces.begin(), forces.end()};
}

RunResult prepare_run(Scenario scenario, int levels, bool in_study) {
  const auto start = std::chrono::steady_clock::now();
  RunResult result;
  Geometry geometry;
  {
    Progress progress("geometry");
    geometry = build_geometry(scenario);
    resolve_points(scenario, geometry.landmarks);
    result.seconds_geometry = seconds_since(start);
    progress.finish(std::to_string(geometry.surface.triangles.size()) + " triangles");
  }

  // Level 0: the coarse mesh. A mesh that stays inverted cannot be solved on; say where.
  HexMesh coarse;
  double seconds_mesh = 0.0;
  {
    Progress progress("mesh");
    const auto t = std::chrono::steady_clock::now();
    coarse = scenario.mesh.method == MeshMethod::kSheets
                 ? mesh_by_sheets(scenario, geometry, &result.fidelity)
                 : mesh_by_grid(scenario, geometry, &result.fidelity, &result.mesh_core);
    seconds_mesh = seconds_since(t);
    progress.finish(std::to_string(coarse.hexes.size()) + " hexes");
  }
  result.levels.push_back(prepare_level(scenario, 0, coarse));
  result.levels.back().seconds_mesh = seconds_mesh;
  {
    const Bodies bodies = split_bodies(result.levels.back().mesh);  // refinement keeps the bodies
    require_every_body_held(scenario, result.levels.back(), bodies);
    result.support_hold = check_support_hold(scenario, result.levels.back(), bodies);
  }
  require_fixed_supports_apart(scenario, result.levels.back());
  require_muscles_load_the_bone(scenario, result.levels.back());
  require_levels_fit_memory(scenario, coarse, levels, in_study);

  // Every patch of every level is selected before the first solve, so a scenario error never costs a solve.
  std::unique_ptr<SurfaceProjector> projector;
  if (levels > 0) projector = std::make_unique<SurfaceProjector>(geometry.surface);
  for (int level = 1; level <= levels; ++level) {
    Progress progress("refine level " + std::to_string(level));
    const auto t = std::chrono::steady_clock::now();
    RefineReport report;
    RefineOptions options;
    options.fit_volume = scenario.mesh.fit_volume;  // the coarse nodes keep their (fitted) places
    HexMesh fine = refine_to_surface(result.levels.back().mesh, projector.get(), options, &report);
    if (report.after.inverted > 0)
      throw RunError(scenario.path + ": refinement level " + std::to_string(level) + " left " +
                     inverted_hexes_text(fine) +
                     "; run with fewer validation levels (--levels) or another mesh.target_hexes");
    const double seconds = seconds_since(t);
    result.levels.push_back(prepare_level(scenario, level, std::move(fine), &result.levels.back()));
    require_fixed_supports_apart(scenario, result.levels.back());
    result.levels.back().seconds_mesh = seconds;
    progress.finish(std::to_string(result.levels.back().mesh.hexes.size()) + " hexes");
  }

  result.scenario = std::move(scenario);
  result.seconds_total = seconds_since(start);
  return result;
}

void solve_run(RunResult& result) {
  const auto start = std::chrono::steady_clock::now();
  const Scenario& s = result.scenario;
  for (LevelResult& level : result.levels) {
    solve_level(s, level);
    // Every probe is placed in a hex before the solve (probe_points_in_mesh); one the solver still does not
    // find has no values, and its zeros in results.json must not pass for measured ones.
    for (std::size_t i = 0; i < s.probes.size(); ++i)
      if (!level.solution.probes[i].found)
        warn(point_place(s.probes[i].at, s.probes[i].where).str() + ": probe '" + s.probes[i].name +
             "' was not found in the level " + std::to_string(level.level) +
             " mesh: it has no values (found: false in results.json); move it into the bone");
    // The hold measured before the solve was of every support; with contacts released the bone may hang
    // on a few patches (an opening load lifting the teeth off their contacts): measured again, and
    // results.json's support_hold is then of the coarse level as solved.
    std::vector<bool> released(s.supports.size(), false);
    for (std::size_t i = 0; i < s.supports.size(); ++i) released[i] = level.solution.reactions[i].released;
    if (std::none_of(released.begin(), released.end(), [](bool b) { return b; })) continue;
    std::vector<RigidMode> hold =
        check_support_hold(s, level, split_bodies(level.mesh), released,
                           "level " + std::to_string(level.level) + ", with the contact " +
                               flagged_names(s, released) + " released: ");
    if (level.level == 0) result.support_hold = std::move(hold);
  }
  result.seconds_total += seconds_since(start);
}

TrustLimits trust_limits(const RunResult& result) {
  const double size = largest_extent(result.levels.front().mesh.vertices);
  return {kEquilibriumTolerance, kMaxDisplacementFraction * size, size};
}

void require_trustworthy(const RunResult& result, const std::string& results) {
  const TrustLimits limits = trust_limits(result);
  const double size = limits.bone_size_mm;
  for (const LevelResult& l : result.levels) {
    if (!(l.solution.equilibrium_residual <= limits.equilibrium_residual)) {
      // %.3g: std::to_string printed a residual of 3e-8 as "0.000000 > 1e-8".
      const SolverSpec& solver = result.scenario.solver;
      char text[160];
      std::snprintf(text, sizeof text, "relative residual %.3g > 1e-8", l.solution.equilibrium_residual);
      char tolerance[32];
      std::snprintf(tolerance, sizeof tolerance, "%g", solver.tolerance);
      // The place first, as every scenario message has it: inside the parentheses a study's note ("variant
      // 'tol' of study cg.yaml") read as part of the value.
      const SourceLocation& at = solver.tolerance_at.line ? solver.tolerance_at : solver.where;
      throw RunError((at.line ? at.str() + ": " : std::string()) + "level " + std::to_string(l.level) +
                     ": applied forces and reactions do not balance (" + text + "); " + results +
                     " are not trustworthy: tighten solver.tolerance (" + tolerance +
                     (at.line ? std::string() : std::string(", the default")) + ")");
    }
    if (!(l.solution.max_displacement <= limits.max_displacement_mm)) {
      char text[400];
      std::snprintf(text, sizeof text,
                    "level %d: the largest displacement, %.3g mm, is more than %.0f %% of the bone's size "
                    "(%.1f mm), but linear elasticity holds only for small displacements",
                    l.level, l.solution.max_displacement, 100 * kMaxDisplacementFraction, size);
      // At the modulus, the likeliest slip (1e-6 for 11000), as the equilibrium failure names its tolerance;
      // without one, the file, so that a study's or a script's log says which scenario failed.
      const SourceLocation& E_at = result.scenario.materials.default_material.E_MPa_at;
      throw RunError((E_at.line ? E_at.str() : result.scenario.path) + ": " + text + "; " + results +
                     " are meaningless: check materials E_MPa (in MPa, cortical bone about 11000), the "
                     "muscles' max_force_N (in N) and that the supports hold the bone");
    }
  }
}

RunResult run_pipeline(Scenario scenario, int levels) {
  RunResult result = prepare_run(std::move(scenario), levels);
  solve_run(result);
  return result;
}

}  // namespace hexbite
