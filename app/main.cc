// The hexbite command line: parses options with CLI11 and maps errors to exit codes
// (0 ok, 1 failed run, 2 bad input or usage).
#include <CLI/CLI.hpp>
#include <iostream>

#include "app/commands.h"
#include "common/error.h"
#include "common/progress.h"

#ifndef HEXBITE_VERSION
#define HEXBITE_VERSION "unknown"
#endif

int main(int argc, char** argv) {
  CLI::App app{"hexbite: hexahedral meshing and bite simulation of the human mandible"};
  app.set_version_flag("--version", std::string("hexbite ") + HEXBITE_VERSION);
  bool quiet = false;
  app.add_flag("-q,--quiet", quiet, "No progress display and no informational output")
      ->configurable(false);
  app.require_subcommand(1);
  app.fallthrough();  // --quiet may follow the subcommand
  app.parse_complete_callback([&] { hexbite::set_quiet(quiet); });

  hexbite::add_surface_commands(app);
  hexbite::add_generate_commands(app);
  hexbite::add_quality_command(app);
  hexbite::add_render_command(app);
  hexbite::add_mesh_command(app);
  hexbite::add_refine_command(app);
  hexbite::add_reorder_command(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);  // prints the message and a hint to --help
    return hexbite::kExitBadInput;
  } catch (const hexbite::InputError& e) {
    std::cerr << "hexbite: error: " << e.what() << '\n';
    return hexbite::kExitBadInput;
  } catch (const hexbite::RunError& e) {
    std::cerr << "hexbite: failed: " << e.what() << '\n';
    return hexbite::kExitRunFailed;
  } catch (const std::exception& e) {
    std::cerr << "hexbite: failed: " << e.what() << '\n';
    return hexbite::kExitRunFailed;
  }
  return hexbite::kExitOk;
}
