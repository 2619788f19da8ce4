// `hexbite report RUN_DIR -o report.html`: the validation report of a finished `hexbite run` as one
// self-contained HTML file (postprocess/run_report.h), with pictures of the solution unless --no-pictures.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "app/commands.h"
#include "app/option_checks.h"
#include "common/atomic_file.h"
#include "common/error.h"
#include "common/json_text.h"
#include "common/progress.h"
#include "postprocess/render.h"
#include "postprocess/report_pictures.h"
#include "postprocess/run_report.h"
#include "postprocess/run_results.h"

namespace hexbite {

namespace {

namespace fs = std::filesystem;

struct ReportArgs {
  std::string run_dir, output, title;
  bool no_pictures = false, json = false;
};

// The coarse level's solution of RUN_DIR, which the pictures are drawn from: solution.vtu, or under mpirun
// solution.pvtu with its pieces. A scenario with outputs.vtu: false writes neither, which is bad input for
// a report with pictures (exit 2), with what to do.
std::string solution_for_pictures(const std::string& run_dir) {
  std::error_code ec;
  for (const char* name : {"solution.vtu", "solution.pvtu"}) {
    const std::string path = (fs::path(run_dir) / name).string();
    if (fs::is_regular_file(path, ec)) return path;
    if (fs::is_directory(path, ec))
      throw InputError("'" + path +
                       "' is a folder, not the run's solution file, which the report's pictures " +
                       "are drawn from: remove or rename that folder and run the scenario again, or add " +
                       "--no-pictures");
  }
  throw InputError("'" + (fs::path(run_dir) / "solution.vtu").string() +
                   "' does not exist (nor a solution.pvtu of a run under mpirun), and the report's pictures "
                   "are drawn from it (a scenario with `outputs: {vtu: false}` skips it): add --no-pictures, "
                   "or run the scenario again with outputs.vtu: true");
}

void write_report(const ReportArgs& a) {
  std::error_code ec;
  if (!fs::exists(a.run_dir, ec))
    throw InputError("'" + a.run_dir + "' does not exist: give the folder of a finished run " +
                     "(`hexbite run SCENARIO -o RUN_DIR`)");
  if (!fs::is_directory(a.run_dir, ec))
    throw InputError("'" + a.run_dir + "' is a file, not a folder: give the folder of a finished run " +
                     "(`hexbite run SCENARIO -o RUN_DIR`), which holds results.json");
  // The output folder of a study holds one run folder per variant, not a run of its own.
  if (!fs::exists(fs::path(a.run_dir) / "results.json", ec) &&
      fs::exists(fs::path(a.run_dir) / "study.json", ec)) {
    std::vector<std::string> variants;
    for (const fs::directory_entry& e : fs::directory_iterator(a.run_dir, ec))
      if (fs::is_regular_file(e.path() / "results.json", ec))
        variants.push_back(e.path().filename().string());
    std::sort(variants.begin(), variants.end());
    throw InputError(
        "'" + a.run_dir + "' is the output folder of a study (it holds study.json), and a report " +
        "is of one run: give the folder of one of its variants" +
        (variants.empty() ? std::string()
                          : ", e.g. '" + (fs::path(a.run_dir) / variants.front()).string() + "'"));
  }
  const RunFigures run = read_run_figures((fs::path(a.run_dir) / "results.json").string());
  std::vector<ReportPicture> pictures;
  if (!a.no_pictures) {
    const std::string vtu = solution_for_pictures(a.run_dir);
    // The same refusal as `hexbite render`, before any work, with the way out that a report has.
    const std::string no_display = display_problem();
    if (!no_display.empty())
      throw RunError("cannot draw the report's pictures: no X display (" + no_display +
                     "); run the command under `xvfb-run -a`, or add --no-pictures for a report without "
                     "pictures");
    pictures = render_report_pictures(vtu, run);
  }
  const std::vector<std::string> warnings = report_warnings(run);
  write_file_atomically(a.output, report_html(run, warnings, pictures, {a.title, HEXBITE_VERSION}));
  for (const std::string& w : warnings) std::cerr << "hexbite: warning: " << w << '\n';
  if (a.json) {
    nlohmann::json list = nlohmann::json::array();
    for (const ReportPicture& p : pictures) list.push_back({{"field", p.field}, {"view", p.view}});
    std::cout << json_text(nlohmann::json{{"report", a.output}, {"pictures", list}, {"warnings", warnings}})
              << '\n';
  }
  info("wrote " + a.output + " (" + std::to_string(pictures.size()) + " pictures, " +
       std::to_string(warnings.size()) + (warnings.size() == 1 ? " warning)" : " warnings)"));
}

}  // namespace

void add_report_command(CLI::App& app) {
  auto args = std::make_shared<ReportArgs>();
  CLI::App* cmd = app.add_subcommand(
      "report", "Write the validation report of a finished run as one self-contained HTML file");
  cmd->add_option("RUN_DIR", args->run_dir, "Output folder of `hexbite run` (holds results.json)")
      ->required();
  cmd->add_option("-o,--output", args->output, "HTML file to write")
      ->required()
      ->check(output_file({".html", ".htm"}));
  // A blank title fell back to the scenario's name ('') or wrote an empty heading ('   ') without a word.
  cmd->add_option("--title", args->title, "Report title (default: the scenario's name)")
      ->check([](const std::string& title) {
        return title.find_first_not_of(" \t\r\n") == std::string::npos
                   ? "the title is blank; give some text, or leave out --title for the scenario's name"
                   : "";
      })
      ->check(one_line_of_text("the title"));
  cmd->add_flag("--no-pictures", args->no_pictures,
                "Leave out the pictures (they need solution.vtu and an X display)");
  cmd->add_flag("--json", args->json, "Print a JSON summary: the report's path, its pictures and warnings");
  cmd->callback([args] { write_report(*args); });
}

}  // namespace hexbite
