#include <CLI/CLI.hpp>

#include "app/commands.h"

namespace hexbite {

void add_generate_commands(CLI::App& app) { (void)app; }

}  // namespace hexbite
