#include <CLI/CLI.hpp>

#include "app/commands.h"

namespace hexbite {

void add_surface_clean_command(CLI::App& surface) { (void)surface; }

}  // namespace hexbite
