#include "scenarios/scenario.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <tuple>
#include <utility>

#include "common/error.h"
#include "common/number_format.h"
#include "mesher/grid_mesher.h"
#include "mesher/quad_local_refinement.h"
#include "mesher/units.h"
#include "scenarios/scenario_tree.h"
#include "scenarios/yaml_input.h"

namespace hexbite {

std::string SourceLocation::str() const {
  return file + ":" + std::to_string(line) + ":" + std::to_string(column) + (note.empty() ? "" : ": " + note);
}

namespace {

namespace fs = std::filesystem;

using namespace yaml_input;

std::string fmt(double x) {
  return format_significant(x);
}

// `number`: format_rounded for a point the program computed (a landmark's), whose last digits are round-off.
std::string fmt(const Vec3& p, std::string (*number)(double) = format_significant) {
  return "[" + number(p[0]) + ", " + number(p[1]) + ", " + number(p[2]) + "]";
}

std::vector<std::string> split_tokens(const std::string& name) {
  std::vector<std::string> tokens;
  std::string current;
  for (char c : name) {
    if (c == '_' || c == '.' || c == '-' || c == ' ') {
      if (!current.empty()) tokens.push_back(current);
      current.clear();
    } else {
      current += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    }
  }
  if (!current.empty()) tokens.push_back(current);
  return tokens;
}

// The known names most like `given`: landmark names are long compounds ("right_first_molar_bite_point"),
// so a name sharing more of its words ranks first and the edit distance breaks ties.
std::vector<std::string> closest_names(const std::string& given, const std::vector<std::string>& known,
                                       size_t count) {
  const auto given_tokens = split_tokens(given);
  std::vector<std::tuple<int, size_t, std::string>> ranked;
  for (const auto& name : known) {
    const auto tokens = split_tokens(name);
    int shared = 0;
    for (const auto& t : given_tokens) shared += std::count(tokens.begin(), tokens.end(), t) > 0 ? 1 : 0;
    ranked.emplace_back(-shared, edit_distance(given, name), name);
  }
  std::sort(ranked.begin(), ranked.end());
  std::vector<std::string> out;
  for (size_t i = 0; i < ranked.size() && i < count; ++i) out.push_back(std::get<2>(ranked[i]));
  return out;
}

// A key's place for messages about its value: the key's, or in a study's variant that set the value
// (`set: {supports: []}`, `set: {supports.floor.contact: true}`, `set: {activation_pattern: null}`) the
// study's line, where it was written. (A null value of the key's own file is placed at its key.)
SourceLocation written_at(const Map& map, const std::string& key) {
  const Value& v = map.get(key);
  return v.at.file != map.key_at(key).file ? v.at : map.key_at(key);
}

double to_number(const Value& v) {
  const std::optional<double> x = plain_number(v.node);
  if (!x) fail(v.at, v.path + " must be a number, " + number_expected(v.node));
  return *x;
}

// A whole number of any size (up to 2^53); the callers check their ranges on it, so that 1e10 is "out of
// range" and not "not a whole number" (an int, as before, could not hold it).
long long to_whole(const Value& v) {
  long long x = 0;
  if (!decimal_whole_number(v.node, &x))
    fail(v.at, v.path + " must be a whole number, found " + describe(v.node) +
                   "; write it in decimal digits, without quotes");
  return x;
}

bool to_bool(const Value& v) {
  bool x = false;
  if (!v.node.IsScalar() || is_quoted(v.node) || !YAML::convert<bool>::decode(v.node, x))
    fail(v.at, v.path + " must be true or false, found " + describe(v.node) + "; write true or false");
  return x;
}

// Coordinates and vectors in mm, each component within kMaxCoordinateMm (mesher/units.h).
Vec3 to_vec3(const Value& v) {
  if (!v.node.IsSequence() || v.node.size() != 3)
    fail(v.at, v.path + " must be three numbers [x, y, z], found " + describe(v.node) +
                   "; write e.g. [0, -20, 45]");
  Vec3 xyz;
  const auto items = to_list(v);
  for (int k = 0; k < 3; ++k) {
    xyz[k] = to_number(items[k]);
    if (std::abs(xyz[k]) > kMaxCoordinateMm)
      fail(items[k].at, items[k].path + " is " + fmt(xyz[k]) + ", beyond " + fmt(kMaxCoordinateMm) +
                            " mm in size; give millimetres in the frame of the geometry (a mandible spans "
                            "about 100 mm)");
  }
  return xyz;
}

PointRef to_point(const Value& v) {
  PointRef p;
  p.where = v.at;
  if (v.node.IsSequence()) {
    p.xyz = to_vec3(v);
    p.resolved = true;
    return p;
  }
  double number = 0;
  if (!v.node.IsScalar() || v.node.Scalar().empty() ||
      (!is_quoted(v.node) && YAML::convert<double>::decode(v.node, number)))
    fail(v.at, v.path + " must be a point, found " + describe(v.node) +
                   "; write coordinates [x, y, z] in mm or a name (a landmark, a landmarks.points entry, "
                   "'<muscle>.insertion' or '<muscle>.origin')");
  p.name = v.node.Scalar();
  return p;
}

template <typename Enum>
Enum to_choice(const Value& v, const std::vector<std::pair<std::string, Enum>>& choices) {
  std::vector<std::string> names;
  for (const auto& [name, value] : choices) names.push_back(name);
  // Nothing, a list or a mapping was told "write a word such as left_condyle", to_string's hint for points.
  const std::string given = to_string(v, "valid choices are " + join_quoted(names));
  for (const auto& [name, value] : choices)
    if (given == name) return value;
  fail(v.at, v.path + " is " + quote(given) + ", not a valid choice; " + suggestion(given, names));
}

double positive(const Value& v, const std::string& unit_hint) {
  const double x = to_number(v);
  if (x <= 0)
    fail(v.at, v.path + " is " + fmt(x) + " but must be positive" + (x < 0 ? " (it is negative)" : "") +
                   "; give " + unit_hint);
  return x;
}

// The largest radius of a muscle insertion or support patch. A patch is a muscle's insertion area or a
// contact (a tooth, a condyle), at most a few centimetres across (the largest, the masseter's insertion on
// the ramus, spans about 3 to 4 cm); the whole mandible is about 100 mm across, so a 50 mm patch already
// covers most of one side. Larger radii (1000 mm ran and loaded or held the whole bone) are a slip of the
// unit or the digits.
constexpr double kMaxPatchRadiusMm = 50.0;

double patch_radius(const Value& v, const std::string& unit_hint) {
  const double r = positive(v, unit_hint);
  if (r > kMaxPatchRadiusMm)
    fail(v.at,
         v.path + " is " + fmt(r) + " mm but must be greater than 0 and at most " + fmt(kMaxPatchRadiusMm) +
             " mm: a patch is an insertion or contact area, and a mandible is about 100 mm across, so " +
             fmt(r) + " mm would take in most or all of the bone; give " + unit_hint +
             ", and check that the value is not in another unit");
  return r;
}

// With `folder_too`, a folder is taken as well (a CT volume given as a DICOM series). `example` (a file name)
// is the hint for a value that is no text.
std::string resolve_file(const Source& ctx, const Value& v, const std::string& kind,
                         const std::string& example, bool folder_too = false) {
  const std::string given = to_string(v, "give the " + kind + " file's path, e.g. file: " + example);
  fs::path path(given);
  // A path that a study set resolves against the study file's folder (yaml_input.h).
  const fs::path folder = ctx.folder_of(v.node);
  if (path.is_relative()) path = folder / path;
  path = path.lexically_normal();
  std::error_code error;
  if (!fs::is_regular_file(path, error) && !(folder_too && fs::is_directory(path, error)))
    fail(v.at, kind + " file " + quote(given) +
                   (path.string() == given ? std::string() : " (resolved to " + quote(path.string()) + ")") +
                   " does not exist or is not a file" + (folder_too ? " or folder" : "") +
                   "; give a path relative to the " + (folder == ctx.folder ? "scenario" : "study") +
                   " file's folder or an absolute path");
  return path.string();
}

const std::vector<std::pair<std::string, MandibleVariant>> kVariants = {
    {"dentate", MandibleVariant::kDentate},
    {"edentulous", MandibleVariant::kEdentulous},
    {"atrophic", MandibleVariant::kAtrophic}};

// The `units` of a surface or CT geometry: the unit of the file's lengths.
void read_units(const Map& map, GeometrySpec& g) {
  if (auto x = map.find("units")) {
    g.units = to_choice<std::string>(*x, {{"mm", "mm"}, {"cm", "cm"}, {"m", "m"}});
    g.units_given = true;
  }
  g.scale_to_mm = unit_to_mm(g.units);
}

GeometrySpec parse_geometry(const Source& ctx, const Value& v) {
  const Map map(v, {"mandible", "surface", "ct"});
  GeometrySpec g;
  g.where = v.at;
  std::vector<std::string> given;
  for (const char* key : {"mandible", "surface", "ct"})
    if (map.has(key)) given.push_back(key);
  if (given.empty())
    fail(
        v.at,
        "geometry needs one of 'mandible', 'surface' or 'ct'; e.g. geometry: {mandible: {variant: dentate}}");
  if (given.size() > 1)
    fail(map.key_at(given[1]), "geometry has both " + quote(given[0]) + " and " + quote(given[1]) +
                                   "; keep exactly one geometry source (in a study's set, replace the "
                                   "whole geometry: geometry: {" +
                                   given[1] + ": {...}}, not geometry." + given[1] + ")");
  if (map.has("mandible")) {
    g.source = GeometrySource::kMandible;
    std::vector<std::string> keys = {"variant"};
    for (const MandibleDimension& d : mandible_dimensions()) keys.push_back(d.scenario_key);
    const Map m(map.get("mandible"), keys);
    MandibleParameters& p = g.mandible;
    if (auto x = m.find("variant")) p.variant = to_choice(*x, kVariants);
    // The generator's own ranges (mandible_dimensions), checked here so that a value outside is named at
    // its line rather than as a generate option when the mandible is built.
    const MandibleParameters defaults = mandible_defaults(p.variant);
    for (const MandibleDimension& d : mandible_dimensions()) {
      const auto x = m.find(d.scenario_key);
      if (!x) continue;
      const double value = to_number(*x);
      if (!(value >= d.lo && value <= d.hi)) {
        const std::string whose = d.field == &MandibleParameters::voxel_mm
                                      ? ""
                                      : std::string(variant_name(p.variant)) + " variant's ";
        fail(x->at, x->path + " is " + fmt(value) + " " + d.unit +
                        ", outside the built-in mandible's range " + fmt(d.lo) + " to " + fmt(d.hi) + " " +
                        d.unit + "; give a value in it, or leave it out for the " + whose + "default " +
                        fmt(defaults.*d.field) + " " + d.unit);
      }
      p.*d.field = value;
    }
  } else if (map.has("surface")) {
    g.source = GeometrySource::kSurface;
    const Map s(map.get("surface"), {"file", "units"});
    g.file = resolve_file(ctx, s.require("file", "file: jaw.stl"), "surface", "jaw.stl");
    read_units(s, g);
  } else {
    g.source = GeometrySource::kCt;
    const Map c(map.get("ct"), {"file", "threshold", "series", "units"});
    g.file = resolve_file(ctx, c.require("file", "file: jaw.mha"), "CT volume", "jaw.mha", true);
    g.threshold =
        to_number(c.require("threshold", "threshold: 400 (the bone iso-value, e.g. in Hounsfield units)"));
    if (auto series = c.find("series"))
      g.dicom_series = to_string(*series, "give the series' number, description or UID, e.g. series: 3");
    read_units(c, g);
  }
  return g;
}

LandmarkSpec parse_landmarks(const Source& ctx, const std::optional<Value>& v, const GeometrySpec& geometry) {
  LandmarkSpec l;
  // A landmark file lies in its bone's frame, so by default it shares the unit written for the surface or
  // CT volume.
  if (geometry.source != GeometrySource::kMandible) l.units = geometry.units;
  l.scale_to_mm = unit_to_mm(l.units);
  if (!v) return l;
  const Map map(*v, {"file", "units", "points"});
  l.where = v->at;
  if (auto x = map.find("file")) l.file = resolve_file(ctx, *x, "landmark", "landmarks.yaml");
  if (auto x = map.find("units")) {
    if (!map.has("file"))
      fail(map.key_at("units"),
           "landmarks.units is given without landmarks.file; add the file or remove units");
    l.units = to_choice<std::string>(*x, {{"mm", "mm"}, {"cm", "cm"}, {"m", "m"}});
    l.scale_to_mm = unit_to_mm(l.units);
  }
  if (auto x = map.find("points")) {
    if (!x->node.IsNull() && !x->node.IsMap())
      fail(x->at, "landmarks.points must be a mapping 'name: [x, y, z]', found " + describe(x->node) +
                      "; write e.g. points: {implant_site: [0, -30, 20]}");
    for (auto it = x->node.begin(); x->node.IsMap() && it != x->node.end(); ++it) {
      const SourceLocation key_at = ctx.locate(it->first, x->at);
      const std::string name = it->first.Scalar();
      for (const auto& earlier : l.points)
        if (earlier.name == name)
          fail(key_at, "point " + quote(name) + " is defined twice in landmarks.points (first on line " +
                           std::to_string(earlier.where.line) + "); rename or remove one");
      const SourceLocation value_at = ctx.locate(it->second, key_at);
      l.points.push_back({name, to_vec3({&ctx, it->second, value_at, "landmarks.points." + name}), key_at});
    }
  }
  return l;
}

MeshSettings parse_mesh(const Value& v) {
  const Map map(v, {"method", "target_hexes", "validation_levels", "refine_at_bite", "refine_radius_mm",
                    "refine_levels", "fit_volume", "grid_frame", "core"});
  MeshSettings m;
  if (auto x = map.find("method")) {
    m.method = to_choice<MeshMethod>(*x, {{"grid", MeshMethod::kGrid}, {"sheets", MeshMethod::kSheets}});
    m.method_at = x->at;
  }
  if (auto x = map.find("target_hexes")) {
    const long long n = to_whole(*x);
    if (n < kMinTargetHexes || n > kMaxTargetHexes)
      fail(x->at, "mesh.target_hexes is " + std::to_string(n) + " but must be from " +
                      std::to_string(kMinTargetHexes) + " to " + std::to_string(kMaxTargetHexes) +
                      "; the default is 2500, at which the built-in mandible keeps its condyles");
    m.target_hexes = static_cast<int>(n);
  }
  if (auto x = map.find("validation_levels")) {
    const long long n = to_whole(*x);
    m.validation_levels_at = x->at;
    if (n < 0 || n > kMaxValidationLevels)
      fail(x->at, "mesh.validation_levels is " + std::to_string(n) + " but must be from 0 (none) to " +
                      std::to_string(kMaxValidationLevels) +
                      "; each level refines the mesh 8-way and solves again");
    m.validation_levels = static_cast<int>(n);
  }
  if (auto x = map.find("refine_at_bite")) {
    m.refine_at_bite = to_bool(*x);
    m.refine_at_bite_at = x->at;
    if (m.refine_at_bite && m.method != MeshMethod::kSheets)
      fail(x->at,
           "mesh.refine_at_bite refines the quad surface of the sheet mesher, but mesh.method is grid" +
               std::string(m.method_at.line ? "" : " (the default)") +
               "; write method: sheets in mesh, or remove refine_at_bite");
  }
  if (auto x = map.find("refine_radius_mm")) {
    m.refine_radius_mm = to_number(*x);
    if (!m.refine_at_bite)
      fail(x->at, "mesh.refine_radius_mm needs refine_at_bite: true in mesh; add it or remove this key");
    if (m.refine_radius_mm < kMinRefineRadiusMm || m.refine_radius_mm > kMaxRefineRadiusMm)
      fail(x->at, "mesh.refine_radius_mm is " + fmt(m.refine_radius_mm) + " but must be from " +
                      fmt(kMinRefineRadiusMm) + " to " + fmt(kMaxRefineRadiusMm) + " mm; the default is 8");
  }
  if (auto x = map.find("refine_levels")) {
    const long long n = to_whole(*x);
    if (!m.refine_at_bite)
      fail(x->at, "mesh.refine_levels needs refine_at_bite: true in mesh; add it or remove this key");
    if (n < 1 || n > kMaxRefineLevels)
      fail(x->at, "mesh.refine_levels is " + std::to_string(n) + " but must be from 1 to " +
                      std::to_string(kMaxRefineLevels) +
                      " (rings of quads around the bite point); the default is 3");
    m.refine_levels = static_cast<int>(n);
  }
  if (auto x = map.find("fit_volume")) m.fit_volume = to_bool(*x);
  if (auto x = map.find("grid_frame")) {
    m.arch_frame = to_choice<bool>(*x, {{"axes", false}, {"arch", true}});
    m.grid_frame_at = x->at;
    if (m.method != MeshMethod::kGrid)
      fail(x->at,
           "mesh.grid_frame lays the overlay grid of method grid, but mesh.method is sheets; remove "
           "grid_frame or write method: grid");
  }
  if (auto x = map.find("core")) {
    m.core = to_choice<MeshCore>(
        *x, {{"grid", MeshCore::kGrid}, {"swept", MeshCore::kSwept}, {"auto", MeshCore::kAuto}});
    m.core_at = x->at;
    if (m.method != MeshMethod::kGrid)
      fail(x->at,
           "mesh.core chooses the core of method grid, but mesh.method is sheets; remove core or write "
           "method: grid");
    if (m.core == MeshCore::kSwept && m.grid_frame_at.line > 0 && !m.arch_frame)
      fail(x->at,
           "mesh.core swept sweeps the core across the dental arch, but mesh.grid_frame is axes; write "
           "grid_frame: arch, leave it out, or write core: grid");
    if (m.core == MeshCore::kSwept) m.arch_frame = true;
  }
  return m;
}

// Stiffer than any material (diamond: about 1.05e6 MPa): a modulus above it is one in Pa (1.1e10 for
// bone), which leaves the stresses right but makes the displacements a million times too small.
constexpr double kMaxYoungsModulusMPa = 1e7;
// Softer than any solid (soft gels: about 1e-5 MPa; fat and brain about 1e-3): a modulus below it is a slip
// of the exponent. Far below it the solve itself broke: 1e-300 gave a non-finite solution blamed on the
// supports, 4.9e-324 a deal.II exception.
constexpr double kMinYoungsModulusMPa = 1e-6;

double parse_E(const Value& v) {
  const double E = to_number(v);
  if (E <= 0)
    fail(v.at, v.path + " is " + fmt(E) +
                   " MPa but Young's modulus must be positive; cortical bone is about 11000 MPa");
  if (E < kMinYoungsModulusMPa)
    fail(v.at, v.path + " is " + fmt(E) + " MPa, below " + fmt(kMinYoungsModulusMPa) +
                   " MPa: softer than any solid (a soft gel is about 1e-5 MPa); give the modulus in MPa: "
                   "cortical bone is about 11000 MPa, a periodontal ligament about 1");
  if (E > kMaxYoungsModulusMPa)
    fail(v.at, v.path + " is " + fmt(E) +
                   " MPa, stiffer than any material (diamond: about 1e6 MPa); give "
                   "MPa, not Pa: cortical bone is about 11000 MPa, titanium 110000");
  return E;
}

double parse_poisson(const Value& v) {
  const double nu = to_number(v);
  if (nu <= -1 || nu >= 0.5)
    fail(v.at, v.path + " is " + fmt(nu) +
                   " but Poisson's ratio must lie strictly between -1 and 0.5 (0.5 is incompressible); bone "
                   "is about 0.28");
  return nu;
}

Materials parse_materials(const Value& v) {
  const Map map(v, {"default", "regions"});
  Materials m;
  if (auto x = map.find("default")) {
    const Map d(*x, {"E_MPa", "poisson"});
    if (auto y = d.find("E_MPa")) {
      m.default_material.E_MPa = parse_E(*y);
      m.default_material.E_MPa_at = y->at;
    }
    if (auto y = d.find("poisson")) {
      m.default_material.poisson = parse_poisson(*y);
      m.default_material.poisson_at = y->at;
    }
  }
  if (auto x = map.find("regions")) {
    for (const Value& item : to_list(*x)) {
      const Map r(item, {"name", "sphere", "box", "E_MPa", "poisson"});
      MaterialRegion region;
      region.where = item.at;
      region.name = to_name(r.require("name", "name: implant_site"));
      if (r.has("sphere") == r.has("box"))
        fail(item.at, item.path + " (" + quote(region.name) +
                          ") needs exactly one shape, 'sphere: {center, radius_mm}' or 'box: {min, max}'");
      if (r.has("sphere")) {
        region.shape = RegionShape::kSphere;
        const Map s(r.get("sphere"), {"center", "radius_mm"});
        region.center = to_point(s.require("center", "center: [0, -30, 20]"));
        region.radius_mm = positive(s.require("radius_mm", "radius_mm: 5"), "a radius in mm");
        region.radius_at = written_at(s, "radius_mm");
      } else {
        region.shape = RegionShape::kBox;
        const Map b(r.get("box"), {"min", "max"});
        region.min = to_point(b.require("min", "min: [-10, -40, 10]"));
        region.max = to_point(b.require("max", "max: [10, -20, 30]"));
      }
      if (!r.has("E_MPa") && !r.has("poisson"))
        fail(item.at,
             item.path + " (" + quote(region.name) +
                 ") changes nothing; give E_MPa and/or poisson (the one left out keeps the default)");
      region.material = m.default_material;
      if (auto y = r.find("E_MPa")) {
        region.material.E_MPa = parse_E(*y);
        region.material.E_MPa_at = y->at;
      }
      if (auto y = r.find("poisson")) {
        region.material.poisson = parse_poisson(*y);
        region.material.poisson_at = y->at;
      }
      for (const auto& earlier : m.regions)
        if (earlier.name == region.name)
          fail(item.at, "material region " + quote(region.name) + " is defined twice (first on line " +
                            std::to_string(earlier.where.line) + "); give each region its own name");
      m.regions.push_back(region);
    }
  }
  return m;
}

double parse_activation(const Value& v) {
  const double a = to_number(v);
  if (a < 0 || a > 1)
    fail(v.at, v.path + " is " + fmt(a) +
                   " but an activation must lie in [0, 1] (a fraction of the maximum force); write e.g. 0.5");
  return a;
}

Muscle default_muscle(const std::string& name, const SourceLocation& where) {
  Muscle m;
  m.name = name;
  m.where = where;
  m.insertion.name = name + ".insertion";
  m.insertion.where = where;
  m.origin = PointRef{name + ".origin", {}, false, where};
  return m;
}

Muscle parse_muscle(const Value& item) {
  const Map map(item, {"name", "insertion", "radius_mm", "origin", "direction", "max_force_N", "activation"});
  Muscle m = default_muscle(to_name(map.require("name", "name: right_superficial_masseter")), item.at);
  if (auto x = map.find("insertion")) m.insertion = to_point(*x);
  if (auto x = map.find("radius_mm")) {
    m.radius_mm = patch_radius(*x, "the insertion patch radius in mm, e.g. 10");
    m.radius_at = written_at(map, "radius_mm");
  }
  if (map.has("origin") && map.has("direction"))
    fail(map.key_at("direction"),
         "muscle " + quote(m.name) +
             " has both 'origin' and 'direction'; the line of action needs exactly one");
  if (auto x = map.find("origin")) m.origin = to_point(*x);
  if (auto x = map.find("direction")) {
    m.origin.reset();
    m.direction = to_vec3(*x);
    const Vec3& d = *m.direction;
    if (std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) < 1e-12)
      fail(x->at, "muscle " + quote(m.name) + " has a zero line of action (direction " + fmt(d) +
                      "); give a non-zero direction vector");
  }
  if (auto x = map.find("max_force_N")) {
    m.max_force_N = positive(*x, "the maximum force in N, e.g. 190.4");
    if (*m.max_force_N > kMaxMuscleForceN)
      fail(x->at, x->path + " is " + fmt(*m.max_force_N) + " N, more than " + fmt(kMaxMuscleForceN) +
                      " N; no jaw muscle comes near (the superficial masseter gives about 190 N): give the "
                      "force in newtons");
  }
  m.activation =
      parse_activation(map.require("activation", "activation: 0.5 (a fraction of max_force_N in [0, 1])"));
  return m;
}

// activation_pattern: {base: a, base: {left: a, right: b}} becomes left_<base> and right_<base> muscles
// with every other property from the landmarks.
std::vector<Muscle> parse_activation_pattern(const Source& ctx, const Value& v) {
  std::vector<Muscle> muscles;
  if (v.node.IsNull()) return muscles;
  if (!v.node.IsMap())
    fail(
        v.at,
        "activation_pattern must be a mapping 'muscle: activation' or 'muscle: {left: a, right: b}', found " +
            describe(v.node) +
            "; write e.g. activation_pattern: {superficial_masseter: {left: 0.2, right: 0.56}}");
  for (auto it = v.node.begin(); it != v.node.end(); ++it) {
    const SourceLocation key_at = ctx.locate(it->first, v.at);
    const std::string base = it->first.Scalar();
    const SourceLocation value_at = it->second.IsNull() ? key_at : ctx.locate(it->second, key_at);
    const Value value{&ctx, it->second, value_at, "activation_pattern." + base};
    // "right_superficial_masseter: 0.5" became left_right_superficial_masseter and
    // right_right_superficial_masseter, reported as muscles unknown to the landmarks.
    for (const char* side : {"left_", "right_"})
      if (base.rfind(side, 0) == 0)
        fail(key_at, "activation_pattern key " + quote(base) + " starts with " + quote(side) +
                         ", but a pattern key is a muscle name without its side (the pattern makes both "
                         "sides' muscles); write " +
                         base.substr(std::strlen(side)) + ": {" +
                         std::string(side).substr(0, std::strlen(side) - 1) + ": " +
                         (value.node.IsScalar() ? value.node.Scalar() : std::string("a")) + "}, or list " +
                         quote(base) + " in muscles");
    std::vector<Muscle> added;
    if (value.node.IsMap()) {
      const Map sides(value, {"left", "right"});
      for (const char* side : {"left", "right"})
        if (auto x = sides.find(side)) {
          Muscle m = default_muscle(std::string(side) + "_" + base, sides.key_at(side));
          m.activation = parse_activation(*x);
          added.push_back(m);
        }
      // "superficial_masseter: {}" added no muscle without a word.
      if (added.empty())
        fail(value_at, "activation_pattern." + base +
                           " gives no side; write an activation for both sides (e.g. 0.5) or {left: a, "
                           "right: b} (either may be left out)");
    } else {
      const double activation = parse_activation(value);
      for (const char* side : {"left", "right"}) {
        Muscle m = default_muscle(std::string(side) + "_" + base, key_at);
        m.activation = activation;
        added.push_back(m);
      }
    }
    for (Muscle& m : added) {
      m.pattern_key = base;
      muscles.push_back(std::move(m));
    }
  }
  return muscles;
}

Support parse_support(const Value& item) {
  const Map map(item, {"name", "at", "radius_mm", "fixed", "spring_N_per_mm3", "bite", "contact"});
  Support s;
  s.where = item.at;
  const Value& name = map.require("name", "name: right_condyle");
  s.name = to_name(name);
  s.name_at = name.at;
  s.at = to_point(map.require("at", "at: right_condyle_tmj_point"));
  s.radius_mm =
      patch_radius(map.require("radius_mm", "radius_mm: 5"), "the support patch radius in mm, e.g. 5");
  s.radius_at = written_at(map, "radius_mm");
  if (map.has("fixed") && map.has("spring_N_per_mm3")) {
    // At the one a study added, if it added one: the base's spring was named for a study's `fixed`.
    const SourceLocation fixed = written_at(map, "fixed");
    fail(fixed.file != item.at.file ? fixed : written_at(map, "spring_N_per_mm3"),
         "support " + quote(s.name) +
             " has both 'fixed' and 'spring_N_per_mm3'; a patch is either fixed "
             "or elastic, keep one");
  }
  if (auto x = map.find("fixed")) {
    s.fixed_at = written_at(map, "fixed");
    const auto items = to_list(*x);
    if (items.empty())
      fail(x->at, "support " + quote(s.name) +
                      " fixes no component; list the components to fix, e.g. [x, y, z] or [z]");
    s.fixed = {false, false, false};
    for (const Value& c : items) {
      const int axis = to_choice<int>(c, {{"x", 0}, {"y", 1}, {"z", 2}});
      if (s.fixed[axis])
        fail(c.at, "support " + quote(s.name) + " lists component " + quote(c.node.Scalar()) +
                       " twice; list each once");
      s.fixed[axis] = true;
    }
  }
  if (auto x = map.find("spring_N_per_mm3")) {
    s.spring_at = written_at(map, "spring_N_per_mm3");
    s.spring_N_per_mm3 =
        positive(*x, "the foundation stiffness in N/mm^3 (traction per displacement), e.g. 50");
  }
  if (auto x = map.find("bite")) s.bite = to_bool(*x);
  if (auto x = map.find("contact")) s.contact = to_bool(*x);
  if (s.contact && s.spring_N_per_mm3)
    fail(written_at(map, "contact"), "support " + quote(s.name) +
                                         " is a spring and a contact; a contact is a fixed patch that only "
                                         "pushes: remove 'contact' or 'spring_N_per_mm3'");
  return s;
}

SolverSpec parse_solver(const Value& v) {
  const Map map(v, {"degree", "linear_solver", "tolerance", "max_iterations"});
  SolverSpec s;
  s.where = v.at;
  if (auto x = map.find("degree")) {
    const long long n = to_whole(*x);
    if (n != 1 && n != 2) fail(x->at, "solver.degree is " + std::to_string(n) + "; use 1 (Q1) or 2 (Q2)");
    s.degree = static_cast<int>(n);
  }
  if (auto x = map.find("linear_solver")) {
    s.linear_solver_at = x->at;
    s.linear_solver = to_choice<LinearSolverChoice>(*x, {{"auto", LinearSolverChoice::kAuto},
                                                         {"cg_amg", LinearSolverChoice::kCgAmg},
                                                         {"direct", LinearSolverChoice::kDirect}});
  }
  if (auto x = map.find("tolerance")) {
    s.tolerance_at = x->at;
    s.tolerance = to_number(*x);
    if (s.tolerance <= 0 || s.tolerance >= 1)
      fail(x->at, "solver.tolerance is " + fmt(s.tolerance) +
                      " but a relative tolerance must lie in (0, 1); the default is 1e-10");
  }
  if (auto x = map.find("max_iterations")) {
    s.max_iterations_at = x->at;
    const long long n = to_whole(*x);
    if (n <= 0 || n > std::numeric_limits<int>::max())
      fail(x->at, "solver.max_iterations is " + std::to_string(n) + " but must be from 1 to " +
                      std::to_string(std::numeric_limits<int>::max()) + "; the default is 10000");
    s.max_iterations = static_cast<int>(n);
  }
  return s;
}

Outputs parse_outputs(const Value& v) {
  const Map map(v, {"vtu", "inp", "bite_force"});
  Outputs o;
  if (auto x = map.find("vtu")) o.vtu = to_bool(*x);
  if (auto x = map.find("inp")) o.inp = to_bool(*x);
  if (auto x = map.find("bite_force")) o.bite_force = to_bool(*x);
  return o;
}

template <typename T>
void check_unique_names(const std::vector<T>& items, const std::string& kind) {
  for (size_t i = 0; i < items.size(); ++i)
    for (size_t j = 0; j < i; ++j) {
      if (items[i].name != items[j].name) continue;
      // The list order is not the file's: the muscles of an activation_pattern come after the muscles
      // list, wherever the pattern is written. The message names the later place and the earlier line.
      // At each name's own place when it has one (a study's rename), else at the item.
      const SourceLocation* first = items[j].name_at.line ? &items[j].name_at : &items[j].where;
      const SourceLocation* second = items[i].name_at.line ? &items[i].name_at : &items[i].where;
      if (first->file == second->file &&
          std::tie(second->line, second->column) < std::tie(first->line, first->column))
        std::swap(first, second);
      // A name written elsewhere than its item (a study's rename) is the one to name, whichever item comes
      // first in the list.
      const auto renamed = [](const T& item) {
        return item.name_at.line > 0 && item.name_at.file != item.where.file;
      };
      if (renamed(items[j]) && !renamed(items[i])) std::swap(first, second);
      fail(*second, kind + " " + quote(items[i].name) + " is defined twice (first on line " +
                        std::to_string(first->line) +
                        (first->file == second->file ? "" : " of " + first->file) + "); give each " + kind +
                        " its own name");
    }
}

// Linear (Q1) hexes lock as the material nears incompressibility: on the built-in mandible (4,025 hexes)
// their largest displacement is 0.89 of the Q2 value at poisson 0.28, 0.84 at 0.45, 0.70 at 0.49, 0.37 at
// 0.499 and 0.11 at 0.4999 (von Mises maximum 0.61, 0.60, 0.53, and 0.07 at 0.4999). Above 0.45 they are
// refused.
constexpr double kMaxPoissonQ1 = 0.45;

void check_poisson_for_degree(const Scenario& s) {
  if (s.solver.degree != 1) return;
  std::vector<const MaterialSpec*> materials = {&s.materials.default_material};
  for (const MaterialRegion& region : s.materials.regions) materials.push_back(&region.material);
  for (const MaterialSpec* m : materials)
    if (m->poisson > kMaxPoissonQ1)
      fail(m->poisson_at,
           "poisson " + fmt(m->poisson) + " with solver.degree 1: linear hexes lock when the material is " +
               "nearly incompressible (volumetric locking: on the built-in mandible their displacement is "
               "0.89 " +
               "of the Q2 value at 0.28, 0.70 at 0.49 and 0.11 at 0.4999); write solver: {degree: 2} for a " +
               "Poisson's ratio above " + fmt(kMaxPoissonQ1) + ", or use at most " + fmt(kMaxPoissonQ1));
}

// Checks that can be made before the geometry exists: something loads the bone, something holds it.
void check_loads_and_supports(const Scenario& s, const Map& root) {
  const SourceLocation muscles_at = root.has("muscles")              ? written_at(root, "muscles")
                                    : root.has("activation_pattern") ? written_at(root, "activation_pattern")
                                                                     : root.at();
  if (std::none_of(s.muscles.begin(), s.muscles.end(), [](const Muscle& m) { return m.activation > 0; }))
    fail(muscles_at,
         "no muscle is active, so nothing loads the mandible; give at least one muscle an activation "
         "above 0 in 'muscles' or 'activation_pattern'");
  const SourceLocation supports_at = root.has("supports") ? written_at(root, "supports") : root.at();
  if (s.supports.empty())
    fail(supports_at,
         "the scenario has no supports: nothing holds the mandible, so it could move as a rigid body "
         "and the problem is singular; add support patches, e.g. both condyles "
         "(- {name: right_condyle, at: right_condyle_tmj_point, radius_mm: 6})");
  std::array<bool, 3> held{false, false, false};
  for (const Support& support : s.supports)
    for (int axis = 0; axis < 3; ++axis)
      held[axis] = held[axis] || support.spring_N_per_mm3 || support.fixed[axis];
  for (int axis = 0; axis < 3; ++axis)
    if (!held[axis])
      fail(supports_at, std::string("no support holds the mandible along ") + "xyz"[axis] +
                            ", so it could slide freely and the problem is singular; add that component to a "
                            "support's 'fixed' list or use a spring support");
  if (s.outputs.bite_force &&
      std::none_of(s.supports.begin(), s.supports.end(), [](const Support& x) { return x.bite; }))
    fail(supports_at,
         "no support is marked 'bite: true', but the bite force is reported (outputs.bite_force is true "
         "by default); mark the biting patch with 'bite: true', or set outputs.bite_force: false");
}

double distance(const Vec3& a, const Vec3& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                   (a[2] - b[2]) * (a[2] - b[2]));
}

Vec3 quad_centroid(const QuadSurface& surface, const std::array<int, 4>& quad) {
  Vec3 c{0, 0, 0};
  for (int v : quad)
    for (int k = 0; k < 3; ++k) c[k] += 0.25 * surface.vertices[v][k];
  return c;
}

}  // namespace

Scenario parse_scenario_tree(const YAML::Node& root_node, const Source& ctx) {
  const SourceLocation top{ctx.file, 1, 1, ctx.note};
  if (!root_node.IsDefined() || root_node.IsNull())
    fail(top,
         "the scenario file is empty; it needs at least 'name', 'geometry', 'supports' and the muscle "
         "forces ('muscles' or 'activation_pattern') "
         "(see docs/scenario-format.md)");
  const Value root_value{&ctx, root_node, top, ""};
  if (!root_node.IsMap())
    fail(root_value.at, "a scenario must be a mapping of 'key: value' entries starting with 'name:', found " +
                            describe(root_node) + "; see docs/scenario-format.md");
  if (root_node["base"] && root_node["variants"])
    fail(root_value.at,
         "this is a study file (it has 'base' and 'variants'), not a scenario: run it with "
         "`hexbite study " +
             ctx.file + " -o DIR`, or give a scenario file");
  const Map root(root_value,
                 {"format_version", "name", "description", "geometry", "landmarks", "mesh", "materials",
                  "muscles", "activation_pattern", "supports", "solver", "outputs", "probes"});
  Scenario s;
  s.path = ctx.file;
  if (auto x = root.find("format_version")) {
    const long long n = to_whole(*x);
    if (n != 1)
      fail(x->at,
           "format_version " + std::to_string(n) +
               " is not known to this hexbite, which reads format_version 1; update hexbite or the file");
    s.format_version = 1;
  }
  s.name = to_name(root.require("name", "name: lateral_bite"));
  if (auto x = root.find("description"))
    s.description = x->node.IsScalar() && x->node.Scalar().empty() ? "" : to_string(*x, kTextHint);
  s.geometry = parse_geometry(ctx, root.require("geometry", "geometry: {mandible: {variant: dentate}}"));
  s.landmarks = parse_landmarks(ctx, root.find("landmarks"), s.geometry);
  if (auto x = root.find("mesh")) s.mesh = parse_mesh(*x);
  if (auto x = root.find("materials")) s.materials = parse_materials(*x);
  if (auto x = root.find("muscles"))
    for (const Value& item : to_list(*x)) s.muscles.push_back(parse_muscle(item));
  if (auto x = root.find("activation_pattern"))
    for (Muscle& m : parse_activation_pattern(ctx, *x)) s.muscles.push_back(std::move(m));
  if (auto x = root.find("supports"))
    for (const Value& item : to_list(*x)) s.supports.push_back(parse_support(item));
  if (auto x = root.find("solver")) s.solver = parse_solver(*x);
  if (auto x = root.find("outputs")) s.outputs = parse_outputs(*x);
  if (auto x = root.find("probes"))
    for (const Value& item : to_list(*x)) {
      const Map p(item, {"name", "at"});
      const Value& name = p.require("name", "name: chin");
      s.probes.push_back({to_name(name, "write a name such as chin"),
                          to_point(p.require("at", "at: incisal_point")), item.at, name.at});
    }
  check_poisson_for_degree(s);
  check_unique_names(s.muscles, "muscle");
  check_unique_names(s.supports, "support");
  check_unique_names(s.probes, "probe");
  check_loads_and_supports(s, root);
  if (s.mesh.refine_at_bite &&
      std::none_of(s.supports.begin(), s.supports.end(), [](const Support& x) { return x.bite; }))
    fail(s.mesh.refine_at_bite_at,
         "mesh.refine_at_bite refines around the bite supports' points, but no support has bite: true; mark "
         "the biting patch with bite: true, or remove refine_at_bite");
  return s;
}

Scenario load_scenario(const std::string& path) {
  const std::string text = read_yaml_text(path, "scenario");
  const Source source{path, fs::path(path).parent_path(), "", {}};
  return parse_scenario_tree(parse_yaml_document(text, path, "scenario"), source);
}

void resolve_points(Scenario& s, const Landmarks& landmarks) {
  std::map<std::string, Vec3> known = landmarks.points;
  for (const MuscleLine& m : landmarks.muscles) {
    known[m.name + ".insertion"] = m.insertion;
    known[m.name + ".origin"] = m.origin;
  }
  for (const NamedPoint& p : s.landmarks.points) {
    if (known.count(p.name))
      fail(p.where, ambiguous_name_text("extra point " + quote(p.name), "a landmark", "the landmark"));
    known[p.name] = p.xyz;
  }
  std::vector<std::string> known_names;
  for (const auto& [name, xyz] : known) known_names.push_back(name);

  auto resolve = [&](PointRef& p) {
    if (p.resolved) return;
    const auto it = known.find(p.name);
    if (it == known.end()) {
      if (known_names.empty())
        fail(p.where,
             "unknown point name " + quote(p.name) +
                 ": there are no named points (no landmarks and no landmarks.points); give coordinates "
                 "[x, y, z] or add the point to landmarks.points");
      fail(p.where,
           "unknown point name " + quote(p.name) + "; the closest known names are " +
               join_quoted(closest_names(p.name, known_names, 3)) +
               "; use a landmark, a landmarks.points name, '<muscle>.insertion' or '<muscle>.origin', "
               "or coordinates [x, y, z]");
    }
    p.xyz = it->second;
    p.resolved = true;
  };

  std::vector<std::string> muscle_names;
  for (const MuscleLine& m : landmarks.muscles) muscle_names.push_back(m.name);
  for (Muscle& m : s.muscles) {
    const auto line = std::find_if(landmarks.muscles.begin(), landmarks.muscles.end(),
                                   [&](const MuscleLine& l) { return l.name == m.name; });
    const bool uses_defaults = (!m.insertion.resolved && m.insertion.name == m.name + ".insertion") ||
                               (m.origin && !m.origin->resolved && m.origin->name == m.name + ".origin") ||
                               !m.max_force_N;
    if (line == landmarks.muscles.end() && !m.pattern_key.empty()) {
      // A landmark set with one side of the muscle only (a half jaw's file): the pattern key is right, the
      // side is missing, so suggest the side that exists, with the activation the pattern gives it.
      const bool left = m.name.rfind("left_", 0) == 0;
      const std::string other_side = left ? "right" : "left";
      const std::string other = other_side + "_" + m.pattern_key;
      if (std::find(muscle_names.begin(), muscle_names.end(), other) != muscle_names.end()) {
        const auto pattern_other = std::find_if(s.muscles.begin(), s.muscles.end(),
                                                [&](const Muscle& o) { return o.name == other; });
        fail(m.where, "activation_pattern key " + quote(m.pattern_key) + " makes " + m.name +
                          ", but the landmarks have " + other + " only; activate that side alone (" +
                          m.pattern_key + ": {" + other_side + ": " +
                          fmt(pattern_other != s.muscles.end() ? pattern_other->activation : m.activation) +
                          "}), or add " + m.name + " to the landmark file");
      }
      // A pattern muscle takes everything from the landmarks: name the pattern key and the keys that exist.
      std::vector<std::string> bases;
      for (const std::string& name : muscle_names)
        for (const char* side : {"left_", "right_"})
          if (name.rfind(side, 0) == 0 &&
              std::find(bases.begin(), bases.end(), name.substr(std::strlen(side))) == bases.end())
            bases.push_back(name.substr(std::strlen(side)));
      fail(m.where, "activation_pattern key " + quote(m.pattern_key) + " is no muscle of the landmarks (" +
                        m.name + " is unknown)" +
                        (bases.empty() ? "; they have no muscles, so list each muscle in muscles with its "
                                         "insertion, origin or direction, and max_force_N"
                                       : "; the closest pattern keys are " +
                                             join_quoted(closest_names(m.pattern_key, bases, 3)) +
                                             ": correct the key, or list a muscle of your own in muscles"));
    }
    if (line == landmarks.muscles.end() && uses_defaults)
      fail(m.where,
           "muscle " + quote(m.name) + " is not a muscle of the landmarks" +
               (muscle_names.empty()
                    ? " (they have none)"
                    : " (closest: " + join_quoted(closest_names(m.name, muscle_names, 3)) + ")") +
               ", so its insertion, origin and max_force_N have no default; correct the name or give all "
               "three ('direction' may replace 'origin')");
    if (!m.max_force_N) m.max_force_N = line->max_force_N;
    // A landmark file may give a muscle 0 N (the scenario may not); activated, it loads nothing, and with
    // no other active muscle the run solved a load of zero and reported a bite force of 0 N with exit 0.
    if (m.activation > 0 && !(*m.max_force_N > 0))
      fail(m.where, "muscle " + quote(m.name) + " is active (" + fmt(m.activation) +
                        ") but its max_force_N from the landmarks is 0 N, so it would load nothing; give it "
                        "a max_force_N in muscles, or set its activation to 0");
    resolve(m.insertion);
    Vec3 d;
    if (m.origin) {
      resolve(*m.origin);
      for (int k = 0; k < 3; ++k) d[k] = m.origin->xyz[k] - m.insertion.xyz[k];
    } else {
      d = *m.direction;
    }
    const double length = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (length < 1e-9)
      fail(m.origin ? m.origin->where : m.where,
           "muscle " + quote(m.name) + " has a zero line of action: its origin equals its insertion " +
               fmt(m.insertion.xyz, format_rounded) +
               "; move the origin or give 'direction: [x, y, z]' instead");
    for (int k = 0; k < 3; ++k) m.line_of_action[k] = d[k] / length;
  }
  for (Support& support : s.supports) resolve(support.at);
  for (Probe& probe : s.probes) resolve(probe.at);
  for (MaterialRegion& region : s.materials.regions) {
    if (region.shape == RegionShape::kSphere) {
      resolve(region.center);
      continue;
    }
    resolve(region.min);
    resolve(region.max);
    for (int k = 0; k < 3; ++k)
      if (region.min.xyz[k] >= region.max.xyz[k])
        fail(region.where, "material region " + quote(region.name) + ": box min " + fmt(region.min.xyz) +
                               " is not below max " + fmt(region.max.xyz) + " in " + "xyz"[k] +
                               "; min must be the lower corner and max the upper one");
  }
}

int region_at(const Materials& materials, const Vec3& x) {
  for (int i = static_cast<int>(materials.regions.size()) - 1; i >= 0; --i) {
    const MaterialRegion& r = materials.regions[static_cast<std::size_t>(i)];
    const bool inside = r.shape == RegionShape::kSphere
                            ? distance(x, r.center.xyz) <= r.radius_mm
                            : (x[0] >= r.min.xyz[0] && x[0] <= r.max.xyz[0] && x[1] >= r.min.xyz[1] &&
                               x[1] <= r.max.xyz[1] && x[2] >= r.min.xyz[2] && x[2] <= r.max.xyz[2]);
    if (inside) return i;
  }
  return -1;
}

MaterialSpec material_at(const Materials& materials, const Vec3& x) {
  const int i = region_at(materials, x);
  return i < 0 ? materials.default_material : materials.regions[static_cast<std::size_t>(i)].material;
}

double distance_outside(const MaterialRegion& r, const Vec3& x) {
  if (r.shape == RegionShape::kSphere) return std::max(0.0, distance(x, r.center.xyz) - r.radius_mm);
  double sum = 0;
  for (int k = 0; k < 3; ++k) {
    const double d = std::max({r.min.xyz[k] - x[k], 0.0, x[k] - r.max.xyz[k]});
    sum += d * d;
  }
  return std::sqrt(sum);
}

Vec3 muscle_force(const Muscle& muscle) {
  const double magnitude = muscle.activation * muscle.max_force_N.value_or(0);
  return {magnitude * muscle.line_of_action[0], magnitude * muscle.line_of_action[1],
          magnitude * muscle.line_of_action[2]};
}

std::vector<int> select_patch_quads(const QuadSurface& boundary, const Vec3& center, double radius) {
  std::vector<int> selected;
  for (size_t q = 0; q < boundary.quads.size(); ++q)
    if (distance(quad_centroid(boundary, boundary.quads[q]), center) <= radius)
      selected.push_back(static_cast<int>(q));
  return selected;
}

std::vector<int> require_patch_quads(const QuadSurface& boundary, const Vec3& center, double radius,
                                     const SourceLocation& where, const std::string& what) {
  std::vector<int> selected = select_patch_quads(boundary, center, radius);
  if (!selected.empty()) return selected;
  if (boundary.quads.empty())
    fail(where, what + " selects no surface facets because the mesh boundary has none");
  double nearest = std::numeric_limits<double>::infinity();
  for (const auto& quad : boundary.quads)
    nearest = std::min(nearest, distance(quad_centroid(boundary, quad), center));
  const std::string found =
      what + " selects no surface facets: no boundary facet centre lies within radius_mm = " + fmt(radius) +
      " of " + fmt(center, format_rounded) + ", the nearest is " + format_rounded(nearest) + " mm away";
  // Farther than any patch may reach: a larger radius is no remedy (it is refused), the point is off the
  // meshed bone (a wrong coordinate or unit, or a part of the bone that a coarse mesh lost).
  if (nearest > kMaxPatchRadiusMm)
    fail(where,
         found + ", farther than any patch reaches (radius_mm is at most " + fmt(kMaxPatchRadiusMm) +
             " mm), so the point is not on the meshed bone: check its coordinates and their unit, or, if "
             "the coarse mesh lost that part of the bone, make it finer (mesh.target_hexes)");
  fail(where, found +
                  "; increase radius_mm beyond that, move the point onto the bone surface, or refine "
                  "the mesh");
}

}  // namespace hexbite
