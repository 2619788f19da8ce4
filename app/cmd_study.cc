// hexbite study STUDY.yaml -o DIR [--levels N] [--export inp] [--json]
//
// A what-if study as one command (docs/studies.md): every variant of the study's base scenario runs the
// whole pipeline of `hexbite run` and gets its own run folder DIR/<variant>/, and DIR/study.json,
// study.csv and study.md compare the variants with the first one.
//
// Every variant is checked before the first solve: the study file and each variant's scenario when the
// study is loaded (scenarios/study.h), that no file or link in DIR is where a variant's folder goes, then
// each variant's geometry, meshes and patches (prepare_run), so a bad value in the last variant costs no
// solve. All or nothing: the variants' folders and the tables are
// written into one hidden stage folder in DIR (common/output_stage.h) and moved into DIR only when every
// variant has solved and passed the checks of `hexbite run` (equilibrium, small displacements); any failure
// leaves DIR as it was. One process only: under mpirun it is refused.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "app/commands.h"
#include "app/option_checks.h"
#include "app/run_outputs.h"
#include "app/run_pipeline.h"
#include "common/atomic_file.h"
#include "common/error.h"
#include "common/json_text.h"
#include "common/output_stage.h"
#include "common/progress.h"
#include "postprocess/study_table.h"
#include "scenarios/study.h"
#include "solver/mpi_session.h"

namespace hexbite {

namespace {

namespace fs = std::filesystem;

struct StudyCliOptions {
  std::string study;
  std::string output;
  std::optional<int> levels;
  std::vector<std::string> export_formats;  // --export inp: every variant's model.inp
  bool json = false;
};

// Runs `step` for a variant: an error that does not name the variant yet (a mesh that stayed inverted, a
// solver that failed) is prefixed with it, keeping its kind (exit code).
template <class F>
void for_variant(const StudyVariant& variant, const std::string& study_file, F step) {
  const auto named = [&](const std::string& message) {
    const std::string note = "variant '" + variant.name + "'";
    return message.find(note) != std::string::npos ? message
                                                   : note + " of study " + study_file + ": " + message;
  };
  try {
    step();
  } catch (const InputError& e) {
    throw InputError(named(e.what()));
  } catch (const RunError& e) {
    throw RunError(named(e.what()));
  }
}

// The row of study.json of a solved variant: the figures of its finest level.
StudyRow study_row(const StudyVariant& variant, const RunResult& r) {
  const LevelResult& finest = r.levels.back();
  const ElasticitySolution& u = finest.solution;
  StudyRow row;
  row.name = variant.name;
  row.set = variant.set;
  row.level = finest.level;
  row.hexes = static_cast<long long>(finest.mesh.hexes.size());
  if (r.scenario.outputs.bite_force) row.bite_force_N = u.bite_force;
  row.max_displacement_mm = u.max_displacement;
  row.von_mises_max_MPa = u.von_mises_max;
  row.von_mises_p99_MPa = u.von_mises_p99;
  row.strain_energy_mJ = u.strain_energy;
  for (const SupportReaction& reaction : u.reactions) {
    row.reactions.emplace_back(reaction.name, reaction.magnitude);
    if (reaction.released) row.released.push_back(reaction.name);
  }
  return row;
}

void run_study(const StudyCliOptions& o) {
  // Each variant would be distributed on its own; the study's stage and tables are one process's work.
  if (MpiSession::size() > 1)
    throw InputError(
        "hexbite study runs on one process, not under mpirun; run it without mpirun, or run a "
        "variant's scenario with mpirun hexbite run");
  const auto start = std::chrono::steady_clock::now();
  Study study = load_study(o.study);
  const std::size_t count = study.variants.size();
  {
    // The study file, the base, and every variant's files: none may be replaced by study.json, study.md,
    // study.csv or a file of a variant's run folder.
    std::vector<std::pair<std::string, std::string>> inputs = {{study.path, "the study file"},
                                                               {study.base, "the base scenario"}};
    std::set<std::string> folders;
    for (const StudyVariant& v : study.variants) {
      folders.insert(v.name);
      for (auto& input : scenario_inputs(v.scenario))
        if (input.second != "the scenario") inputs.push_back(std::move(input));
    }
    refuse_inputs_among_outputs(inputs, o.output, [&folders](const std::string& name) {
      const std::size_t slash = name.find('/');
      if (slash == std::string::npos)
        return name == "study.json" || name == "study.md" || name == "study.csv";
      return folders.count(name.substr(0, slash)) > 0 && name.find('/', slash + 1) == std::string::npos &&
             is_run_output_name(name.substr(slash + 1));
    });
  }
  // A file where a variant's folder goes (a variant named notes.txt beside your notes) was found only when
  // the study was moved into DIR, after every variant had solved. The rule of the stage's commit: anything
  // but a folder is in the way, a link too; a link (to a folder on another disk) was called "a file".
  for (const StudyVariant& v : study.variants) {
    const fs::path folder = fs::path(o.output) / v.name;
    std::error_code ec;
    const fs::file_status status = fs::symlink_status(folder, ec);
    if (!fs::exists(status) || fs::is_directory(status)) continue;
    const bool link = fs::is_symlink(status);
    const std::string what = link ? "a symbolic link to '" + fs::read_symlink(folder, ec).string() + "'" +
                                        (fs::exists(folder, ec) ? "" : ", which does not exist or loops") +
                                        ", not a folder; a variant's run folder must be a real folder:"
                                  : "a file, not a folder;";
    throw InputError(v.where.str() + ": variant '" + v.name + "': its run folder '" + folder.string() +
                     "' is " + what +
                     " rename the variant (its name names the folder), remove or rename the " +
                     (link ? "link" : "file") + ", or choose another output folder");
  }
  const auto counted = [&](std::size_t i) {
    return std::to_string(i + 1) + " / " + std::to_string(count) + ": " + study.variants[i].name;
  };

  // Everything the input decides, for every variant, before the first solve.
  std::vector<RunResult> runs;
  for (std::size_t i = 0; i < count; ++i) {
    StudyVariant& v = study.variants[i];
    info("check variant " + counted(i));
    if (!o.export_formats.empty()) v.scenario.outputs.inp = true;  // "inp", the one format
    for_variant(v, study.path, [&] {
      if (v.scenario.outputs.inp) check_inp_exportable(v.scenario);
      const int levels = o.levels ? *o.levels : v.scenario.mesh.validation_levels;
      runs.push_back(prepare_run(v.scenario, levels, /*in_study=*/true));
    });
  }

  // The whole study is staged in DIR and moved in only when complete.
  OutputStage stage(o.output);
  const std::string left =
      stage.created_dir() ? "did not create '" + stage.dir() + "'" : "left '" + stage.dir() + "' as it was";
  StudyTable table{study.name, study.path, study.base, {}};
  std::vector<std::string> files;
  try {
    for (std::size_t i = 0; i < count; ++i) {
      const StudyVariant& v = study.variants[i];
      RunResult& r = runs[i];
      info("variant " + counted(i));
      for_variant(v, study.path, [&] {
        solve_run(r);
        // The variant's run folder, exactly as `hexbite run` writes it (app/cmd_run.cc).
        const auto t = std::chrono::steady_clock::now();
        RunOutputs outputs(stage.stage_dir() + "/" + v.name, /*in_stage=*/true);
        const std::vector<std::string> written = outputs.write(r, r.scenario.outputs.inp);
        nlohmann::ordered_json results = results_json(r, seconds_since(t));
        // scenario_file names the base; this says which study and which changes made these results, so
        // that the folder (and a report of it) is not taken for the base scenario's.
        results["study"] = {{"name", study.name}, {"file", study.path}, {"variant", v.name}, {"set", v.set}};
        outputs.commit(json_text(results) + '\n');
        for (const std::string& f : written) files.push_back(v.name + "/" + f);
        files.push_back(v.name + "/results.json");
        require_trustworthy(r, "the results of variant '" + v.name + "'");
      });
      table.rows.push_back(study_row(v, r));
      r = RunResult();  // the solution is written: free its memory for the next variant
    }
    const nlohmann::ordered_json j = study_json(table);
    write_file_atomically(stage.stage_dir() + "/study.csv", study_csv(j));
    write_file_atomically(stage.stage_dir() + "/study.md", study_markdown(j));
    write_file_atomically(stage.stage_dir() + "/study.json", json_text(j) + '\n');
    for (const char* name : {"study.csv", "study.md", "study.json"}) files.push_back(name);  // json last
    // An earlier study's output files in a variant's folder that this one does not rewrite go; the tables
    // are always rewritten, and everything else (other folders, your own files) stays.
    stage.commit(files, [&](const std::string& name) {
      return name.find('/') != std::string::npos && is_earlier_run_output(stage.dir(), name);
    });

    if (o.json) {
      std::cout << json_text(j) << '\n';
    } else if (!is_quiet()) {
      char total[64];
      std::snprintf(total, sizeof total, "%.1f", seconds_since(start));
      std::cout << "Study " << study.name << " (" << study.path << "), base " << study.base << ", " << count
                << " variant" << (count == 1 ? "" : "s") << "\n\n"
                << study_markdown(j) << "\nwrote in " << stage.dir()
                << ": study.json, study.csv, study.md and a run folder per variant (" << total
                << " s in all)\n";
    }
  } catch (const InputError& e) {
    throw InputError(named_in_dir(e.what(), stage.stage_dir(), stage.dir()) +
                     "; the study kept none of its files and " + left);
  } catch (const RunError& e) {
    // A variant's files are written into the study's hidden stage: named where the user looks for them.
    throw RunError(named_in_dir(e.what(), stage.stage_dir(), stage.dir()) +
                   "; the study kept none of its files and " + left);
  }
}

}  // namespace

void add_study_command(CLI::App& app) {
  auto o = std::make_shared<StudyCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "study", "Run a what-if study: a base scenario and its variants, each a full run, compared in tables");
  cmd->add_option("study", o->study, "Study file (.yaml), see docs/studies.md")->required();
  cmd->add_option("-o,--output", o->output, "Output folder (created if missing)")
      ->required()
      ->check(output_folder());
  cmd->add_option("--levels", o->levels,
                  "Validation levels of every variant (each refines the mesh 8-way and solves again); "
                  "overrides the scenarios' mesh.validation_levels")
      ->transform(count_in_range(0, kMaxValidationLevels));
  // Asked for by users who wanted every variant's CalculiX deck: `--export inp` was "not expected".
  add_export_option(*cmd, o->export_formats);
  cmd->add_flag("--json", o->json, "Print study.json instead of the table");
  cmd->callback([o] { run_study(*o); });
}

}  // namespace hexbite
