#include "mesher/landmarks.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <sstream>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/number_format.h"
#include "common/paths.h"
#include "common/suggestion.h"
#include "mesher/surface_projector.h"
#include "mesher/units.h"
#include "mesher/vec3.h"
#include "mesher/yaml_scalars.h"

namespace hexbite {

namespace {

// Every message names the file and the 1-based line and column (as the scenario's messages do) so that a
// user can go straight to the mistake.
[[noreturn]] void fail(const std::string& path, const YAML::Mark& mark, const std::string& what) {
  std::string where = path;
  if (!mark.is_null()) where += ":" + std::to_string(mark.line + 1) + ":" + std::to_string(mark.column + 1);
  throw InputError("landmark file " + where + ": " + what);
}

// Records that `name` is given at `mark`; a name given twice (a landmark and a muscle share the names) is
// refused with the line of its first place.
void claim_name(const std::string& path, const YAML::Mark& mark, const std::string& name,
                std::map<std::string, int>& names) {
  const auto [first, fresh] = names.emplace(name, mark.is_null() ? 0 : mark.line + 1);
  if (!fresh)
    fail(path, mark,
         "name '" + name + "' is given twice" +
             (first->second > 0 ? " (first on line " + std::to_string(first->second) + ")" : std::string()) +
             "; keep one");
}

// Numbers as a scenario takes them: plain, not quoted (yaml_scalars.h).
double read_number(const std::string& path, const YAML::Node& node, const std::string& what) {
  const std::optional<double> value = plain_number(node);
  if (!value) fail(path, node.Mark(), what + " must be a number, " + number_expected(node));
  return *value;
}

// A point in mm, each coordinate within kMaxCoordinateMm like a scenario's own (scenarios/scenario.cc), also
// after the conversion from the file's unit.
Vec3 read_point(const std::string& path, const YAML::Node& node, const std::string& what, double scale) {
  if (!node.IsSequence() || node.size() != 3)
    fail(path, node.Mark(), what + " must be a list of three coordinates [x, y, z]");
  Vec3 p{};
  for (std::size_t k = 0; k < 3; ++k) {
    const double value = read_number(path, node[k], what + " coordinate");
    p[k] = scale * value;
    if (!(std::abs(p[k]) <= kMaxCoordinateMm))
      fail(path, node[k].Mark(),
           what + " coordinate is " + format_significant(p[k]) +
               (scale == 1.0 ? "" : " mm (" + format_significant(value) + " in the file's unit)") +
               ", beyond " + format_significant(kMaxCoordinateMm) +
               " mm in size; give the coordinates in the frame and unit of the surface (a mandible spans "
               "about 100 mm)");
  }
  return p;
}

void read_muscle(const std::string& path, const YAML::Node& node, double scale, Landmarks& out,
                 std::map<std::string, int>& names) {
  if (!node.IsMap())
    fail(path, node.Mark(), "each muscle must be a map {name, max_force_N, insertion, origin}");
  MuscleLine m;
  // The name may follow the points in the map; the messages about them give it.
  const YAML::Node name = node["name"];
  const std::string muscle =
      name && name.IsScalar() && !name.Scalar().empty() ? "muscle '" + name.Scalar() + "' " : "muscle ";
  bool has[4] = {false, false, false, false};
  for (const auto& kv : node) {
    const std::string key = kv.first.as<std::string>();
    if (key == "name") {
      if (!kv.second.IsScalar() || kv.second.Scalar().empty())
        fail(path, kv.second.Mark(), "muscle name must be a non-empty string");
      m.name = kv.second.Scalar();
      has[0] = true;
    } else if (key == "max_force_N") {
      m.max_force_N = read_number(path, kv.second, muscle + "max_force_N");
      if (m.max_force_N < 0) fail(path, kv.second.Mark(), muscle + "max_force_N must not be negative");
      if (m.max_force_N > kMaxMuscleForceN)
        fail(path, kv.second.Mark(),
             muscle + "max_force_N is " + format_significant(m.max_force_N) + " N, more than " +
                 format_significant(kMaxMuscleForceN) +
                 " N; no jaw muscle comes near (the superficial masseter gives about 190 N): give the force "
                 "in newtons");
      has[1] = true;
    } else if (key == "insertion") {
      m.insertion = read_point(path, kv.second, muscle + "insertion", scale);
      has[2] = true;
    } else if (key == "origin") {
      m.origin = read_point(path, kv.second, muscle + "origin", scale);
      has[3] = true;
    } else {
      fail(path, kv.first.Mark(),
           "unknown muscle key '" + key + "'; " +
               suggestion(key, {"name", "max_force_N", "insertion", "origin"}, "muscle keys"));
    }
  }
  static const char* const kKeys[4] = {"name", "max_force_N", "insertion", "origin"};
  for (int k = 0; k < 4; ++k)
    if (!has[k])
      fail(
          path, node.Mark(),
          std::string("muscle ") + (m.name.empty() ? "" : "'" + m.name + "' ") + "has no '" + kKeys[k] + "'");
  claim_name(path, node.Mark(), m.name, names);
  out.muscles.push_back(std::move(m));
}

std::string format_point(const Vec3& p) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "[%.4f, %.4f, %.4f]", p[0], p[1], p[2]);
  return buf;
}

std::string format_number(double v) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.4f", v);
  return buf;
}

}  // namespace

std::string ambiguous_name_text(const std::string& point, const std::string& other,
                                const std::string& other_short) {
  return point + " has the name of " + other + ", so the name would be ambiguous; rename it or use " +
         other_short;
}

std::optional<Vec3> Landmarks::find(const std::string& name) const {
  if (auto it = points.find(name); it != points.end()) return it->second;
  const auto dot = name.rfind('.');
  if (dot == std::string::npos) return std::nullopt;
  const std::string muscle = name.substr(0, dot), part = name.substr(dot + 1);
  for (const auto& m : muscles) {
    if (m.name != muscle) continue;
    if (part == "insertion") return m.insertion;
    if (part == "origin") return m.origin;
  }
  return std::nullopt;
}

Landmarks read_landmarks(const std::string& path, double scale_to_mm) {
  require_regular_file(path, "landmark file");
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw InputError("cannot read landmark file '" + path + "'");
  } catch (const YAML::ParserException& e) {
    fail(path, e.mark, "not valid YAML: " + e.msg);
  }
  if (root.IsNull()) throw InputError("landmark file '" + path + "' is empty");
  if (!root.IsMap()) fail(path, root.Mark(), "expected a map with 'landmarks:' and 'muscles:'");

  Landmarks out;
  std::map<std::string, int> names;               // name -> the 1-based line where it is first given
  std::map<std::string, YAML::Mark> point_marks;  // landmark name -> its key
  try {
    for (const auto& kv : root) {
      const std::string key = kv.first.as<std::string>();
      const YAML::Node& value = kv.second;
      if (key == "landmarks") {
        if (value.IsNull()) continue;
        if (!value.IsMap()) fail(path, value.Mark(), "'landmarks' must map names to [x, y, z]");
        for (const auto& lm : value) {
          const std::string name = lm.first.as<std::string>();
          claim_name(path, lm.first.Mark(), name, names);
          point_marks.emplace(name, lm.first.Mark());
          out.points[name] = read_point(path, lm.second, "landmark '" + name + "'", scale_to_mm);
        }
      } else if (key == "muscles") {
        if (value.IsNull()) continue;
        if (!value.IsSequence()) fail(path, value.Mark(), "'muscles' must be a list");
        for (const auto& m : value) read_muscle(path, m, scale_to_mm, out, names);
      } else {
        fail(
            path, kv.first.Mark(),
            "unknown section '" + key + "'; " +
                (key == "units" ? "a landmark file has no unit of its own: a scenario's landmarks.units says "
                                  "it, `hexbite mesh` reads it in the --units of its surface, and `hexbite "
                                  "reorder` in millimetres"
                                : suggestion(key, {"landmarks", "muscles"}, "sections")));
      }
    }
    // Landmarks::find and a scenario take "<muscle>.insertion" for the muscle's point, so a landmark of
    // that name would be silently shadowed by it.
    for (const auto& [name, mark] : point_marks) {
      const auto dot = name.rfind('.');
      if (dot == std::string::npos) continue;
      const std::string muscle = name.substr(0, dot), part = name.substr(dot + 1);
      if ((part == "insertion" || part == "origin") && names.count(muscle) && !out.points.count(muscle))
        fail(path, mark,
             ambiguous_name_text("landmark '" + name + "'",
                                 "the " + part + " of muscle '" + muscle + "' (line " +
                                     std::to_string(names.at(muscle)) + ")",
                                 "the muscle's " + part));
    }
  } catch (const YAML::Exception& e) {
    // Keys that are not scalars (e.g. a list used as a key) end up here; yaml-cpp says only "bad conversion".
    fail(path, e.mark, "expected a name (a plain word) as the key, not a list or map (YAML: " + e.msg + ")");
  }
  return out;
}

void write_landmarks(const std::string& path, const Landmarks& landmarks, const std::string& header_comment) {
  std::ostringstream s;
  std::istringstream header(header_comment);
  for (std::string line; std::getline(header, line);) s << (line.empty() ? "#" : "# " + line) << '\n';
  s << "landmarks:\n";
  for (const auto& [name, p] : landmarks.points) s << "  " << name << ": " << format_point(p) << '\n';
  s << "muscles:   # max_force_N is for one side\n";
  for (const auto& m : landmarks.muscles)
    s << "  - {name: " << m.name << ", max_force_N: " << format_number(m.max_force_N)
      << ", insertion: " << format_point(m.insertion) << ", origin: " << format_point(m.origin) << "}\n";
  write_file_atomically(path, s.str());
}

std::string landmark_fit_warning(const Landmarks& landmarks, const TriSurface& surface,
                                 const std::string& file, const std::string& unit, const std::string& how) {
  if (landmarks.muscles.empty() || surface.triangles.empty()) return {};
  const SurfaceProjector projector(surface);
  // The muscles by their insertions' distance to the surface, farthest first, with the coordinates scaled
  // by `factor` (another reading of the file's unit).
  const auto distances = [&](double factor) {
    std::vector<std::pair<double, std::string>> off;  // (distance, muscle)
    for (const MuscleLine& m : landmarks.muscles)
      off.emplace_back(projector.distance(vec3::scale(m.insertion, factor)), m.name);
    std::sort(off.begin(), off.end(), std::greater<>());
    return off;
  };
  const auto median = [](const std::vector<std::pair<double, std::string>>& off) {
    const std::size_t n = off.size();
    return n % 2 ? off[n / 2].first : 0.5 * (off[n / 2 - 1].first + off[n / 2].first);
  };
  const auto off = distances(1.0);
  const std::size_t n = off.size();
  if (median(off) <= kLandmarkFitMedianMm) return {};
  std::string farthest;
  for (std::size_t i = 0; i < std::min<std::size_t>(3, n); ++i) {
    char item[160];
    std::snprintf(item, sizeof item, "%s%s (%.1f mm)", i ? ", " : "", off[i].second.c_str(), off[i].first);
    farthest += item;
  }
  char text[200];
  std::snprintf(text, sizeof text, "its %zu muscle insertions lie a median %.1f mm from the surface", n,
                median(off));
  std::string advice =
      "check that the file was written for this surface and in its frame (+x the subject's left, +y "
      "posterior, +z superior)";
  for (const char* other : {"mm", "cm", "m"}) {
    if (other == unit) continue;
    const double fit = median(distances(unit_to_mm(other) / unit_to_mm(unit)));
    if (fit > kLandmarkFitMedianMm) continue;
    std::string fix = how;
    for (std::size_t at = fix.find("<unit>"); at != std::string::npos; at = fix.find("<unit>"))
      fix.replace(at, 6, other);
    char read[160];
    std::snprintf(read, sizeof read, "read in %s, they lie a median %.1f mm from it: ", other, fit);
    advice = read + fix;
    break;
  }
  return "landmark file " + file + ": " + text +
         " (they lie on the bone, within about 1 mm, when the file belongs to it); farthest: " + farthest +
         ". Placements and patches built from it will be off; " + advice;
}

std::vector<LeftRightPair> left_right_pairs(const Landmarks& landmarks) {
  std::map<std::string, Vec3> located = landmarks.points;  // points and insertions, by name
  for (const MuscleLine& m : landmarks.muscles) located.emplace(m.name + ".insertion", m.insertion);
  std::vector<LeftRightPair> pairs;
  for (const auto& [name, left] : located) {
    if (name.rfind("left_", 0) != 0) continue;
    const auto right = located.find("right_" + name.substr(5));
    if (right != located.end()) pairs.push_back({name, left, right->second});
  }
  return pairs;
}

std::string landmark_side_warning(const Landmarks& landmarks, const std::string& file) {
  const std::vector<LeftRightPair> pairs = left_right_pairs(landmarks);
  std::vector<const LeftRightPair*> swapped;  // left_ points at smaller x than their partners
  for (const LeftRightPair& p : pairs)
    if (p.left[0] < p.right[0]) swapped.push_back(&p);
  if (swapped.empty()) return {};
  // Named: the pair farthest apart, the plainest sign of a swap (insertions near the midline may cross).
  const LeftRightPair& first =
      **std::max_element(swapped.begin(), swapped.end(), [](const LeftRightPair* a, const LeftRightPair* b) {
        return a->right[0] - a->left[0] < b->right[0] - b->left[0];
      });
  char text[400];
  std::snprintf(text, sizeof text,
                "%s lies at x = %.1f mm, at smaller x than its partner right_%s (x = %.1f mm)",
                first.left_name.c_str(), first.left[0], first.left_name.substr(5).c_str(), first.right[0]);
  return "landmark file " + file + ": " + text +
         (swapped.size() > 1 ? " (and " + std::to_string(swapped.size() - 1) + " more of its " +
                                   std::to_string(pairs.size()) + " left/right pairs)"
                             : std::string()) +
         ", but the frame has +x on the subject's left, so left_ points lie at larger x than their right_ "
         "partners: the file's sides are swapped or mirrored, and a bite or muscle of one side would act "
         "on the other. Check the file's frame (+x the subject's left, +y posterior, +z superior), or "
         "swap left_ and right_ in its names";
}

}  // namespace hexbite
