// The "surface" command group: check, clean and from-ct.
#include <CLI/CLI.hpp>

#include "app/commands.h"

namespace hexbite {

void add_surface_commands(CLI::App& app) {
  CLI::App* surface = app.add_subcommand("surface", "Check, clean or extract triangle surfaces");
  surface->require_subcommand(1);
  add_surface_check_command(*surface);
  add_surface_clean_command(*surface);
  add_surface_from_ct_command(*surface);
}

}  // namespace hexbite
