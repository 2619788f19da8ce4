// Study files: what-if studies as one file. A study names a base scenario and its variants; each variant
// changes the base by `set` entries, a dotted path (list items addressed by their name) mapped to a YAML
// value that replaces or adds that key. The format is documented in docs/studies.md.
//
// load_study() reads the study file and builds and validates every variant's scenario before anything runs,
// so that a bad value in the last variant stops the study before the first solve. Errors are InputErrors
// "FILE:LINE:COLUMN: variant 'NAME' ...: what; what to do": a value that the study set is named at its line
// in the study file, anything else at its line in the base scenario (as `hexbite run` names it).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "scenarios/scenario.h"

namespace hexbite {

struct StudyVariant {
  std::string name;            // unique and file-name safe: it names the variant's output folder
  SourceLocation where;        // the variant's entry in the study file
  nlohmann::ordered_json set;  // the changes as given: {"dotted.path": value}, empty for the base as it is
  Scenario scenario;           // the base scenario with the changes, validated as load_scenario() validates
};

struct Study {
  std::string path;  // the study file as given
  std::string name;
  std::string description;
  std::string base;  // the base scenario's path: the `base` key resolved against the study file's folder
  std::vector<StudyVariant> variants;  // at least one; the first is the reference of the comparison
};

// Reads a study file and validates it and every variant's scenario. Throws InputError as described above.
Study load_study(const std::string& path);

}  // namespace hexbite
