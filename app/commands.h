// Registration of the hexbite subcommands; each command lives in its own cmd_*.cc file.
#pragma once

namespace CLI {
class App;
}

namespace hexbite {

void add_surface_commands(CLI::App& app);  // the "surface" group, cmd_surface.cc
void add_surface_check_command(CLI::App& surface);
void add_surface_clean_command(CLI::App& surface);
void add_surface_from_ct_command(CLI::App& surface);
void add_generate_commands(CLI::App& app);  // generate mandible
void add_quality_command(CLI::App& app);    // quality MESH.vtu

}  // namespace hexbite
