#include "postprocess/run_results.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "common/error.h"
#include "common/paths.h"
#include "postprocess/study_table.h"

namespace hexbite {

namespace {

// Ordered: a study variant's `set` is listed in the order its changes apply (sorted, a report read
// "supports.nut: {at: right ...}; supports.nut.at: left ..." for the reverse order, which put the nut left).
using json = nlohmann::ordered_json;

// A value of the file with its key path, for messages ("validation.levels[1].hexes").
struct Key {
  const json& value;
  std::string path;
};

class Checked {
 public:
  explicit Checked(std::string file) : file_(std::move(file)) {}

  Key child(const Key& parent, const std::string& name) const {
    object(parent);
    const std::string path = parent.path.empty() ? name : parent.path + "." + name;
    const auto it = parent.value.find(name);
    if (it == parent.value.end())
      throw InputError("'" + file_ + "': key '" + path +
                       "' is missing: the file is not a complete results.json of `hexbite run` "
                       "(docs/running.md); run the scenario again");
    return {*it, path};
  }
  bool has(const Key& parent, const std::string& name) const {
    return parent.value.is_object() && parent.value.contains(name);
  }
  Key item(const Key& parent, std::size_t i) const {
    return {parent.value[i], parent.path + "[" + std::to_string(i) + "]"};
  }
  // Calls f(item) for every item of the array `parent`.`name` (which must be there and be an array).
  template <class F>
  void each(const Key& parent, const std::string& name, F f) const {
    const Key list = child(parent, name);
    for (std::size_t i = 0; i < array(list).size(); ++i) f(item(list, i));
  }

  const json& object(const Key& k) const {
    if (!k.value.is_object()) wrong(k, "an object");
    return k.value;
  }
  const json& array(const Key& k) const {
    if (!k.value.is_array()) wrong(k, "an array");
    return k.value;
  }
  double number(const Key& k) const {
    if (!k.value.is_number()) wrong(k, "a number");
    return k.value.get<double>();
  }
  std::optional<double> number_or_null(const Key& k) const {
    if (k.value.is_null()) return std::nullopt;
    if (!k.value.is_number()) wrong(k, "a number or null");
    return k.value.get<double>();
  }
  long whole(const Key& k) const {
    if (!k.value.is_number_integer()) wrong(k, "a whole number");
    return k.value.get<long>();
  }
  // A count (hexes, nodes, iterations): the run writes none below `least`, so a smaller one was edited in.
  long count(const Key& k, long least = 0) const {
    const long n = whole(k);
    if (n < least)
      throw InputError("'" + file_ + "': key '" + k.path + "' is " + std::to_string(n) +
                       ", but a run writes " +
                       (least == 0 ? "no negative count" : "at least " + std::to_string(least)) +
                       ", so the file was changed since: run the scenario again");
    return n;
  }
  double positive(const Key& k) const {
    const double x = number(k);
    if (!(x > 0))
      throw InputError("'" + file_ + "': key '" + k.path + "' is " + k.value.dump() +
                       ", but a run writes a positive number, so the file was changed since: run the "
                       "scenario again");
    return x;
  }
  bool boolean(const Key& k) const {
    if (!k.value.is_boolean()) wrong(k, "true or false");
    return k.value.get<bool>();
  }
  std::string text(const Key& k) const {
    if (!k.value.is_string()) wrong(k, "a string");
    return k.value.get<std::string>();
  }
  Vec3 vec(const Key& k) const {
    if (!k.value.is_array() || k.value.size() != 3) wrong(k, "an array of 3 numbers");
    return {number(item(k, 0)), number(item(k, 1)), number(item(k, 2))};
  }

  double number(const Key& parent, const std::string& name) const { return number(child(parent, name)); }
  long count(const Key& parent, const std::string& name, long least = 0) const {
    return count(child(parent, name), least);
  }
  Vec3 vec(const Key& parent, const std::string& name) const { return vec(child(parent, name)); }

 private:
  [[noreturn]] void wrong(const Key& k, const std::string& expected) const {
    const std::string what = k.path.empty() ? "the file" : "key '" + k.path + "'";
    const std::string type = k.value.type_name();
    const std::string found = k.value.is_null()                       ? "null"
                              : k.value.is_boolean()                  ? "a boolean"
                              : (type == "object" || type == "array") ? "an " + type
                                                                      : "a " + type;
    throw InputError("'" + file_ + "': " + what + " is " + found + ", expected " + expected);
  }

  std::string file_;
};

QualityFigures quality(const Checked& c, const Key& q, const std::string& measure) {
  const Key m = c.child(q, measure);
  return {c.number_or_null(c.child(m, "min")), c.number_or_null(c.child(m, "mean")),
          c.number_or_null(c.child(m, "max"))};
}

// The figures of one level: the top level (level 0 without its counts) or an entry of validation.levels.
LevelFigures level_figures(const Checked& c, const Key& l, const std::vector<std::string>& support_order) {
  LevelFigures f;
  const Key reactions = c.child(l, "reactions");
  // results.json keeps the reactions in an object (sorted by name); the scenario's order reads better. Every
  // support of the model has one (a missing one, from an edited file, was left out of the report silently).
  std::vector<std::string> names = support_order;
  for (const auto& item : c.object(reactions).items())
    if (std::find(names.begin(), names.end(), item.key()) == names.end()) names.push_back(item.key());
  for (const std::string& name : names) {
    const Key r = c.child(reactions, name);
    // `released` came with contact supports; a results.json of an older hexbite has none.
    f.reactions.push_back({name, c.vec(r, "force_N"), c.number(r, "magnitude_N"),
                           c.boolean(c.child(r, "bite")),
                           c.has(r, "released") && c.boolean(c.child(r, "released"))});
  }
  f.bite_force = c.number_or_null(c.child(l, "bite_force_N"));
  f.applied_force = c.vec(l, "applied_force_N");
  f.equilibrium_residual = c.number(l, "equilibrium_residual");
  f.max_displacement = c.number(l, "max_displacement_mm");
  f.max_displacement_at = c.vec(l, "max_displacement_at");
  f.von_mises_max = c.number(l, "von_mises_max_MPa");
  f.von_mises_p99 = c.number(l, "von_mises_p99_MPa");
  f.von_mises_max_at = c.vec(l, "von_mises_max_at");
  f.strain_energy = c.number(l, "strain_energy_mJ");
  const Key probes = c.child(l, "probes");
  for (const auto& item : c.object(probes).items()) {
    const Key p = c.child(probes, item.key());
    f.probes.push_back({item.key(), c.vec(p, "at"), c.number(p, "moved_mm"), c.boolean(c.child(p, "found")),
                        c.vec(p, "displacement_mm"), c.number(p, "von_mises_MPa")});
  }
  const Key solver = c.child(l, "solver");
  f.iterations = c.count(solver, "iterations");
  f.solve_seconds = c.number(solver, "seconds");
  f.ranks = c.count(solver, "ranks", 1);
  return f;
}

// The model as solved: materials, muscles and supports. A results.json written before the report existed
// lacks the materials and the supports' centres, radii and conditions, so those are optional.
void read_model(const Checked& c, const Key& top, RunFigures& r) {
  const auto optional_number = [&](const Key& k, const char* name) {
    return c.has(k, name) ? c.number_or_null(c.child(k, name)) : std::nullopt;
  };
  if (c.has(top, "materials")) {
    const Key materials = c.child(top, "materials");
    const Key d = c.child(materials, "default");
    r.default_material = MaterialFigures{"", c.number(d, "E_MPa"), c.number(d, "poisson"), std::nullopt};
    c.each(materials, "regions", [&](const Key& m) {
      r.material_regions.push_back(
          {c.text(c.child(m, "name")), c.number(m, "E_MPa"), c.number(m, "poisson"), c.count(m, "hexes")});
    });
  }
  if (c.has(top, "muscles"))
    c.each(top, "muscles", [&](const Key& m) {
      r.muscles.push_back({c.text(c.child(m, "name")), optional_number(m, "activation"), c.vec(m, "force_N"),
                           c.number(m, "magnitude_N"), c.number(m, "patch_area_mm2")});
    });
  if (c.has(top, "supports"))
    c.each(top, "supports", [&](const Key& k) {
      SupportFigures s;
      s.name = c.text(c.child(k, "name"));
      if (c.has(k, "center_mm")) s.center = c.vec(k, "center_mm");
      s.radius_mm = optional_number(k, "radius_mm");
      s.spring_N_per_mm3 = optional_number(k, "spring_N_per_mm3");
      if (c.has(k, "fixed")) {
        s.fixed.emplace();
        c.each(k, "fixed", [&](const Key& axis) { s.fixed->push_back(c.text(axis)); });
      }
      s.contact = c.has(k, "contact") && c.boolean(c.child(k, "contact"));
      s.patch_area_mm2 = c.number(k, "patch_area_mm2");
      r.supports.push_back(s);
    });
}

// Line and column (1-based) of byte `byte` (1-based, as nlohmann's parse_error counts) of `text`.
std::pair<int, int> line_and_column(const std::string& text, std::size_t byte) {
  int line = 1, column = 1;
  for (std::size_t i = 0; i + 1 < byte && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
  return {line, column};
}

json parse(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(path, ec))
    throw InputError("'" + fs::path(path).parent_path().string() + "' holds no " +
                     fs::path(path).filename().string() +
                     ", so no finished run: run `hexbite run SCENARIO -o " +
                     fs::path(path).parent_path().string() + "` first");
  require_regular_file(path, "the run's results file");
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in) throw InputError("cannot read '" + path + "'");
  try {
    return json::parse(text.str());
  } catch (const json::parse_error& e) {
    // nlohmann's message starts with its own code and position; ours names the file, line and column.
    std::string what = e.what();
    const std::size_t reason = what.find(": ", what.find("parse error"));
    if (reason != std::string::npos) what = what.substr(reason + 2);
    const auto [line, column] = line_and_column(text.str(), e.byte);
    throw InputError("'" + path + "':" + std::to_string(line) + ":" + std::to_string(column) +
                     ": not JSON: " + what + "; the run writes results.json whole, so the file was " +
                     "changed or cut since: run the scenario again");
  } catch (const json::out_of_range& e) {
    // A number beyond a double (1e999) gave nlohmann's own text and exit 1.
    std::string what = e.what();
    if (const std::size_t reason = what.find("] "); reason != std::string::npos)
      what = what.substr(reason + 2);
    throw InputError(
        "'" + path + "': " + what +
        "; the run writes no such number, so the file was changed since: run the scenario again");
  }
}

}  // namespace

RunFigures read_run_figures(const std::string& path) {
  const json j = parse(path);
  const Checked c(path);
  const Key top{j, ""};
  c.object(top);
  RunFigures r;
  r.scenario = c.text(c.child(top, "scenario"));
  r.scenario_file = c.text(c.child(top, "scenario_file"));
  r.mesh_method = c.text(c.child(top, "mesh_method"));
  if (c.has(top, "study")) {
    const Key s = c.child(top, "study");
    c.object(c.child(s, "set"));
    r.study = StudyFigures{c.text(c.child(s, "name")), c.text(c.child(s, "file")),
                           c.text(c.child(s, "variant")), study_changes(c.child(s, "set").value, false)};
  }
  const Key mesh = c.child(top, "mesh");
  if (c.has(mesh, "core")) r.mesh_core = c.text(c.child(mesh, "core"));
  r.degree = static_cast<int>(c.count(mesh, "degree", 1));
  const Key q = c.child(mesh, "quality");
  r.scaled_jacobian = quality(c, q, "scaled_jacobian");
  r.condition = quality(c, q, "condition");
  r.condition_verdict = quality(c, q, "condition_verdict");
  r.oddy = quality(c, q, "oddy");
  r.inverted = c.count(q, "inverted");
  if (c.has(mesh, "fidelity")) {
    const Key f = c.child(mesh, "fidelity");
    const auto figure = [&](const char* name) { return c.number_or_null(c.child(f, name)); };
    r.fidelity = FidelityFigures{figure("hausdorff_mm"),
                                 figure("hausdorff_mesh_to_surface_mm"),
                                 figure("hausdorff_surface_to_mesh_mm"),
                                 figure("mesh_volume_mm3"),
                                 figure("surface_volume_mm3"),
                                 figure("volume_difference")};
  }
  if (c.has(top, "support_hold"))
    c.each(top, "support_hold", [&](const Key& b) {
      SupportHoldFigures s;
      s.weak = c.boolean(c.child(b, "weak"));
      s.hold = c.number(b, "hold");
      s.rotation = c.text(c.child(b, "weakest_motion")) == "rotation";
      s.direction = c.vec(b, "direction");
      if (s.rotation) s.axis_point = c.vec(b, "axis_point_mm");
      r.support_hold.push_back(s);
    });
  if (c.has(top, "hexbite_version")) r.hexbite_version = c.text(c.child(top, "hexbite_version"));
  // Required, as every key the report warns from: without it a run that failed its small-displacement
  // check (exit 1, files kept) was reported without the warning.
  const Key checks = c.child(top, "checks");
  c.boolean(c.child(checks, "passed"));
  c.positive(c.child(checks, "equilibrium_residual_limit"));
  r.max_displacement_limit = c.positive(c.child(checks, "max_displacement_limit_mm"));
  r.bone_size = c.positive(c.child(checks, "bone_size_mm"));
  read_model(c, top, r);
  std::vector<std::string> support_order;
  for (const SupportFigures& s : r.supports) support_order.push_back(s.name);
  r.coarse = level_figures(c, top, support_order);
  r.coarse.hexes = c.count(mesh, "hexes", 1);
  r.coarse.nodes = c.count(mesh, "nodes", 1);
  r.coarse.dofs = c.count(mesh, "dofs");
  const Key validation = c.child(top, "validation");
  c.each(validation, "levels", [&](const Key& l) {
    LevelFigures f = level_figures(c, l, support_order);
    const Key level = c.child(l, "level");
    f.level = static_cast<int>(c.whole(level));
    // The levels are 0, 1, 2, ... in order (docs/running.md): the report labels its rows and warnings so.
    if (f.level != static_cast<long>(r.levels.size()))
      throw InputError("'" + path + "': key '" + level.path + "' is " + level.value.dump() + ", but " +
                       "validation.levels holds level 0 first and one more in each entry, so it must be " +
                       std::to_string(r.levels.size()) +
                       "; the file was changed since: run the scenario again");
    f.hexes = c.count(l, "hexes", 1);
    f.nodes = c.count(l, "nodes", 1);
    f.dofs = c.count(l, "dofs");
    r.levels.push_back(f);
  });
  if (r.levels.empty())
    throw InputError("'" + path + "': key 'validation.levels' is empty; a run solves at least level 0");
  const Key change = c.child(validation, "relative_change");
  r.change_bite_force = c.number_or_null(c.child(change, "bite_force"));
  r.change_max_displacement = c.number_or_null(c.child(change, "max_displacement"));
  r.change_strain_energy = c.number_or_null(c.child(change, "strain_energy"));
  return r;
}

}  // namespace hexbite
