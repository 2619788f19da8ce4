#include "app/run_outputs.h"

#include <mpi.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <regex>
#include <sstream>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/markup_escape.h"
#include "common/number_format.h"
#include "mesher/grid_mesher.h"
#include "mesher/hex_mesh_io.h"
#include "postprocess/quality_json.h"
#include "solver/mpi_session.h"

namespace hexbite {

namespace {

using nlohmann::json;

json vec(const Vec3& v) {
  return json::array({v[0], v[1], v[2]});
}

double norm(const Vec3& v) {
  return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

// The figures of one level; results.json repeats them per level under validation.levels, and the top level
// holds those of level 0 (the mesh of mesh.vtu, solution.vtu and model.inp).
json level_figures(const Scenario& s, const LevelResult& l) {
  const ElasticitySolution& u = l.solution;
  json reactions = json::object();
  // A refined level carries its coarser level's patches, each quad split into 4 (running.md, step 6), and
  // its area changes with the new boundary nodes' projection; it is given per level (the supports' list
  // gives the coarse level's only).
  for (std::size_t i = 0; i < u.reactions.size(); ++i) {
    const SupportReaction& r = u.reactions[i];
    reactions[r.name] = {{"force_N", vec(r.force)},
                         {"magnitude_N", r.magnitude},
                         {"bite", r.is_bite},
                         {"released", r.released},
                         {"patch_area_mm2", l.support_patches[i].area_mm2},
                         {"facets", l.support_patches[i].faces.size()}};
  }
  json probes = json::object();
  for (std::size_t i = 0; i < s.probes.size(); ++i) {
    const ProbeValue& p = u.probes[i];
    const Vec3& requested = s.probes[i].at.xyz;
    const double moved =
        std::hypot(p.point[0] - requested[0], p.point[1] - requested[1], p.point[2] - requested[2]);
    probes[s.probes[i].name] = {
        {"at", vec(p.point)}, {"requested_at", vec(requested)},         {"moved_mm", moved},
        {"found", p.found},   {"displacement_mm", vec(p.displacement)}, {"von_mises_MPa", p.von_mises}};
  }
  return {{"level", l.level},
          {"hexes", l.mesh.hexes.size()},
          {"nodes", l.mesh.vertices.size()},
          {"dofs", u.dofs},
          {"reactions", reactions},
          {"bite_force_N", s.outputs.bite_force ? json(u.bite_force) : json()},
          {"applied_force_N", vec(u.applied_force)},
          {"equilibrium_residual", u.equilibrium_residual},
          {"max_displacement_mm", u.max_displacement},
          {"max_displacement_at", vec(u.max_displacement_at)},
          {"von_mises_max_MPa", u.von_mises_max},
          {"von_mises_p99_MPa", u.von_mises_p99},
          {"von_mises_max_at", vec(u.von_mises_max_at)},
          {"strain_energy_mJ", u.strain_energy},
          {"probes", probes},
          {"solver", {{"iterations", u.iterations}, {"seconds", u.seconds}, {"ranks", u.ranks}}}};
}

// (fine - coarse) / |fine| between the last two levels; null without a validation level.
json relative_change(const RunResult& r, double (*figure)(const ElasticitySolution&)) {
  if (r.levels.size() < 2) return json();
  const double fine = figure(r.levels.back().solution);
  const double coarse = figure(r.levels[r.levels.size() - 2].solution);
  return fine == 0.0 ? json() : json((fine - coarse) / std::abs(fine));
}

// An Abaqus set name from a scenario name: letters, digits and '_' only, upper case (CalculiX folds case).
std::string set_name(const std::string& prefix, const std::string& name) {
  std::string out = prefix;
  for (char c : name) out += std::isalnum(static_cast<unsigned char>(c)) ? std::toupper(c) : '_';
  return out.substr(0, 79);  // the longest that CalculiX prints (write_inp)
}

std::vector<int> patch_nodes(const MeshPatch& patch) {
  std::vector<int> nodes;
  for (const BoundaryQuad& q : patch.faces) nodes.insert(nodes.end(), q.begin(), q.end());
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  return nodes;
}

// model_mesh.inp (nodes, elements, sets, via write_inp) and model.inp (material, supports, loads, step),
// which includes the former. The loads are the consistent nodal forces of the muscles' uniform tractions,
// the load vector the Q1 solver assembles, summed per node over all muscles.
void write_inp_deck(const RunResult& r, const std::string& dir) {
  const LevelResult& l = r.levels.front();
  const Scenario& s = r.scenario;

  // One element set per distinct material, in order of first appearance.
  std::vector<Material> materials;
  std::vector<IndexSet> element_sets;
  for (std::size_t h = 0; h < l.hex_material.size(); ++h) {
    const Material& m = l.hex_material[h];
    std::size_t k = 0;
    while (k < materials.size() && !(materials[k].youngs_modulus == m.youngs_modulus &&
                                     materials[k].poisson_ratio == m.poisson_ratio))
      ++k;
    if (k == materials.size()) {
      materials.push_back(m);
      element_sets.push_back({"MAT_" + std::to_string(k + 1), {}});
    }
    element_sets[k].ids.push_back(static_cast<int>(h));
  }
  std::vector<IndexSet> node_sets;
  for (std::size_t i = 0; i < s.supports.size(); ++i)
    node_sets.push_back({set_name("SUP_", s.supports[i].name), patch_nodes(l.support_patches[i])});
  for (const MeshPatch& m : l.muscle_patches) node_sets.push_back({set_name("MUS_", m.name), patch_nodes(m)});
  write_inp(dir + "/model_mesh.inp", l.mesh, node_sets, element_sets);

  std::map<int, Vec3> loads;
  for (std::size_t i = 0; i < l.muscle_patches.size(); ++i) {
    const MeshPatch& m = l.muscle_patches[i];
    const Vec3& f = l.muscle_forces[i];
    const Vec3 traction{f[0] / m.area_mm2, f[1] / m.area_mm2, f[2] / m.area_mm2};
    for (const auto& [node, force] : consistent_nodal_forces(l.mesh, m.faces, traction))
      for (int d = 0; d < 3; ++d) loads.try_emplace(node, Vec3{0, 0, 0}).first->second[d] += force[d];
  }

  std::ostringstream out;
  out << "** hexbite run: scenario " << s.name << ", the coarse mesh (level 0) with C3D8 elements\n"
      << "** units: mm, N, MPa. Solve with: ccx -i model (in this folder)\n"
      << "*INCLUDE, INPUT=model_mesh.inp\n";
  for (std::size_t k = 0; k < materials.size(); ++k) {
    const std::string name = element_sets[k].name;
    out << "*MATERIAL, NAME=" << name << "\n*ELASTIC\n"
        << format_inp_number(materials[k].youngs_modulus) << ", "
        << format_inp_number(materials[k].poisson_ratio) << '\n'
        << "*SOLID SECTION, ELSET=" << name << ", MATERIAL=" << name << '\n';
  }
  out << "** fixed supports (zero displacement in the fixed components)\n";
  // The deck is of the solved state: a contact released at level 0 (it would pull the bone) is left out.
  for (std::size_t i = 0; i < s.supports.size(); ++i)
    if (l.solution.reactions[i].released)
      out << "** contact " << s.supports[i].name << " released: it would pull the bone\n";
  out << "*BOUNDARY\n";
  for (std::size_t i = 0; i < s.supports.size(); ++i)
    for (int d = 0; d < 3; ++d)
      if (s.supports[i].fixed[d] && !l.solution.reactions[i].released)
        out << node_sets[i].name << ", " << d + 1 << ", " << d + 1 << '\n';
  out << "*STEP\n*STATIC\n** muscle loads: consistent nodal forces of the uniform tractions\n*CLOAD\n";
  for (const auto& [node, f] : loads)
    for (int d = 0; d < 3; ++d)
      if (f[d] != 0.0) out << node + 1 << ", " << d + 1 << ", " << format_inp_number(f[d]) << '\n';
  out << "*NODE PRINT, NSET=NALL\nU\n";
  for (std::size_t i = 0; i < s.supports.size(); ++i)
    out << "*NODE PRINT, NSET=" << node_sets[i].name << ", TOTALS=ONLY\nRF\n";
  out << "*END STEP\n";
  write_file_atomically(dir + "/model.inp", out.str());
}

// The solution arrays of a level, on its whole mesh.
void solution_arrays(const LevelResult& l, std::vector<MeshArray>* cells, std::vector<MeshArray>* points) {
  const ElasticitySolution& u = l.solution;
  const std::size_t n = l.mesh.vertices.size(), m = l.mesh.hexes.size();
  MeshArray displacement{"displacement", 3, {}}, vm_point{"von_mises", 1, u.vertex_von_mises};
  for (const Vec3& d : u.vertex_displacement)
    displacement.values.insert(displacement.values.end(), d.begin(), d.end());
  // Patch membership: the index of the support (muscle) in the scenario's order, -1 elsewhere; a node on
  // two patches shows the later one.
  MeshArray support_id{"support_id", 1, std::vector<double>(n, -1.0)};
  MeshArray muscle_id{"muscle_id", 1, std::vector<double>(n, -1.0)};
  for (std::size_t i = 0; i < l.support_patches.size(); ++i)
    for (int v : patch_nodes(l.support_patches[i])) support_id.values[v] = static_cast<double>(i);
  for (std::size_t i = 0; i < l.muscle_patches.size(); ++i)
    for (int v : patch_nodes(l.muscle_patches[i])) muscle_id.values[v] = static_cast<double>(i);
  *points = {displacement, vm_point, support_id, muscle_id};

  MeshArray stress{"stress", 6, {}}, principal{"principal_stress", 3, {}};
  MeshArray E{"E_MPa", 1, {}}, nu{"poisson", 1, {}};
  for (std::size_t h = 0; h < m; ++h) {
    stress.values.insert(stress.values.end(), u.hex_stress[h].begin(), u.hex_stress[h].end());
    principal.values.insert(principal.values.end(), u.hex_principal_stress[h].begin(),
                            u.hex_principal_stress[h].end());
    E.values.push_back(l.hex_material[h].youngs_modulus);
    nu.values.push_back(l.hex_material[h].poisson_ratio);
  }
  *cells = {
      {"von_mises", 1, u.hex_von_mises}, {"von_mises_max", 1, u.hex_von_mises_max}, stress, principal, E, nu};
}

// Piece `rank` of `ranks`: the contiguous block of hexes [m rank / ranks, m (rank + 1) / ranks) on the
// vertices they use (renumbered in ascending order), with the arrays sliced to match.
void slice(const HexMesh& mesh, int rank, int ranks, std::vector<MeshArray>* cells,
           std::vector<MeshArray>* points, HexMesh* piece) {
  const std::size_t m = mesh.hexes.size();
  const std::size_t first = m * rank / ranks, last = m * (rank + 1) / ranks;
  std::vector<int> new_id(mesh.vertices.size(), -1);
  for (std::size_t h = first; h < last; ++h)
    for (int v : mesh.hexes[h]) new_id[v] = 0;
  std::vector<int> old_id;
  for (std::size_t v = 0; v < new_id.size(); ++v)
    if (new_id[v] == 0) {
      new_id[v] = static_cast<int>(old_id.size());
      old_id.push_back(static_cast<int>(v));
    }
  piece->vertices.clear();
  piece->hexes.clear();
  for (int v : old_id) piece->vertices.push_back(mesh.vertices[v]);
  for (std::size_t h = first; h < last; ++h) {
    std::array<int, 8> hex;
    for (int k = 0; k < 8; ++k) hex[k] = new_id[mesh.hexes[h][k]];
    piece->hexes.push_back(hex);
  }
  for (MeshArray& a : *cells)
    a.values =
        std::vector<double>(a.values.begin() + first * a.components, a.values.begin() + last * a.components);
  for (MeshArray& a : *points) {
    std::vector<double> values;
    for (int v : old_id)
      values.insert(values.end(), a.values.begin() + v * a.components,
                    a.values.begin() + (v + 1) * a.components);
    a.values = std::move(values);
  }
}

// The .pvtu that ties the pieces together (the arrays' names and sizes, the pieces' file names).
std::string pvtu_text(const std::vector<MeshArray>& cells, const std::vector<MeshArray>& points,
                      const std::vector<std::string>& pieces) {
  std::ostringstream out;
  out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"PUnstructuredGrid\" version=\"1.0\" "
         "byte_order=\"LittleEndian\" header_type=\"UInt64\">\n  <PUnstructuredGrid GhostLevel=\"0\">\n";
  out << "    <PPointData>\n";
  for (const MeshArray& a : points)
    out << "      <PDataArray type=\"Float64\" Name=\"" << markup_escape(a.name) << "\" NumberOfComponents=\""
        << a.components << "\"/>\n";
  out << "    </PPointData>\n    <PCellData>\n";
  for (const char* name : kVtuQualityArrays)
    out << "      <PDataArray type=\"Float64\" Name=\"" << name << "\" NumberOfComponents=\"1\"/>\n";
  for (const MeshArray& a : cells)
    out << "      <PDataArray type=\"Float64\" Name=\"" << markup_escape(a.name) << "\" NumberOfComponents=\""
        << a.components << "\"/>\n";
  out << "    </PCellData>\n    <PPoints>\n      <PDataArray type=\"Float64\" NumberOfComponents=\"3\"/>\n"
         "    </PPoints>\n";
  for (const std::string& p : pieces) out << "    <Piece Source=\"" << markup_escape(p) << "\"/>\n";
  out << "  </PUnstructuredGrid>\n</VTKFile>\n";
  return out.str();
}

// Writes the solution of one level as DIR/STEM.vtu (one rank) or DIR/STEM.pvtu with pieces
// DIR/STEM_<rank>.vtu written by each rank (several ranks). Returns the files written (rank 0's view).
std::vector<std::string> write_solution(const LevelResult& l, const std::string& dir,
                                        const std::string& stem) {
  std::vector<MeshArray> cells, points;
  solution_arrays(l, &cells, &points);
  const int rank = MpiSession::rank(), ranks = MpiSession::size();
  if (ranks == 1) {
    write_vtu(dir + "/" + stem + ".vtu", l.mesh, cells, points);
    return {stem + ".vtu"};
  }
  std::vector<std::string> pieces;
  for (int p = 0; p < ranks; ++p) pieces.push_back(stem + "_" + std::to_string(p) + ".vtu");
  const std::vector<MeshArray> all_cells = cells, all_points = points;
  HexMesh piece;
  slice(l.mesh, rank, ranks, &cells, &points, &piece);
  write_vtu(dir + "/" + pieces[rank], piece, cells, points);
  if (rank != 0) return {};
  write_file_atomically(dir + "/" + stem + ".pvtu", pvtu_text(all_cells, all_points, pieces));
  pieces.insert(pieces.begin(), stem + ".pvtu");
  return pieces;
}

double bite_force(const ElasticitySolution& u) {
  return u.bite_force;
}
double max_displacement(const ElasticitySolution& u) {
  return u.max_displacement;
}
double strain_energy(const ElasticitySolution& u) {
  return u.strain_energy;
}

}  // namespace

void check_inp_exportable(const Scenario& scenario) {
  for (const Support& s : scenario.supports)
    if (s.spring_N_per_mm3)
      throw InputError(
          (s.spring_at.line ? s.spring_at : s.where).str() + ": support '" + s.name +
          "' is a spring (spring_N_per_mm3), which the CalculiX export does not write; "
          "use fixed components for the comparison with CalculiX, or leave the export out (--export inp, "
          "outputs.inp)");
  // Names that differ only in case or in characters other than letters and digits ("condyle" and
  // "CONDYLE", "left condyle" and "left_condyle") give one set name: write_inp refused it after the solve
  // (exit 1, mesh.vtu already written, no results.json). Refused here, before anything runs.
  std::map<std::string, std::pair<std::string, SourceLocation>> taken;  // set name -> (what, where)
  const auto claim = [&](const std::string& set, const std::string& what, const SourceLocation& where) {
    const auto [it, fresh] = taken.emplace(set, std::make_pair(what, where));
    if (!fresh)
      throw InputError(
          where.str() + ": " + what + " and " + it->second.first + " (line " +
          std::to_string(it->second.second.line) + ") get the same CalculiX set name " + set +
          " (set names keep letters, digits and '_', in upper case, up to 79 characters), so the "
          "export would mix their nodes; rename one of them, or leave the export out (--export inp, "
          "outputs.inp)");
  };
  for (const Support& s : scenario.supports)
    claim(set_name("SUP_", s.name), "support '" + s.name + "'", s.where);
  for (const Muscle& m : scenario.muscles)
    if (m.activation > 0) claim(set_name("MUS_", m.name), "muscle '" + m.name + "'", m.where);
}

json results_json(const RunResult& r, double seconds_output) {
  const Scenario& s = r.scenario;
  const LevelResult& coarse = r.levels.front();
  json j = level_figures(s, coarse);
  j.erase("level");
  j.erase("hexes");
  j.erase("nodes");
  j.erase("dofs");
  j["scenario"] = s.name;
  j["scenario_file"] = s.path;
  j["hexbite_version"] = HEXBITE_VERSION;
  j["mesh_method"] = s.mesh.method == MeshMethod::kSheets ? "sheets" : "grid";
  j["mesh"] = {{"hexes", coarse.mesh.hexes.size()},
               {"nodes", coarse.mesh.vertices.size()},
               {"dofs", coarse.solution.dofs},
               {"degree", s.solver.degree},
               {"quality", quality_to_json(coarse.quality, hex_mesh_volume(coarse.mesh))},
               {"fidelity", fidelity_to_json(r.fidelity)}};
  if (!r.mesh_core.empty()) j["mesh"]["core"] = r.mesh_core;
  // The model as solved, so that a report (hexbite report) can say what was simulated without the scenario.
  json regions = json::array();
  for (std::size_t i = 0; i < s.materials.regions.size(); ++i) {
    const MaterialRegion& m = s.materials.regions[i];
    regions.push_back({{"name", m.name},
                       {"E_MPa", m.material.E_MPa},
                       {"poisson", m.material.poisson},
                       {"hexes", coarse.region_hexes[i]}});
  }
  j["materials"] = {
      {"default",
       {{"E_MPa", s.materials.default_material.E_MPa}, {"poisson", s.materials.default_material.poisson}}},
      {"regions", regions}};
  json muscles = json::array();
  std::size_t active = 0;
  for (const Muscle& m : s.muscles) {
    if (m.activation <= 0) continue;  // the patches and forces of the active muscles, in scenario order
    muscles.push_back({{"name", coarse.muscle_patches[active].name},
                       {"activation", m.activation},
                       {"force_N", vec(coarse.muscle_forces[active])},
                       {"magnitude_N", norm(coarse.muscle_forces[active])},
                       {"patch_area_mm2", coarse.muscle_patches[active].area_mm2},
                       {"facets", coarse.muscle_patches[active].faces.size()}});
    ++active;
  }
  j["muscles"] = muscles;
  json supports = json::array();
  for (std::size_t i = 0; i < s.supports.size(); ++i) {
    const Support& sup = s.supports[i];
    json fixed = json::array();
    for (int k = 0; k < 3 && !sup.spring_N_per_mm3; ++k)
      if (sup.fixed[static_cast<std::size_t>(k)]) fixed.push_back(std::string(1, "xyz"[k]));
    supports.push_back({{"name", sup.name},
                        {"center_mm", vec(sup.at.xyz)},
                        {"radius_mm", sup.radius_mm},
                        {"fixed", fixed},
                        {"spring_N_per_mm3", sup.spring_N_per_mm3 ? json(*sup.spring_N_per_mm3) : json()},
                        {"bite", sup.bite},
                        {"contact", sup.contact},
                        {"patch_area_mm2", coarse.support_patches[i].area_mm2},
                        {"facets", coarse.support_patches[i].faces.size()}});
  }
  j["supports"] = supports;
  json hold = json::array();
  for (const RigidMode& m : r.support_hold) {
    json body = {{"hold", m.rho}, {"weak", is_weak(m)}};
    body["weakest_motion"] = m.rotation ? "rotation" : "translation";
    body["direction"] = vec(m.direction);
    if (m.rotation) body["axis_point_mm"] = vec(m.axis_point);
    hold.push_back(body);
  }
  j["support_hold"] = hold;
  json levels = json::array();
  for (const LevelResult& l : r.levels) levels.push_back(level_figures(s, l));
  j["validation"] = {{"levels", levels},
                     {"relative_change",
                      {{"bite_force", relative_change(r, bite_force)},
                       {"max_displacement", relative_change(r, max_displacement)},
                       {"strain_energy", relative_change(r, strain_energy)}}}};
  json mesh_seconds = json::array(), solve_seconds = json::array();
  for (const LevelResult& l : r.levels) {
    mesh_seconds.push_back(l.seconds_mesh);
    solve_seconds.push_back(l.seconds_solve);
  }
  const TrustLimits limits = trust_limits(r);
  bool passed = true;
  for (const LevelResult& l : r.levels)
    passed = passed && l.solution.equilibrium_residual <= limits.equilibrium_residual &&
             l.solution.max_displacement <= limits.max_displacement_mm;
  j["checks"] = {{"passed", passed},
                 {"equilibrium_residual_limit", limits.equilibrium_residual},
                 {"max_displacement_limit_mm", limits.max_displacement_mm},
                 {"bone_size_mm", limits.bone_size_mm}};
  j["seconds"] = {{"geometry", r.seconds_geometry},
                  {"mesh_per_level", mesh_seconds},
                  {"solve_per_level", solve_seconds},
                  {"output", seconds_output},
                  {"total", r.seconds_total + seconds_output}};
  return j;
}

namespace {

void broadcast(std::string* text, int root) {
  unsigned long size = text->size();
  MPI_Bcast(&size, 1, MPI_UNSIGNED_LONG, root, MPI_COMM_WORLD);
  text->resize(size);
  MPI_Bcast(text->data(), static_cast<int>(size), MPI_CHAR, root, MPI_COMM_WORLD);
}

}  // namespace

bool is_earlier_run_output(const std::string& dir, const std::string& name) {
  const std::filesystem::path path = std::filesystem::path(dir) / name;
  std::error_code ec;
  return path.filename() != "results.json" && is_run_output_name(path.filename().string()) &&
         std::filesystem::is_regular_file(path.parent_path() / "results.json", ec);
}

bool is_run_output_name(const std::string& filename) {
  // Levels 1 to kMaxValidationLevels only: a solution_level4.vtu was never written by a run, so it is the
  // user's and stays.
  static const std::regex kOutputName(R"((results\.json|mesh\.vtu|model(_mesh)?\.inp|solution(_level[1-)" +
                                      std::to_string(kMaxValidationLevels) +
                                      R"(])?(\.pvtu|(_[0-9]+)?\.vtu)))");
  return std::regex_match(filename, kOutputName);
}

std::vector<std::pair<std::string, std::string>> scenario_inputs(const Scenario& scenario) {
  std::vector<std::pair<std::string, std::string>> inputs = {{scenario.path, "the scenario"}};
  if (!scenario.geometry.file.empty()) inputs.push_back({scenario.geometry.file, "the geometry file"});
  if (!scenario.landmarks.file.empty()) inputs.push_back({scenario.landmarks.file, "the landmark file"});
  return inputs;
}

void refuse_inputs_among_outputs(const std::vector<std::pair<std::string, std::string>>& inputs,
                                 const std::string& dir,
                                 const std::function<bool(const std::string&)>& is_output) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path out = fs::weakly_canonical(dir, ec);
  if (ec) return;  // the folder's own check reports what is wrong with it
  for (const auto& [input, what] : inputs) {
    const fs::path path(input);
    if (!fs::is_regular_file(fs::symlink_status(path, ec))) continue;  // a link is replaced, not its target
    // The input's folder resolved, its own name kept: where a rename into DIR would land.
    const fs::path folder = fs::weakly_canonical(fs::absolute(path, ec).parent_path(), ec);
    if (ec) continue;
    const fs::path relative = (folder / path.filename()).lexically_relative(out);
    if (relative.empty() || *relative.begin() == "..") continue;
    if (is_output(relative.generic_string()))
      throw InputError("'" + input + "' is " + what + " of this command, and it writes its own '" +
                       relative.generic_string() + "' into '" + dir +
                       "': the input would be replaced by an output; choose another output folder (-o) or "
                       "rename the input");
  }
}

RunOutputs::RunOutputs(const std::string& dir, bool in_stage) : dir_(dir), in_stage_(in_stage) {
  while (dir_.size() > 1 && dir_.back() == '/') dir_.pop_back();  // as OutputStage names it
  const bool root = MpiSession::rank() == 0;
  on_all_ranks(
      [&] {
        if (!root) return;
        stage_ = std::make_unique<OutputStage>(dir);
        stage_dir_ = stage_->stage_dir();
        created_dir_ = stage_->created_dir();
      },
      kNoNote);
  // The pieces of a distributed run are written into the stage that rank 0 just made.
  if (MpiSession::size() > 1) {
    broadcast(&stage_dir_, 0);
    int created = created_dir_;
    MPI_Bcast(&created, 1, MPI_INT, 0, MPI_COMM_WORLD);
    created_dir_ = created != 0;
  }
}

RunOutputs::~RunOutputs() = default;  // ~OutputStage discards an uncommitted stage

// Under mpirun an error of one rank (its piece did not fit on the disk) used to leave the others waiting in
// the next collective call until the job was aborted, with no rank left to clean up. Here every rank runs
// its part of `step`, then all learn whether any rank failed and throw the error of the lowest rank that
// did (the same text everywhere, so rank 0 alone prints it), after which rank 0 discards the stage: by then
// no rank writes into it any more. A writer's message names the file by its place in DIR, not in the stage.
void RunOutputs::on_all_ranks(const std::function<void()>& step, Note note) {
  int kind = 0;  // 0 done, 1 RunError (or another failure), 2 InputError
  std::string message;
  try {
    step();
  } catch (const InputError& e) {
    kind = 2;
    message = e.what();
  } catch (const std::exception& e) {
    kind = 1;
    message = e.what();
  }
  const int ranks = MpiSession::size();
  if (ranks > 1) {
    const int mine = kind != 0 ? MpiSession::rank() : ranks;
    int first = ranks;
    MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    if (first == ranks) return;
    MPI_Bcast(&kind, 1, MPI_INT, first, MPI_COMM_WORLD);
    broadcast(&message, first);
  }
  if (kind == 0) return;
  message = named_in_dir(message, stage_dir_, dir_);
  const bool advise = note == kWriteNote && message.find(kWriteAdvice) == std::string::npos;
  if (note != kNoNote && !in_stage_)
    message += "; the run kept none of its files and " +
               (created_dir_ ? "did not create '" + dir_ + "'" : "left '" + dir_ + "' as it was") +
               (advise ? std::string(": ") + kWriteAdvice + ", and run again" : "");
  else if (advise)
    message += std::string("; ") + kWriteAdvice + ", and run again";
  if (kind == 2) throw InputError(message);
  throw RunError(message);
}

std::vector<std::string> RunOutputs::write(const RunResult& r, bool export_inp) {
  const bool vtu = r.scenario.outputs.vtu;
  const int rank = MpiSession::rank();
  std::vector<std::string> written;
  on_all_ranks(
      [&] {
        if (rank == 0) {
          if (vtu) {
            write_vtu(stage_dir_ + "/mesh.vtu", r.levels.front().mesh);
            written.push_back("mesh.vtu");
          }
          if (export_inp) {
            write_inp_deck(r, stage_dir_);
            written.insert(written.end(), {"model.inp", "model_mesh.inp"});
          }
        }
        for (const LevelResult& l : r.levels) {
          if (!vtu) break;
          const std::string stem = l.level == 0 ? "solution" : "solution_level" + std::to_string(l.level);
          const std::vector<std::string> files = write_solution(l, stage_dir_, stem);
          written.insert(written.end(), files.begin(), files.end());
        }
      },
      kWriteNote);
  files_ = written;
  return written;
}

void RunOutputs::commit(const std::string& results_text) {
  const bool root = MpiSession::rank() == 0;
  on_all_ranks(
      [&] {
        if (root) write_file_atomically(stage_dir_ + "/results.json", results_text);
      },
      kWriteNote);
  on_all_ranks(
      [&] {
        if (!root) return;
        std::vector<std::string> files = files_;
        files.push_back("results.json");  // last: a script that waits for it finds the whole set
        stage_->commit(files, [&](const std::string& name) { return is_earlier_run_output(dir_, name); });
      },
      kCommitNote);
}

std::string summary_table(const RunResult& r) {
  std::ostringstream out;
  char line[256];
  // The label column fits the longest reaction row ("reaction right_first_molar (N)" pushed its figures two
  // columns right of the others').
  std::size_t width = 28;
  for (const Support& support : r.scenario.supports)
    width = std::max(width, std::string("reaction  (N)").size() + support.name.size() + 2);
  const auto label_cell = [&](const std::string& label) {
    out << label << std::string(width > label.size() ? width - label.size() : 1, ' ');
  };
  const auto row = [&](const char* label, const char* format, auto value) {
    label_cell(label);
    for (const LevelResult& l : r.levels) {
      std::snprintf(line, sizeof line, format, value(l));
      out << line;
    }
    out << '\n';
  };
  // Figures in fixed point, but never a small one shown as zero (format_table_number).
  const auto figure_row = [&](const std::string& label, int decimals, auto value) {
    label_cell(label);
    for (const LevelResult& l : r.levels) out << format_table_number(value(l), decimals, 14);
    out << '\n';
  };
  label_cell("level");
  for (const LevelResult& l : r.levels) {
    std::snprintf(line, sizeof line, "%14d", l.level);
    out << line;
  }
  out << '\n';
  row("hexes", "%14zu", [](const LevelResult& l) { return l.mesh.hexes.size(); });
  row("degrees of freedom", "%14lld", [](const LevelResult& l) { return l.solution.dofs; });
  if (r.scenario.outputs.bite_force)
    figure_row("bite force (N)", 2, [](const LevelResult& l) { return l.solution.bite_force; });
  for (std::size_t i = 0; i < r.scenario.supports.size(); ++i) {
    const std::string label = "reaction " + r.scenario.supports[i].name + " (N)";
    figure_row(label, 2, [i](const LevelResult& l) { return l.solution.reactions[i].magnitude; });
  }
  // A released contact's row reads 0; say why, and at which levels.
  for (std::size_t i = 0; i < r.scenario.supports.size(); ++i) {
    std::string levels;
    for (const LevelResult& l : r.levels)
      if (l.solution.reactions[i].released) levels += (levels.empty() ? "" : ", ") + std::to_string(l.level);
    if (!levels.empty())
      out << "  (contact " << r.scenario.supports[i].name << " released at level " << levels
          << ": it would pull the bone)\n";
  }
  figure_row("max displacement (mm)", 5, [](const LevelResult& l) { return l.solution.max_displacement; });
  figure_row("von Mises max (MPa)", 3, [](const LevelResult& l) { return l.solution.von_mises_max; });
  figure_row("von Mises p99 (MPa)", 3, [](const LevelResult& l) { return l.solution.von_mises_p99; });
  figure_row("strain energy (mJ)", 5, [](const LevelResult& l) { return l.solution.strain_energy; });
  row("equilibrium residual", "%14.2e", [](const LevelResult& l) { return l.solution.equilibrium_residual; });
  row("CG iterations (0 = direct)", "%14d", [](const LevelResult& l) { return l.solution.iterations; });
  figure_row("solve seconds", 2, [](const LevelResult& l) { return l.solution.seconds; });
  if (r.levels.size() >= 2) {
    const int last = r.levels.back().level;
    out << "relative change, level " << last << " against " << last - 1 << ": bite force ";
    // In percent with 2 decimals, but a small change that would show as 0.00 in scientific notation
    // (format_table_number); "n/a" when the last level's figure is zero.
    const auto pct = [&](double (*figure)(const ElasticitySolution&)) -> std::string {
      const json c = relative_change(r, figure);
      if (c.is_null()) return "n/a";
      const double percent = 100.0 * c.get<double>();
      return (percent > 0 ? "+" : "") + format_table_number(percent, 2, 0) + " %";
    };
    out << pct(bite_force) << ", max displacement " << pct(max_displacement) << ", strain energy "
        << pct(strain_energy) << '\n';
  }
  return out.str();
}

}  // namespace hexbite
