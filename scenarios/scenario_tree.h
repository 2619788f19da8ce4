// A scenario from an already parsed YAML tree, for trees that are not one file as it is: a study's variant
// is its base scenario's tree with the study's `set` values grafted in (scenarios/study.h). load_scenario()
// is this function on one file's tree.
#pragma once

#include <yaml-cpp/yaml.h>

#include "scenarios/scenario.h"
#include "scenarios/yaml_input.h"

namespace hexbite {

// Validates `root` exactly as load_scenario() validates a file; every error names the place that `source`
// gives the offending node (its file, line, column and note). Scenario::path is source.file.
Scenario parse_scenario_tree(const YAML::Node& root, const yaml_input::Source& source);

}  // namespace hexbite
