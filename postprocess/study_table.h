// The comparison tables of a what-if study (`hexbite study`, docs/studies.md): one row per variant with the
// figures of its finest solved level and their relative change against the first variant, the reference.
//
// study_json() is the machine-readable table (DIR/study.json); study_csv() and study_markdown() are made
// from that JSON, so the three cannot disagree. A figure a variant lacks (no bite support, so no bite force;
// a support the variant does not have) is null in JSON, empty in CSV and "—" in Markdown.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace hexbite {

// One variant's figures.
struct StudyRow {
  std::string name;
  nlohmann::ordered_json set;  // the variant's changes as given ({"dotted.path": value})
  int level = 0;               // the validation level the figures are of: the finest one solved
  long long hexes = 0;
  std::optional<double> bite_force_N;  // none when the variant reports no bite force
  double max_displacement_mm = 0;
  double von_mises_max_MPa = 0;
  double von_mises_p99_MPa = 0;
  double strain_energy_mJ = 0;
  std::vector<std::pair<std::string, double>> reactions;  // support name -> magnitude (N), scenario order
  std::vector<std::string> released;  // contacts released at that level (their reaction is 0: not a measure)
};

struct StudyTable {
  std::string study;           // the study's name
  std::string study_file;      // the study file as given
  std::string base;            // the base scenario's path
  std::vector<StudyRow> rows;  // the first is the reference
};

// A variant's changes on one line: "path: value; path: value", line breaks and tabs as spaces, other
// control characters as \xNN. With `abbreviate` (Markdown), a mapping or list longer than a table cell stands
// as "{...}" or "[...]": study.csv and study.json give it whole.
std::string study_changes(const nlohmann::ordered_json& set, bool abbreviate);

// {study, study_file, base, variants: [{name, set, level, hexes, bite_force_N, max_displacement_mm,
// von_mises_max_MPa, von_mises_p99_MPa, strain_energy_mJ, reactions {support: N} (every support of any
// variant, null where the variant has none), released [contacts], relative_to_reference
// {the same figures and reactions as (variant - reference) / |reference|}}]}; a relative change is null
// where either figure is missing or the reference's is zero.
nlohmann::ordered_json study_json(const StudyTable& table);

// One row per variant after a header row; numbers exactly as in the JSON (shortest round-trip form).
std::string study_csv(const nlohmann::ordered_json& study);

// A Markdown table to paste into a report: figures rounded as `hexbite run` prints them, each variant's
// relative change against the reference in percent (one decimal) beside its figure, long changes
// abbreviated.
std::string study_markdown(const nlohmann::ordered_json& study);

}  // namespace hexbite
