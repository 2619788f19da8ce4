#include <CLI/CLI.hpp>

#include "app/commands.h"

namespace hexbite {

void add_quality_command(CLI::App& app) { (void)app; }

}  // namespace hexbite
