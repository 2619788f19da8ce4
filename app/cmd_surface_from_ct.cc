#include <CLI/CLI.hpp>

#include "app/commands.h"

namespace hexbite {

void add_surface_from_ct_command(CLI::App& surface) { (void)surface; }

}  // namespace hexbite
