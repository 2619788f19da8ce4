// The hexbite command line: parses options with CLI11 and maps errors to exit codes
// (0 ok, 1 failed run, 2 bad input or usage). MPI is initialized here for the commands that solve, so that
// `mpirun -np N hexbite run ...` works; without mpirun the program is a single rank.
#include <CLI/CLI.hpp>
#include <iostream>
#include <optional>
#include <string>

#include "app/commands.h"
#include "common/error.h"
#include "common/progress.h"
#include "solver/mpi_session.h"

#ifndef HEXBITE_VERSION
#define HEXBITE_VERSION "unknown"
#endif

namespace {

// Starting MPI (and with it PETSc, p4est and Trilinos) costs about half a second, which every quick command
// would pay for nothing: only `run` calls the solver. The main program's own options are all flags, so the
// first argument that is not an option names the subcommand.
bool command_uses_solver(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (!arg.empty() && arg[0] != '-') return arg == "run";
  }
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  std::optional<hexbite::MpiSession> mpi;
  if (command_uses_solver(argc, argv)) mpi.emplace(argc, argv);
  // Only rank 0 reports progress and results; errors are reported by every rank that meets them.
  const bool root = hexbite::MpiSession::rank() == 0;
  const std::string rank_prefix =
      hexbite::MpiSession::size() > 1 ? "[rank " + std::to_string(hexbite::MpiSession::rank()) + "] " : "";
  CLI::App app{"hexbite: hexahedral meshing and bite simulation of the human mandible"};
  app.set_version_flag("--version", std::string("hexbite ") + HEXBITE_VERSION);
  bool quiet = false;
  app.add_flag("-q,--quiet", quiet, "No progress display and no informational output")->configurable(false);
  app.require_subcommand(1);
  app.fallthrough();  // --quiet may follow the subcommand
  app.parse_complete_callback([&] { hexbite::set_quiet(quiet || !root); });

  hexbite::add_surface_commands(app);
  hexbite::add_generate_commands(app);
  hexbite::add_quality_command(app);
  hexbite::add_render_command(app);
  hexbite::add_mesh_command(app);
  hexbite::add_refine_command(app);
  hexbite::add_reorder_command(app);
  hexbite::add_run_command(app);
  hexbite::add_quad_commands(app);

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
    std::cerr << rank_prefix << "hexbite: error: " << e.what() << '\n';
    return hexbite::kExitBadInput;
  } catch (const hexbite::RunError& e) {
    std::cerr << rank_prefix << "hexbite: failed: " << e.what() << '\n';
    return hexbite::kExitRunFailed;
  } catch (const std::exception& e) {
    std::cerr << rank_prefix << "hexbite: failed: " << e.what() << '\n';
    return hexbite::kExitRunFailed;
  }
  return hexbite::kExitOk;
}
