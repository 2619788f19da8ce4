#include "scenarios/study.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <filesystem>
#include <functional>
#include <regex>

#include "scenarios/scenario_tree.h"
#include "scenarios/yaml_input.h"

namespace hexbite {

namespace {

namespace fs = std::filesystem;
using namespace yaml_input;
using json = nlohmann::ordered_json;

// The names of the tables a study writes beside its variants' folders.
const std::vector<std::string> kTableNames = {"study.json", "study.csv", "study.md"};

// "did you mean 'x'? (the <noun> are 'a', 'b')", or the list alone when nothing is close.
std::string choices(const std::string& given, const std::vector<std::string>& valid,
                    const std::string& noun) {
  if (valid.empty()) return "there are none";
  const std::string hint = suggestion(given, valid, noun);
  if (hint.rfind("did you mean", 0) != 0) return hint;
  return hint + " (the " + noun + " are " + join_quoted(valid) + ")";
}

// A YAML value as JSON, for study.json's `set`: the changes as written. A scalar is its text, quoted or
// not: which type it has is the scenario key's to say (`name: 007` is the text 007, `E_MPa: 5500` the
// number 5500, `fixed: [x, y, z]` three axes), and YAML's own reading of a plain scalar (7, 5500, true for
// `y`) misrecorded text. Nothing (`~`, `null`, no value) is null, as the scenario reads it.
json to_json(const YAML::Node& node) {
  if (!node.IsDefined() || node.IsNull()) return json();
  if (node.IsSequence()) {
    json out = json::array();
    for (const YAML::Node& item : node) out.push_back(to_json(item));
    return out;
  }
  if (node.IsMap()) {
    json out = json::object();
    for (auto it = node.begin(); it != node.end(); ++it) out[it->first.Scalar()] = to_json(it->second);
    return out;
  }
  return node.Scalar();
}

std::vector<std::string> split_path(const std::string& path) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  for (std::size_t dot = path.find('.');; dot = path.find('.', start)) {
    parts.push_back(path.substr(start, dot == std::string::npos ? std::string::npos : dot - start));
    if (dot == std::string::npos) break;
    start = dot + 1;
  }
  return parts;
}

// One `set` entry of a variant: the dotted path, where it was written and the value.
struct Setting {
  std::string path;
  SourceLocation at;  // the path's key in the study file
  YAML::Node value;
};

// Every node of `value` (map keys included), with its place in the study file, so that the variant's tree
// names them there. A null value carries the next line's mark; it is named at its key.
void collect_grafted(const YAML::Node& value, const SourceLocation& fallback, const Source& study,
                     std::vector<GraftedNode>* out) {
  const SourceLocation at = value.IsNull() ? fallback : study.locate(value, fallback);
  out->push_back({value, at, study.folder});
  if (value.IsSequence())
    for (const YAML::Node& item : value) collect_grafted(item, at, study, out);
  if (value.IsMap())
    for (auto it = value.begin(); it != value.end(); ++it) {
      out->push_back({it->first, study.locate(it->first, at), study.folder});
      collect_grafted(it->second, study.locate(it->first, at), study, out);
    }
}

// Puts `setting` into the base scenario's `tree`: the key at its dotted path is replaced (or added, for the
// last key of a mapping); list items are addressed by their `name`. Records the study's nodes in `grafted`.
void apply_setting(YAML::Node tree, const Setting& setting, const std::string& base, const Source& study,
                   std::vector<GraftedNode>* grafted) {
  const std::vector<std::string> parts = split_path(setting.path);
  const auto refuse = [&](const std::string& what) {
    fail(setting.at, "set " + quote(setting.path) + ": " + what);
  };
  YAML::Node node = tree;
  std::string walked;  // the part of the path followed so far, for messages
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const std::string& part = parts[i];
    const bool last = i + 1 == parts.size();
    const std::string where = walked.empty() ? "the base scenario " + quote(base) : quote(walked);
    if (part.empty()) refuse("the path has an empty part; write names separated by single dots");
    if (node.IsMap()) {
      std::vector<std::string> keys;
      bool found = false;
      for (auto it = node.begin(); it != node.end(); ++it) {
        keys.push_back(it->first.Scalar());
        if (it->first.Scalar() != part) continue;
        found = true;
        if (last) {
          YAML::Node target = it->second;
          target = setting.value;
        } else {
          node.reset(it->second);  // rebinds the handle; operator= would overwrite the node
        }
        break;
      }
      if (!found) {
        if (!last)
          refuse(where + " has no key " + quote(part) + " (a path may add only its last key); " +
                 choices(part, keys, "keys there"));
        node[part] = setting.value;
        for (auto it = node.begin(); it != node.end(); ++it)
          if (it->first.Scalar() == part) grafted->push_back({it->first, setting.at, study.folder});
      }
    } else if (node.IsSequence()) {
      std::vector<std::string> names;
      bool found = false;
      for (YAML::Node item : node) {
        // Looked up through a const node: a missing key is then not added.
        const YAML::Node name = item.IsMap() ? static_cast<const YAML::Node&>(item)["name"] : YAML::Node();
        names.push_back(name && name.IsScalar() ? name.Scalar() : "");
        if (names.back() != part) continue;
        found = true;
        if (last)
          item = setting.value;
        else
          node.reset(item);
        break;
      }
      names.erase(std::remove(names.begin(), names.end(), ""), names.end());
      if (!found)
        refuse(where + " has no item named " + quote(part) + " (list items are addressed by their name); " +
               choices(part, names, "names"));
    } else {
      refuse(where + " is " + describe(node) + ", not a mapping or a list, so it has no " + quote(part) +
             "; set " + quote(walked) + " itself");
    }
    walked += (walked.empty() ? "" : ".") + part;
  }
  collect_grafted(setting.value, setting.at, study, grafted);
}

// A variant's name becomes its output folder, beside the study's tables.
void check_variant_name(const std::string& name, const SourceLocation& at) {
  static const std::regex kSafe("[A-Za-z0-9][A-Za-z0-9._-]*");
  if (!std::regex_match(name, kSafe) || name.size() > 100)
    fail(at,
         "variant name " + quote(name) +
             " is not a safe folder name: it names the variant's output folder, so use letters, digits, "
             "'_', '-' and '.', starting with a letter or digit, at most 100 characters (e.g. soft_bone)");
  if (std::find(kTableNames.begin(), kTableNames.end(), name) != kTableNames.end())
    fail(at, "variant name " + quote(name) + " is the name of one of the study's tables (" +
                 join_quoted(kTableNames) + "), written beside the variants' folders; rename the variant");
}

}  // namespace

Study load_study(const std::string& path) {
  const std::string text = read_yaml_text(path, "study");
  const YAML::Node root = parse_yaml_document(text, path, "study");
  const Source study_source{path, fs::path(path).parent_path(), "", {}};
  const SourceLocation top{path, 1, 1, ""};
  if (!root.IsDefined() || root.IsNull())
    fail(top,
         "the study file is empty; it needs 'name', 'base' (a scenario file) and 'variants' (see "
         "docs/studies.md)");
  if (root.IsMap() && !root["base"] && !root["variants"] && (root["geometry"] || root["supports"]))
    fail(top,
         "this is a scenario file (it has no 'base' and no 'variants'), not a study: run it with "
         "`hexbite run " +
             path + " -o DIR`, or make it the base of a study (docs/studies.md)");
  const Map map({&study_source, root, top, ""}, {"name", "description", "base", "variants"}, "the study");
  Study study;
  study.path = path;
  study.name =
      to_name(map.require("name", "name: atrophy what-if"), "write a name such as 'atrophy what-if'");
  if (auto x = map.find("description"))
    study.description = x->node.IsScalar() && x->node.Scalar().empty() ? "" : to_string(*x, kTextHint);

  const Value& base = map.require("base", "base: ../lateral_bite_hard_nut.yaml (a scenario file)");
  const std::string given =
      to_string(base, "give the base scenario's file path, e.g. base: ../lateral_bite_hard_nut.yaml");
  fs::path base_path(given);
  if (base_path.is_relative()) base_path = study_source.folder / base_path;
  study.base = base_path.lexically_normal().string();
  std::error_code error;
  if (!fs::is_regular_file(study.base, error))
    fail(base.at, "base scenario " + quote(given) +
                      (study.base == given ? "" : " (resolved to " + quote(study.base) + ")") +
                      " does not exist or is not a file; give a scenario file relative to the study file's "
                      "folder, or an absolute path");
  const std::string base_text = read_yaml_text(study.base, "scenario");
  const Source base_source{study.base, fs::path(study.base).parent_path(), "", {}};

  const Value& variants = map.require("variants", "variants: [{name: reference}]");
  const std::vector<Value> items = to_list(variants);
  if (items.empty())
    fail(variants.at,
         "the study has no variants; list at least one, e.g. '- name: reference' (the base "
         "scenario as it is)");
  for (const Value& item : items) {
    const Map v(item, {"name", "set"});
    StudyVariant variant;
    variant.where = item.at;
    const Value& name = v.require("name", "name: soft_bone");
    variant.name = to_string(name, "write a name such as soft_bone (it names the variant's output folder)");
    check_variant_name(variant.name, name.at);
    for (const StudyVariant& earlier : study.variants)
      if (earlier.name == variant.name)
        fail(name.at, "variant " + quote(variant.name) + " is defined twice (first on line " +
                          std::to_string(earlier.where.line) +
                          "); give each variant its own name (it names the variant's output folder)");

    // The study's values, named in messages at their lines in the study file, with the variant.
    const std::string note = "variant " + quote(variant.name);
    Source study_values = study_source;
    study_values.note = note;
    std::vector<Setting> settings;
    variant.set = json::object();
    if (auto set = v.find("set")) {
      if (!set->node.IsNull() && !set->node.IsMap())
        fail(set->at, note + ": set must be a mapping 'dotted.path: value', found " + describe(set->node) +
                          "; write e.g. set: {materials.default.E_MPa: 5500}");
      for (auto it = set->node.begin(); set->node.IsMap() && it != set->node.end(); ++it) {
        const SourceLocation at = study_values.locate(it->first, set->at);
        if (!it->first.IsScalar() || it->first.Scalar().empty())
          fail(at, "a key of set is not a dotted path; write e.g. materials.default.E_MPa: 5500");
        const std::string key = it->first.Scalar();
        for (const Setting& earlier : settings)
          if (earlier.path == key)
            fail(at, "set " + quote(key) + " appears twice (first on line " +
                         std::to_string(earlier.at.line) + "); keep one");
        settings.push_back({key, at, it->second});
        variant.set[key] = to_json(it->second);
      }
    }

    // The variant's tree: the base scenario's own (parsed again, so that no variant sees another's values)
    // with the settings grafted in.
    YAML::Node tree = parse_yaml_document(base_text, study.base, "scenario");
    Source variant_source = base_source;
    variant_source.note = note + " of study " + path;
    // A base that is no mapping (an empty file) is refused by parse_scenario_tree at its own line.
    for (const Setting& setting : settings)
      if (tree.IsMap()) apply_setting(tree, setting, study.base, study_values, &variant_source.grafted);
    variant.scenario = parse_scenario_tree(tree, variant_source);
    study.variants.push_back(std::move(variant));
  }
  return study;
}

}  // namespace hexbite
