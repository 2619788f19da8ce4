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
#include <nlohmann/json.hpp>
#include <string>

#include "mesher/hex_mesh_io.h"
#include "tests/test_util.h"

namespace hexbite {
namespace {

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
