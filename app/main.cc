// The hexbite command line: parses options with CLI11 and maps errors to exit codes
// (0 ok, 1 failed run, 2 bad input or usage). MPI is initialized here for the commands that solve, so that
// `mpirun -np N hexbite run ...` works; without mpirun the program is a single rank.
#include <mpi.h>

#include <pwd.h>
#include <sys/resource.h>
#include <unistd.h>
#include <CLI/CLI.hpp>
#include <chrono>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <iostream>
#include <new>
#include <optional>
#include <sstream>
#include <string>
#include <thread>

#include "app/commands.h"
#include "common/atomic_file.h"
#include "common/error.h"
#include "common/progress.h"
#include "solver/mpi_session.h"

#ifndef HEXBITE_VERSION
#define HEXBITE_VERSION "unknown"
#endif

namespace {

// Starting MPI (and with it PETSc, p4est and Trilinos) costs about half a second, which every quick command
// would pay for nothing: only `run` and `study` call the solver. The main program's own options are all
// flags, so the first argument that is not an option names the subcommand.
// Help and the version need no solver either: under a file size limit (ulimit -f) or a TMPDIR where no
// file can be made, MPI_Init aborted `hexbite run --help` with Open MPI's own text.
bool command_uses_solver(int argc, char** argv) {
  bool solver = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "-h" || arg == "--help" || arg == "--version") return false;
    if (!solver && !arg.empty() && arg[0] != '-') {
      if (arg != "run" && arg != "study") return false;
      solver = true;
    }
  }
  return solver;
}

// What Open MPI needs of the environment, set before MPI starts. Its daemon (which MPI_Init starts without
// mpirun) resolves a relative TMPDIR from '/', and printed "Impossible to open the file
// /t/ompi.../contact.txt" with an ORTE error on a run that succeeded: TMPDIR is made absolute. With HOME
// unset, a uid without a passwd entry (a container run under an arbitrary uid) crashed PMIx in MPI_Init
// (pmix_home_directory reads getpwuid's null): HOME is set to '/', not to a shared folder such as /tmp, where
// anyone could place a .petscrc or .openmpi/mca-params.conf that PETSc or Open MPI would read.
void prepare_mpi_environment() {
  const char* tmpdir = std::getenv("TMPDIR");
  if (tmpdir && *tmpdir && tmpdir[0] != '/') {
    std::error_code ec;
    const std::filesystem::path absolute = std::filesystem::absolute(tmpdir, ec);
    if (!ec) setenv("TMPDIR", absolute.c_str(), 1);
  }
  if (std::getenv("HOME") == nullptr && getpwuid(getuid()) == nullptr) setenv("HOME", "/", 1);
}

// Open MPI keeps its session files under TMPDIR: one where no folder can be made ended MPI_Init with a
// page of "orte_init failed" text and exit 1. Said plainly instead, before MPI starts; an empty text when
// TMPDIR (or /tmp) is usable.
std::string unusable_tmpdir() {
  const char* tmpdir = std::getenv("TMPDIR");
  const std::string base = tmpdir && *tmpdir ? tmpdir : "/tmp";
  std::string probe = base + "/.hexbite-probe-XXXXXX";
  if (mkdtemp(probe.data()) != nullptr) {
    rmdir(probe.c_str());
    return "";
  }
  return "hexbite: error: no folder can be made in " +
         (tmpdir && *tmpdir ? "TMPDIR '" + base + "'" : std::string("'/tmp'")) + " (" + std::strerror(errno) +
         "), where MPI keeps its session files: point TMPDIR at a folder you can write to\n";
}

// Prints an error's `text` (whole lines) and returns its exit code. Under mpirun every rank reads the same
// command line and scenario and builds the same meshes, so such an error stops all of them with the same
// text: rank 0 alone prints it then. An error of one rank (the others did not fail within a few seconds, or
// failed otherwise) is printed with its rank, and when the others did not fail, the job is aborted: they
// wait in a collective call of the run that this rank will never join, and MPI_Finalize would wait for
// them. `errors` is a communicator of its own, so that the barrier below cannot meet a collective call of
// the run.
int report(const std::string& text, int exit_code, MPI_Comm errors) {
  const int ranks = hexbite::MpiSession::size(), rank = hexbite::MpiSession::rank();
  if (ranks < 2) {
    std::cerr << text;
    return exit_code;
  }
  const std::string own = "[rank " + std::to_string(rank) + "] " + text;
  MPI_Request barrier;
  MPI_Ibarrier(errors, &barrier);
  int all_failed = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (MPI_Test(&barrier, &all_failed, MPI_STATUS_IGNORE) == MPI_SUCCESS && !all_failed &&
         std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  if (!all_failed) {
    std::cerr << own << std::flush;
    MPI_Abort(MPI_COMM_WORLD, exit_code);
  }
  const unsigned long hash = std::hash<std::string>{}(text);
  unsigned long lowest = 0, highest = 0;
  MPI_Allreduce(&hash, &lowest, 1, MPI_UNSIGNED_LONG, MPI_MIN, errors);
  MPI_Allreduce(&hash, &highest, 1, MPI_UNSIGNED_LONG, MPI_MAX, errors);
  if (lowest != highest)
    std::cerr << own;
  else if (rank == 0)
    std::cerr << text;
  return exit_code;
}

// Whether the chosen subcommand (or its own subcommand) was given --json: its standard output is then one
// JSON document, so informational lines go to standard error (set_json_output).
bool json_requested(const CLI::App& app) {
  for (const CLI::App* sub : app.get_subcommands()) {
    const CLI::Option* json = sub->get_option_no_throw("--json");
    if ((json != nullptr && json->count() > 0) || json_requested(*sub)) return true;
  }
  return false;
}

// An option of one value given more than once (CLI11: "--levels: At Most 1 required but received 2"): the
// message names it as --help lists it and says to give it once. Searches `app` and all its subcommands;
// nullopt when no such option is found (the error is then CLI11's own).
std::optional<std::string> repeated_option_message(const CLI::App& app) {
  for (const CLI::Option* o : app.get_options()) {
    if (o->get_items_expected_max() == 1 && o->count() > 1 &&
        o->get_multi_option_policy() == CLI::MultiOptionPolicy::Throw)
      return o->get_name(false, true) + " was given " + std::to_string(o->count()) +
             " times; it takes one value: give it once";
  }
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) {
    if (auto message = repeated_option_message(*sub)) return message;
  }
  return std::nullopt;
}

// A command level that needs a command and was given none (CLI11 says only "A subcommand is required",
// also when the word given is a typo): the message names the word left over, if any, and lists the
// commands of that level with where to read about them. nullopt when the missing piece is something else.
// With `mistyped_only`, only a plain word left over (a mistyped command) gives a message: --help printed the
// help of the level above a typo (`hexbite rnu --help`) with exit 0, as if the command existed.
std::optional<std::string> missing_command_message(const CLI::App& app, bool mistyped_only = false) {
  const CLI::App* level = &app;
  std::string chosen;  // the commands given, "surface " for `hexbite surface nosuch`
  for (auto given = app.get_subcommands(); !given.empty(); given = level->get_subcommands()) {
    level = given.front();
    chosen += level->get_name() + " ";
  }
  if (level->get_require_subcommand_min() == 0) return std::nullopt;
  std::string commands;
  for (const CLI::App* sub :
       level->get_subcommands([](const CLI::App* a) { return !a->get_group().empty(); }))
    commands += (commands.empty() ? "" : ", ") + sub->get_name();
  const std::string list = "the " + chosen + "commands are: " + commands + " (hexbite " + chosen + "--help)";
  // The first word left over decides: an option there belongs to a command not given (`hexbite surface
  // --units m`: 'm' is its value, not a command), a plain word is a mistyped command.
  for (const std::string& word : app.remaining(true)) {
    if (word.empty()) continue;
    if (word[0] == '-') {
      if (mistyped_only) return std::nullopt;
      return "a command is required before '" + word + "'; " + list;
    }
    return "unknown command '" + chosen + word + "'; " + list;
  }
  if (mistyped_only) return std::nullopt;
  return "a command is required; " + list;
}

// A file whose name starts with '-' (`hexbite quality -m.vtu`) is read as an option, and CLI11 then says
// only that the file's argument is required, or worse, splits it (`mesh -old.stl`: option -o with the
// value 'ld.stl', "this command writes .vtu ..."): the message names the file and how to give it. The words
// of the command line are looked at, not what CLI11 left over; a word that is the value of the option
// before it (`-o -x.vtu`, an output to replace) or comes after '--' is no such file. nullopt when no word
// is one.
std::optional<std::string> file_read_as_option_message(const CLI::App& app, int argc, char** argv) {
  // The option `name` of the command line's commands, when it takes a value.
  auto takes_value = [&](const std::string& name) {
    for (const CLI::App* level = &app; level != nullptr;) {
      if (const CLI::Option* option = level->get_option_no_throw(name)) return option->get_type_size() != 0;
      const std::vector<const CLI::App*> given = level->get_subcommands({});
      const auto used =
          std::find_if(given.begin(), given.end(), [](const CLI::App* a) { return a->parsed(); });
      level = used == given.end() ? nullptr : *used;
    }
    return false;
  };
  for (int i = 1; i < argc; ++i) {
    const std::string word = argv[i];
    if (word == "--") break;
    std::error_code ec;
    if (word.size() > 1 && word[0] == '-' && std::filesystem::exists(word, ec) &&
        !(i > 1 && argv[i - 1][0] == '-' && takes_value(argv[i - 1])))
      return "'" + word + "' was read as an option, but it is a file: give it as './" + word +
             "', or put '--' before it (no option after '--' is read as one)";
  }
  return std::nullopt;
}

// Standard output holds what a script reads (`--json`, the tables, --help): when it could not be written
// (a full disk behind `> file`, a closed descriptor), the command failed, though its files were written.
// Exit 0 with a JSON document cut off at 4,096 bytes is what a script could not tell from success.
int checked_stdout(int exit_code) {
  std::cout.flush();
  const bool written = static_cast<bool>(std::cout) && std::fflush(stdout) == 0 && !std::ferror(stdout);
  if (written || exit_code != hexbite::kExitOk) return exit_code;
  std::cerr << "hexbite: failed: cannot write to standard output (a full disk, or the output closed): what "
               "it printed is incomplete; make room, or redirect it elsewhere\n";
  return hexbite::kExitRunFailed;
}

}  // namespace

// OpenBLAS (deal.II's BLAS) starts a thread per core when it is loaded, and each of them allocates a 128 MB
// work buffer, retrying forever when it cannot: under an address-space limit (ulimit -v, as batch systems
// set it) below what the process maps plus those buffers every command hung at its exit with a thread
// spinning (600 MB on this 2-core machine: `hexbite --version` printed and never ended; a 64-core node's
// buffers alone take 8 GB). OpenBLAS reads its thread count from OPENBLAS_NUM_THREADS when it is loaded,
// before main, so under such a limit, unless the user chose a count, hexbite starts itself again with one
// BLAS thread. Its BLAS work is small (MUMPS factorizes at most 30,000 unknowns unless asked to). OpenBLAS
// takes a value that atoi() does not read as positive (empty, 0, "abc": a script's unset
// $SLURM_CPUS_PER_TASK) as no choice and falls back to OMP_NUM_THREADS or a thread per core, so such a value
// is no choice here either.
void one_blas_thread_under_an_address_space_limit(char** argv) {
  rlimit address_space{};
  if (getrlimit(RLIMIT_AS, &address_space) != 0 || address_space.rlim_cur == RLIM_INFINITY) return;
  const char* chosen = std::getenv("OPENBLAS_NUM_THREADS");
  if (chosen != nullptr && std::atoi(chosen) > 0) return;
  setenv("OPENBLAS_NUM_THREADS", "1", 1);
  execv("/proc/self/exe", argv);  // returns only when it failed: go on as before
}

int main(int argc, char** argv) {
  one_blas_thread_under_an_address_space_limit(argv);
  // Past a file size limit (ulimit -f) a write raises SIGXFSZ, which killed the process without a word and
  // left its temporary files; ignored, the write fails with EFBIG and the outputs are undone as on a full
  // disk.
  std::signal(SIGXFSZ, SIG_IGN);
  hexbite::remove_temporary_files_on_signals();
  std::optional<hexbite::MpiSession> mpi;
  if (command_uses_solver(argc, argv)) {
    prepare_mpi_environment();
    if (const std::string problem = unusable_tmpdir(); !problem.empty()) {
      std::cerr << problem;
      return hexbite::kExitBadInput;
    }
    mpi.emplace(argc, argv);
    // PETSc's initialization inside MPI_InitFinalize pushes and pops its own signal handlers and leaves
    // SIGTERM and SIGHUP at their default action: a batch system's time limit or a closed terminal then
    // killed a study without removing its stage folder (helper Z). Installed again.
    hexbite::remove_temporary_files_on_signals();
  }
  // A reader that closes standard output early (`hexbite quality m.vtu | head -1`) killed the process with
  // SIGPIPE: exit 141 and no word. Ignored, the write fails with EPIPE, and checked_stdout says so (exit 1).
  // Set after MPI starts, which restores the default action.
  std::signal(SIGPIPE, SIG_IGN);
  // Only rank 0 reports progress and results; an error met by every rank alike is reported once (report).
  const bool root = hexbite::MpiSession::rank() == 0;
  MPI_Comm errors = MPI_COMM_NULL;
  if (hexbite::MpiSession::size() > 1) MPI_Comm_dup(MPI_COMM_WORLD, &errors);
  CLI::App app{"hexbite: hexahedral meshing and bite simulation of the human mandible"};
  app.set_version_flag("--version", std::string("hexbite ") + HEXBITE_VERSION);
  bool quiet = false;
  app.add_flag("-q,--quiet", quiet, "No progress display and no informational output")->configurable(false);
  app.require_subcommand(1);
  app.fallthrough();  // --quiet may follow the subcommand
  app.parse_complete_callback([&] {
    hexbite::set_quiet(quiet || !root);
    hexbite::set_json_output(json_requested(app));
  });

  hexbite::add_surface_commands(app);
  hexbite::add_generate_commands(app);
  hexbite::add_quality_command(app);
  hexbite::add_render_command(app);
  hexbite::add_mesh_command(app);
  hexbite::add_refine_command(app);
  hexbite::add_reorder_command(app);
  hexbite::add_run_command(app);
  hexbite::add_study_command(app);
  hexbite::add_quad_commands(app);
  hexbite::add_report_command(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    if (const std::optional<std::string> mistyped = missing_command_message(app, true))
      return report("hexbite: error: " + *mistyped + '\n', hexbite::kExitBadInput, errors);
    return checked_stdout(app.exit(e));
  } catch (const CLI::CallForAllHelp& e) {
    return checked_stdout(app.exit(e));
  } catch (const CLI::CallForVersion& e) {
    return checked_stdout(app.exit(e));
  } catch (const CLI::ArgumentMismatch& e) {
    if (const std::optional<std::string> file = file_read_as_option_message(app, argc, argv))
      return report("hexbite: error: " + *file + '\n', hexbite::kExitBadInput, errors);
    std::ostringstream text;
    const std::optional<std::string> repeated = repeated_option_message(app);
    // The message (which option was given twice, when that is the mismatch) and a hint to --help.
    app.exit(repeated ? CLI::ArgumentMismatch(*repeated) : e, text, text);
    return report(text.str(), hexbite::kExitBadInput, errors);
  } catch (const CLI::RequiredError& e) {
    if (const std::optional<std::string> missing = missing_command_message(app))
      return report("hexbite: error: " + *missing + '\n', hexbite::kExitBadInput, errors);
    if (const std::optional<std::string> file = file_read_as_option_message(app, argc, argv))
      return report("hexbite: error: " + *file + '\n', hexbite::kExitBadInput, errors);
    std::ostringstream text;
    app.exit(e, text, text);
    return report(text.str(), hexbite::kExitBadInput, errors);
  } catch (const CLI::ParseError& e) {
    if (const std::optional<std::string> file = file_read_as_option_message(app, argc, argv))
      return report("hexbite: error: " + *file + '\n', hexbite::kExitBadInput, errors);
    std::ostringstream text;
    app.exit(e, text, text);  // the message and a hint to --help
    return report(text.str(), hexbite::kExitBadInput, errors);
  } catch (const hexbite::InputError& e) {
    return report(std::string("hexbite: error: ") + e.what() + '\n', hexbite::kExitBadInput, errors);
  } catch (const hexbite::RunError& e) {
    return report(std::string("hexbite: failed: ") + e.what() + '\n', hexbite::kExitRunFailed, errors);
  } catch (const std::bad_alloc&) {
    // Said as "std::bad_alloc" before.
    return report(
        "hexbite: failed: out of memory: the machine's memory, a container's or batch job's memory limit, "
        "or the address-space limit (ulimit -v) is too small for this work; give the process more, or ask "
        "for less (fewer hexes, fewer validation levels)\n",
        hexbite::kExitRunFailed, errors);
  } catch (const std::exception& e) {
    return report(std::string("hexbite: failed: ") + e.what() + '\n', hexbite::kExitRunFailed, errors);
  }
  return checked_stdout(hexbite::kExitOk);
}
