#include "postprocess/study_table.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "common/error.h"
#include "common/number_format.h"

namespace hexbite {

namespace {

using json = nlohmann::ordered_json;

// The figures of a row, their column labels and the decimals `hexbite run` prints them with.
struct Figure {
  const char* key;
  const char* label;
  int decimals;
};
const Figure kFigures[] = {{"bite_force_N", "bite force (N)", 2},
                           {"max_displacement_mm", "max displacement (mm)", 5},
                           {"von_mises_max_MPa", "von Mises max (MPa)", 3},
                           {"von_mises_p99_MPa", "von Mises p99 (MPa)", 3},
                           {"strain_energy_mJ", "strain energy (mJ)", 5}};

json relative(const json& value, const json& reference) {
  if (!value.is_number() || !reference.is_number() || reference.get<double>() == 0.0) return json();
  return (value.get<double>() - reference.get<double>()) / std::abs(reference.get<double>());
}

// The supports of all variants, in the order they first appear (a variant may add or rename one).
std::vector<std::string> support_names(const json& study) {
  std::vector<std::string> names;
  for (const json& v : study["variants"])
    for (const auto& [name, magnitude] : v["reactions"].items())
      if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
  return names;
}

// True when `support` was a contact released in a row of study.json (its reaction, 0, is not a measure).
bool released(const json& row, const std::string& support) {
  return row.contains("released") &&
         std::find(row["released"].begin(), row["released"].end(), support) != row["released"].end();
}

// The reaction of `support` in a row of study.json, or null.
json reaction(const json& row, const std::string& support) {
  return row["reactions"].contains(support) ? row["reactions"][support] : json();
}

std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string out = "\"";
  for (char c : text) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::string csv_number(const json& value) {
  return value.is_number() ? value.dump() : "";
}

std::string markdown_cell(std::string text) {
  for (std::size_t at = text.find('|'); at != std::string::npos; at = text.find('|', at + 2))
    text.replace(at, 1, "\\|");
  // A line break (a set value "a\nb") ended the table row.
  std::replace(text.begin(), text.end(), '\n', ' ');
  std::replace(text.begin(), text.end(), '\r', ' ');
  return text;
}

// `text` as a Markdown code span: fenced by one backtick more than its longest run of backticks, with a space
// inside the fences when it starts or ends with one (CommonMark), so that a backtick in a set value does not
// end the span.
std::string markdown_code(const std::string& text) {
  std::size_t longest = 0, run = 0;
  for (char c : text) {
    run = c == '`' ? run + 1 : 0;
    longest = std::max(longest, run);
  }
  const std::string fence(longest + 1, '`');
  const std::string pad = !text.empty() && (text.front() == '`' || text.back() == '`') ? " " : "";
  return fence + pad + text + pad + fence;
}

// "362.04", or "362.04 (-1.4 %)" with the relative change when `compared` (not the reference's own row);
// "—" for a missing figure, "362.04 (—)" for a change that has none (the reference's figure is missing or
// zero).
std::string markdown_figure(const json& value, const json& change, bool compared, int decimals) {
  if (!value.is_number()) return "—";
  std::string text = format_table_number(value.get<double>(), decimals, 0);
  if (compared && !change.is_number()) return text + " (—)";
  if (compared) {
    // One decimal: a report compares variants by per cent, and the round-off of equal figures (1e-13 %)
    // reads as 0.0 %; study.csv and study.json keep every digit.
    const double percent = 100.0 * change.get<double>();
    char cell[64];
    std::snprintf(cell, sizeof cell, std::abs(percent) < 0.05 ? " (0.0 %%)" : " (%+.1f %%)", percent);
    text += cell;
  }
  return text;
}

// `set`'s value as a YAML node: its text scalars (scenarios/study.cc records every scalar as written) as
// text, null as null; a number of an older study.json as its JSON text.
YAML::Node yaml_node(const json& value) {
  if (value.is_array()) {
    YAML::Node node(YAML::NodeType::Sequence);
    for (const json& item : value) node.push_back(yaml_node(item));
    return node;
  }
  if (value.is_object()) {
    YAML::Node node(YAML::NodeType::Map);
    for (const auto& [key, item] : value.items()) node[key] = yaml_node(item);
    return node;
  }
  if (value.is_null()) return YAML::Node(YAML::NodeType::Null);
  return YAML::Node(value.is_string() ? value.get<std::string>()
                                      : value.dump(-1, ' ', false, json::error_handler_t::replace));
}

// A value of `set` in YAML's flow style, as a study writes it: [x, y, z], {right: 0.8, left: 0.47};
// yaml-cpp's emitter quotes what YAML would read otherwise.
std::string yaml_flow(const json& value) {
  YAML::Emitter out;
  out.SetSeqFormat(YAML::Flow);
  out.SetMapFormat(YAML::Flow);
  out << yaml_node(value);
  return out.c_str();
}

}  // namespace

std::string study_changes(const json& set, bool abbreviate) {
  std::string out;
  for (const auto& [path, value] : set.items()) {
    std::string text = value.is_string() ? value.get<std::string>() : yaml_flow(value);
    if (abbreviate && text.size() > 40 && value.is_structured()) text = value.is_object() ? "{...}" : "[...]";
    // On one line (studies.md): a YAML block text (`description: |`) kept its line breaks in the CSV cell. A
    // tab, a Unicode line or paragraph separator and U+0085 (NEXT LINE) are spaces too.
    for (const std::string separator : {"\u2028", "\u2029", "\u0085"})
      for (std::size_t at = text.find(separator); at != std::string::npos; at = text.find(separator, at))
        text.replace(at, separator.size(), " ");
    std::string line;
    for (char c : text) {
      if (c == '\n' || c == '\r' || c == '\t') c = ' ';
      if (c != ' ' || (!line.empty() && line.back() != ' ')) line += c;
    }
    while (!line.empty() && line.back() == ' ') line.pop_back();
    // Any other control character (a scenario's description may hold ESC or NUL) went raw into the tables
    // and onto the terminal, where "\x1b[2J" cleared the screen: written \xNN, as in messages.
    out += (out.empty() ? "" : "; ") + path + ": " + printable_message(line);
  }
  return out;
}

json study_json(const StudyTable& table) {
  json variants = json::array();
  for (const StudyRow& row : table.rows) {
    json reactions = json::object();
    for (const auto& [name, magnitude] : row.reactions) reactions[name] = magnitude;
    variants.push_back({{"name", row.name},
                        {"set", row.set},
                        {"level", row.level},
                        {"hexes", row.hexes},
                        {"bite_force_N", row.bite_force_N ? json(*row.bite_force_N) : json()},
                        {"max_displacement_mm", row.max_displacement_mm},
                        {"von_mises_max_MPa", row.von_mises_max_MPa},
                        {"von_mises_p99_MPa", row.von_mises_p99_MPa},
                        {"strain_energy_mJ", row.strain_energy_mJ},
                        {"reactions", reactions},
                        {"released", row.released}});
  }
  json study = {
      {"study", table.study}, {"study_file", table.study_file}, {"base", table.base}, {"variants", variants}};
  // Every row holds every support of any variant, null where the variant has none, as the CSV's columns do:
  // a support renamed by the study was left out of the other variants' rows, where scripts read it.
  const std::vector<std::string> supports = support_names(study);
  for (json& v : study["variants"]) {
    json reactions = json::object();
    for (const std::string& s : supports) reactions[s] = reaction(v, s);
    v["reactions"] = reactions;
  }
  for (json& v : study["variants"]) {
    const json& reference = study["variants"].front();
    json change = json::object();
    for (const Figure& f : kFigures) change[f.key] = relative(v[f.key], reference[f.key]);
    json reactions = json::object();
    // A released contact's 0 is not a measured reaction: no relative change to or from it.
    for (const std::string& s : supports)
      reactions[s] = released(v, s) || released(reference, s)
                         ? json()
                         : relative(reaction(v, s), reaction(reference, s));
    change["reactions"] = reactions;
    v["relative_to_reference"] = change;
  }
  return study;
}

std::string study_csv(const json& study) {
  const std::vector<std::string> supports = support_names(study);
  std::ostringstream out;
  out << "variant,set,level,hexes";
  for (const Figure& f : kFigures) out << ',' << f.key;
  for (const std::string& s : supports) out << ',' << csv_field("reaction_" + s + "_N");
  for (const Figure& f : kFigures) out << ',' << f.key << "_relative";
  out << ",released_contacts\n";
  for (const json& v : study["variants"]) {
    out << csv_field(v["name"].get<std::string>()) << ',' << csv_field(study_changes(v["set"], false)) << ','
        << v["level"].dump() << ',' << v["hexes"].dump();
    for (const Figure& f : kFigures) out << ',' << csv_number(v[f.key]);
    for (const std::string& s : supports) out << ',' << csv_number(reaction(v, s));
    for (const Figure& f : kFigures) out << ',' << csv_number(v["relative_to_reference"][f.key]);
    std::string contacts;  // released
    if (v.contains("released"))
      for (const json& name : v["released"])
        contacts += (contacts.empty() ? "" : ";") + name.get<std::string>();
    out << ',' << csv_field(contacts) << '\n';
  }
  return out.str();
}

std::string study_markdown(const json& study) {
  const std::vector<std::string> supports = support_names(study);
  const json& variants = study["variants"];
  std::ostringstream out;
  out << "| variant | changes | level | hexes |";
  for (const Figure& f : kFigures) out << ' ' << f.label << " |";
  for (const std::string& s : supports) out << " reaction " << markdown_cell(s) << " (N) |";
  out << "\n|---|---|---:|---:|";
  for (std::size_t i = 0; i < std::size(kFigures) + supports.size(); ++i) out << "---:|";
  out << '\n';
  for (std::size_t i = 0; i < variants.size(); ++i) {
    const json& v = variants[i];
    const json& change = v["relative_to_reference"];
    const bool reference = i == 0;  // its changes against itself are zero: shown without them
    const std::string set = study_changes(v["set"], true);
    out << "| " << markdown_cell(v["name"].get<std::string>()) << " | "
        << (set.empty() ? "(none)" : markdown_code(markdown_cell(set))) << " | " << v["level"].dump() << " | "
        << v["hexes"].dump() << " |";
    for (const Figure& f : kFigures)
      out << ' ' << markdown_figure(v[f.key], change[f.key], !reference, f.decimals) << " |";
    for (const std::string& s : supports) {
      out << ' '
          << (released(v, s) ? "0 (released)"
                             : markdown_figure(reaction(v, s), reaction(change, s), !reference, 2))
          << " |";
    }
    out << '\n';
  }
  return out.str();
}

}  // namespace hexbite
