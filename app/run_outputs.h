// What `hexbite run` writes and prints from a RunResult: results.json (the contract documented in
// docs/running.md), the VTU files of the mesh and the solution, the CalculiX deck, and the summary table.
//
// MPI: RunOutputs is collective. Rank 0 writes results.json, mesh.vtu and model.inp; the solution of each
// level is written by rank 0 as one .vtu in a serial run, and under mpirun -np N (N > 1) as a .pvtu whose N
// pieces are written by the ranks in parallel (each a contiguous block of hexes).
// The set is written all-or-nothing (common/output_stage.h): a failed run leaves the output folder as it
// was. The files are deterministic apart from the timings in results.json.
#pragma once

#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "app/run_pipeline.h"
#include "common/output_stage.h"

namespace hexbite {

// Refuses (InputError at the scenario line) what model.inp cannot express: spring supports.
void check_inp_exportable(const Scenario& scenario);

// results.json. `seconds_output` is the time spent writing the files (reported under seconds.output).
nlohmann::json results_json(const RunResult& result, double seconds_output);

// Whether `name` (relative to `dir`, "solution_level2.vtu" or, for a study, "soft_bone/model.inp") is an
// earlier run's output, which a run into the same folder that does not rewrite it removes when its own set is
// moved in: a name a run may write but results.json (which every run writes), in a folder that holds a
// results.json. Without that a folder held no run: the user's own model.inp there was removed.
bool is_earlier_run_output(const std::string& dir, const std::string& name);

// Whether a file of this name (no folder) is one that a run writes or removes: results.json, mesh.vtu,
// model.inp, model_mesh.inp, solution*.vtu / .pvtu and their pieces.
bool is_run_output_name(const std::string& filename);

// The files a run of `scenario` reads, each with what it is: "the scenario", "the geometry file", "the
// landmark file".
std::vector<std::pair<std::string, std::string>> scenario_inputs(const Scenario& scenario);

// Refuses (InputError, exit 2) to write into `dir` when one of `inputs` (path, what it is) lies in it under a
// name that `is_output` (given the name relative to `dir`, "results.json" or "soft/model.inp") says the
// command writes or removes: the input would be replaced by an output (a study file named study.json
// became the study's results). A symbolic link under such a name is not its target and is not refused.
void refuse_inputs_among_outputs(const std::vector<std::pair<std::string, std::string>>& inputs,
                                 const std::string& dir,
                                 const std::function<bool(const std::string&)>& is_output);

// The files of a run into DIR, all or nothing. Every rank constructs one and calls write() and commit()
// together. An error of any rank (disk full, a folder in the way of a file name) makes every rank throw
// the same error (RunError), so that rank 0 reports it once; the files of this run are then removed, and
// DIR keeps the files of an earlier run untouched (or is not created, if it did not exist).
class RunOutputs {
 public:
  // Creates DIR if it is missing, and the hidden folder the files are written into until commit().
  // `in_stage`: DIR lies in another command's stage (a study's variant folder), which says itself what
  // became of the user's folder; an error then does not add what became of DIR, a folder the user never
  // sees (a study's message said "did not create 'out/ref'" of a folder that existed).
  explicit RunOutputs(const std::string& dir, bool in_stage = false);
  // Removes what commit() did not move into DIR.
  ~RunOutputs();
  RunOutputs(const RunOutputs&) = delete;
  RunOutputs& operator=(const RunOutputs&) = delete;

  // Writes mesh.vtu and the solution files of every level (unless the scenario's outputs.vtu is false)
  // and, with `export_inp`, model.inp with model_mesh.inp. Returns the names of the files (relative to DIR;
  // rank 0's view, with every rank's pieces).
  std::vector<std::string> write(const RunResult& result, bool export_inp);

  // Writes results.json with `results_text` and moves the whole set into DIR, results.json last. The files
  // of an earlier run into DIR that this run does not rewrite (a solution_level2.vtu of a run with more
  // levels, a model.inp of a run with --export inp, the pieces of another number of ranks) are removed with
  // it, so that they cannot pass for this run's; other files are left alone.
  void commit(const std::string& results_text);

 private:
  // Runs `step`, then every rank learns whether any failed and throws the same error (see the .cc), with
  // what became of DIR (kWriteNote also says what to do).
  enum Note { kNoNote, kWriteNote, kCommitNote };
  void on_all_ranks(const std::function<void()>& step, Note note);

  std::string dir_;
  std::string stage_dir_;
  bool created_dir_ = false;
  bool in_stage_ = false;
  std::unique_ptr<OutputStage> stage_;  // rank 0's
  std::vector<std::string> files_;
};

// The table printed at the end of a run: per level bite force, reactions, maximum displacement, von Mises
// maximum and 99th percentile, strain energy, solver figures, and the relative change of the last level.
std::string summary_table(const RunResult& result);

}  // namespace hexbite
