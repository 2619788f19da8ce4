// Serial against distributed `hexbite run`: CTest runs the default scenario (coarse level only) once
// serially and once under `mpirun -np 2` (the fixture tests run_serial and run_np2 in tests/CMakeLists.txt);
// this program compares what the two wrote.
#include <gtest/gtest.h>
#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLPUnstructuredGridReader.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "mesher/hex_mesh_io.h"
#include "tests/test_util.h"

namespace hexbite {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const std::string kDir = HEXBITE_RUN_MPI_DIR;

json results(const std::string& run) {
  return json::parse(test::read_file(kDir + "/" + run + "/results.json"));
}

// |a - b| <= 1e-6 max(|a|, |b|), element by element for arrays and objects.
void expect_same(const json& a, const json& b, const std::string& what) {
  if (a.is_number()) {
    const double x = a.get<double>(), y = b.get<double>();
    EXPECT_LE(std::abs(x - y), 1e-6 * std::max(std::abs(x), std::abs(y))) << what << ": " << x << " vs " << y;
    return;
  }
  ASSERT_EQ(a.size(), b.size()) << what;
  for (auto it = a.begin(); it != a.end(); ++it) {
    const std::string key = a.is_object() ? it.key() : std::to_string(it - a.begin());
    expect_same(*it, a.is_object() ? b.at(it.key()) : b.at(it - a.begin()), what + "." + key);
  }
}

const std::vector<std::string> kTwoRanks = {HEXBITE_MPIEXEC, "-np", "2", "--allow-run-as-root",
                                            "--oversubscribe"};

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// A bad scenario stops every rank with the same message: it used to be printed by each rank.
TEST(RunMpi, AScenarioErrorIsReportedOnce) {
  const std::string dir = test::temp_dir();
  std::string text =
      test::read_file(std::string(HEXBITE_SOURCE_DIR) + "/scenarios/lateral_bite_hard_nut.yaml");
  text.replace(text.find("E_MPa: 11000"), 12, "E_MPa: 0");
  test::write_file(dir + "/bad.yaml", text);
  const test::CommandResult r =
      test::run_hexbite({"-q", "run", dir + "/bad.yaml", "-o", dir + "/out"}, kTwoRanks);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(count(r.err, "hexbite: error: " + dir + "/bad.yaml:"), 1u) << r.err;
  EXPECT_EQ(count(r.err, "[rank"), 0u) << r.err;
  // A command-line error, the same on every rank, too.
  const test::CommandResult no_output = test::run_hexbite({"-q", "run", dir + "/bad.yaml"}, kTwoRanks);
  EXPECT_EQ(no_output.exit_code, 2) << no_output.err;
  EXPECT_EQ(count(no_output.err, "--output is required"), 1u) << no_output.err;
}

// An error of rank 0 alone (here it runs under a 64 kB file size limit, so its mesh.vtu does not fit, while
// rank 1 writes its piece of the solution) left rank 1 waiting in a barrier, and the job hung (then, for a
// while, the failing rank aborted the job). Every rank now learns of it and stops with the same message,
// which rank 0 prints once, and the output folder is not made. (Open MPI warns that rank 0's shared memory
// segment does not fit either, and goes on without it.)
TEST(RunMpi, AnErrorOfOneRankEndsTheJob) {
  std::vector<std::string> launcher = kTwoRanks;
  launcher.insert(launcher.begin(), {"timeout", "300"});
  launcher.insert(launcher.end(),
                  {"bash", "-c",
                   "if [ \"$OMPI_COMM_WORLD_RANK\" = 0 ]; then trap '' XFSZ; ulimit -f 64; fi; "
                   "exec \"$@\"",
                   "bash"});
  const std::string out = test::temp_dir() + "/out";
  const test::CommandResult r = test::run_hexbite(
      {"-q", "run", std::string(HEXBITE_SOURCE_DIR) + "/scenarios/lateral_bite_hard_nut.yaml", "-o", out,
       "--levels", "0"},
      launcher);
  EXPECT_EQ(r.exit_code, 1) << r.err;  // timeout's 124 when the job hangs
  EXPECT_EQ(count(r.err, "hexbite: failed: cannot write '" + out + "/"), 1u) << r.err;
  EXPECT_EQ(count(r.err, "[rank"), 0u) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

// linear_solver auto chose the direct solver or CG on each rank from its own memory: with rank 1 under an
// address-space limit (ulimit -v) that leaves no room for MUMPS, rank 0 factorized and rank 1 iterated, and
// the job ended in std::terminate inside Epetra (helper AA). Every rank now takes the least room's choice.
TEST(RunMpi, RanksWithDifferentMemoryTakeTheSameSolver) {
  std::vector<std::string> launcher = kTwoRanks;
  launcher.insert(launcher.begin(), {"timeout", "300"});
  launcher.insert(launcher.end(),
                  {"bash", "-c",
                   "if [ \"$OMPI_COMM_WORLD_RANK\" = 1 ]; then ulimit -v 1200000; fi; exec \"$@\"", "bash"});
  const std::string out = test::temp_dir() + "/out";
  const test::CommandResult r =
      test::run_hexbite({"run", std::string(HEXBITE_SOURCE_DIR) + "/scenarios/lateral_bite_hard_nut.yaml",
                         "-o", out, "--levels", "0"},
                        launcher);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(count(r.err, "the direct solver needs about"), 1u) << r.err;
  EXPECT_NE(r.err.find("another rank's memory, the least of the ranks'"), std::string::npos) << r.err;
  const json run = json::parse(test::read_file(out + "/results.json"));
  EXPECT_GT(run["solver"]["iterations"].get<int>(), 0);  // CG on both ranks
}

// Rank 1's piece cannot be moved into place (a folder of its name is in the way): the run used to leave
// rank 0's new mesh.vtu and solution.pvtu beside the earlier results.json, print the error with rank 1's
// prefix and abort the job. Now nothing moves, and rank 0 reports.
TEST(RunMpi, APieceThatCannotBeMovedInLeavesTheFolderAsItWas) {
  const std::string out = test::temp_dir() + "/out";
  fs::create_directories(out + "/solution_1.vtu/mine");
  for (const char* name : {"results.json", "mesh.vtu", "solution.pvtu", "solution_0.vtu", "model.inp"})
    test::write_file(out + "/" + name, std::string("earlier ") + name + "\n");
  const std::map<std::string, std::string> before = test::files_under(out);
  std::vector<std::string> launcher = kTwoRanks;
  launcher.insert(launcher.begin(), {"timeout", "300"});
  const test::CommandResult r = test::run_hexbite(
      {"-q", "run", std::string(HEXBITE_SOURCE_DIR) + "/scenarios/lateral_bite_hard_nut.yaml", "-o", out,
       "--levels", "0"},
      launcher);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(count(r.err, "hexbite: failed: cannot write '" + out +
                             "/solution_1.vtu': a folder of that name is in the way; remove or rename it, or "
                             "choose another output folder; the run kept none of its files and left '" +
                             out + "' as it was\n"),
            1u)
      << r.err;
  EXPECT_EQ(count(r.err, "[rank"), 0u) << r.err;
  test::expect_same_files(before, test::files_under(out));
}

TEST(RunMpi, TwoRanksGiveTheSerialFigures) {
  const json serial = results("serial"), np2 = results("np2");
  EXPECT_EQ(serial["solver"]["ranks"], 1);
  EXPECT_EQ(np2["solver"]["ranks"], 2);
  for (const char* key : {"bite_force_N", "applied_force_N", "max_displacement_mm", "max_displacement_at",
                          "von_mises_max_MPa", "von_mises_p99_MPa", "strain_energy_mJ"})
    expect_same(serial[key], np2[key], key);
  for (const auto& [name, r] : serial["reactions"].items())
    expect_same(r["force_N"], np2["reactions"][name]["force_N"], "reactions." + name);
  for (const auto& [name, p] : serial["probes"].items())
    expect_same(p["displacement_mm"], np2["probes"][name]["displacement_mm"], "probes." + name);
  EXPECT_LT(np2["equilibrium_residual"].get<double>(), 1e-8);
}

TEST(RunMpi, TwoRanksWriteAParallelVtuOfTheWholeSolution) {
  std::vector<MeshArray> cells, points;
  const HexMesh serial = read_vtu(kDir + "/serial/solution.vtu", &cells, &points);
  vtkNew<vtkXMLPUnstructuredGridReader> reader;
  reader->SetFileName((kDir + "/np2/solution.pvtu").c_str());
  reader->Update();
  vtkUnstructuredGrid* grid = reader->GetOutput();
  ASSERT_EQ(grid->GetNumberOfCells(), static_cast<vtkIdType>(serial.hexes.size()));
  // The pieces share the vertices on their common faces, so compare the largest displacement and the sum
  // of the per-cell von Mises stress, which do not depend on how the points were split.
  vtkDataArray* u = grid->GetPointData()->GetArray("displacement");
  vtkDataArray* vm = grid->GetCellData()->GetArray("von_mises");
  ASSERT_NE(u, nullptr);
  ASSERT_NE(vm, nullptr);
  double umax = 0, vm_sum = 0, serial_vm_sum = 0;
  for (vtkIdType i = 0; i < u->GetNumberOfTuples(); ++i) {
    const double* d = u->GetTuple3(i);
    umax = std::max(umax, std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
  }
  for (vtkIdType i = 0; i < vm->GetNumberOfTuples(); ++i) vm_sum += vm->GetTuple1(i);
  for (const MeshArray& a : cells)
    if (a.name == "von_mises")
      for (double v : a.values) serial_vm_sum += v;
  EXPECT_NEAR(umax, results("serial")["max_displacement_mm"].get<double>(), 1e-9);
  EXPECT_NEAR(vm_sum, serial_vm_sum, 1e-6 * serial_vm_sum);
}

}  // namespace
}  // namespace hexbite
