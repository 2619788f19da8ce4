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
void add_render_command(CLI::App& app);     // render INPUT -o PNG
void add_mesh_command(CLI::App& app);       // mesh SURFACE --method grid, cmd_mesh.cc
void add_refine_command(CLI::App& app);     // refine MESH.vtu --surface SURFACE -o fine.vtu, cmd_refine.cc
void add_reorder_command(CLI::App& app);    // reorder MESH.vtu -o out.vtu --method bfs|rcm, cmd_reorder.cc
void add_run_command(CLI::App& app);        // run SCENARIO.yaml -o DIR [--export inp], cmd_run.cc
void add_study_command(CLI::App& app);      // study STUDY.yaml -o DIR, cmd_study.cc
void add_quad_commands(CLI::App& app);      // the "quad" group (quad check Q.obj), cmd_quad.cc
void add_report_command(CLI::App& app);     // report RUN_DIR -o report.html, cmd_report.cc

}  // namespace hexbite
