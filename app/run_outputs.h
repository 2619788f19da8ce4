// What `hexbite run` writes and prints from a RunResult: results.json (the contract documented in
// docs/running.md), the VTU files of the mesh and the solution, the CalculiX deck, and the summary table.
//
// MPI: write_run_outputs() is collective. Rank 0 writes results.json, mesh.vtu and model.inp; the solution
// of each level is written by rank 0 as one .vtu in a serial run, and under mpirun -np N (N > 1) as a
// .pvtu whose N pieces are written by the ranks in parallel (each a contiguous block of hexes).
// All files are written atomically (a failed run leaves no half-written file) and deterministically apart
// from the timings in results.json.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "app/run_pipeline.h"

namespace hexbite {

// Refuses (InputError at the scenario line) what model.inp cannot express: spring supports.
void check_inp_exportable(const Scenario& scenario);

// results.json. `seconds_output` is the time spent writing the files (reported under seconds.output).
nlohmann::json results_json(const RunResult& result, double seconds_output);

// Writes DIR/mesh.vtu and the solution files of every level (unless the scenario's outputs.vtu is false)
// and, with `export_inp`, DIR/model.inp with DIR/model_mesh.inp. Creates DIR. Returns the names of the files
// written (relative to DIR).
std::vector<std::string> write_run_outputs(const RunResult& result, const std::string& dir, bool export_inp);

// The table printed at the end of a run: per level bite force, reactions, maximum displacement, von Mises
// maximum and 99th percentile, strain energy, solver figures, and the relative change of the last level.
std::string summary_table(const RunResult& result);

}  // namespace hexbite
