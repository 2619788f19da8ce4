// hexbite run SCENARIO.yaml -o DIR [--export inp] [--levels N] [--json]
//
// The whole simulation: geometry, hex mesh, solve, validation levels (refined 8-way and solved again), then
// DIR/results.json, DIR/mesh.vtu, DIR/solution*.vtu (or .pvtu under mpirun) and, with --export inp,
// DIR/model.inp for CalculiX. A scenario error (exit 2) is found before anything is solved or written; a
// failure while writing (exit 1) leaves DIR as it was, the set is moved in only when complete. The
// equilibrium residual and the largest displacement of every level are checked after the results are
// written (require_trustworthy): a failed check fails the run (exit 1), so a wrong answer never passes
// silently but stays inspectable. Under mpirun every rank runs this command; rank 0 prints and writes
// (docs/running.md).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/commands.h"
#include "app/option_checks.h"
#include "app/run_outputs.h"
#include "app/run_pipeline.h"
#include "common/error.h"
#include "common/json_text.h"
#include "common/progress.h"
#include "solver/mpi_session.h"

namespace hexbite {

namespace {

struct RunCliOptions {
  std::string scenario;
  std::string output;
  std::vector<std::string> export_formats;  // --export, repeats allowed
  std::optional<int> levels;
  bool json = false;
};

void run_run(const RunCliOptions& o) {
  const bool root = MpiSession::rank() == 0;
  Scenario scenario = load_scenario(o.scenario);
  refuse_inputs_among_outputs(scenario_inputs(scenario), o.output, is_run_output_name);
  const int levels = o.levels ? *o.levels : scenario.mesh.validation_levels;
  const bool export_inp =
      std::count(o.export_formats.begin(), o.export_formats.end(), "inp") > 0 || scenario.outputs.inp;
  if (export_inp) check_inp_exportable(scenario);

  const RunResult result = run_pipeline(std::move(scenario), levels);

  // All or nothing: a failure while writing leaves o.output as it was (app/run_outputs.h).
  const auto start = std::chrono::steady_clock::now();
  RunOutputs outputs(o.output);
  const std::vector<std::string> files = outputs.write(result, export_inp);
  const double seconds_output =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const nlohmann::json results = results_json(result, seconds_output);
  outputs.commit(json_text(results) + '\n');

  if (root && o.json) {
    std::cout << json_text(results) << '\n';
  } else if (root && !is_quiet()) {
    std::cout << "Scenario " << result.scenario.name << " (" << o.scenario << "), "
              << result.levels.size() - 1 << " validation level" << (result.levels.size() == 2 ? "" : "s")
              << ", " << MpiSession::size() << " rank" << (MpiSession::size() == 1 ? "" : "s") << "\n\n"
              << summary_table(result) << '\n';
    std::cout << "wrote in " << o.output << ": results.json";
    for (const std::string& f : files) std::cout << ", " << f;
    char total[64];
    std::snprintf(total, sizeof total, "%.1f", result.seconds_total + seconds_output);
    std::cout << " (" << total << " s in all)\n";
  }

  require_trustworthy(result, "the results in " + o.output);
}

}  // namespace

void add_run_command(CLI::App& app) {
  auto o = std::make_shared<RunCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "run", "Simulate a bite scenario: mesh, solve, validate by refinement, write results and VTU files");
  cmd->add_option("scenario", o->scenario, "Scenario file (.yaml), see docs/scenario-format.md")->required();
  cmd->add_option("-o,--output", o->output, "Output folder (created if missing)")
      ->required()
      ->check(output_folder());
  add_export_option(*cmd, o->export_formats);
  cmd->add_option(
         "--levels", o->levels,
         "Validation levels (each refines the mesh 8-way and solves again); overrides the scenario's "
         "mesh.validation_levels")
      ->transform(count_in_range(0, kMaxValidationLevels));
  cmd->add_flag("--json", o->json, "Print results.json instead of the summary table");
  cmd->callback([o] { run_run(*o); });
}

}  // namespace hexbite
