#include "app/carried_arrays.h"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <iterator>
#include <optional>

#include "common/paths.h"
#include "mesher/hex_quality.h"

namespace hexbite {

namespace {

// Whether `a` holds what write_vtu writes as its quality array `values`: Float64, one value per hex, equal
// up to the last bits (inf for an inverted hex; NaN where the measure is NaN).
bool is_hexbite_quality(const MeshArray& a, const std::vector<double>& values) {
  if (a.vtk_type != MeshArray().vtk_type || a.components != 1 || a.values.size() != values.size())
    return false;
  for (std::size_t i = 0; i < values.size(); ++i) {
    const double x = a.values[i], y = values[i];
    const bool close = std::isfinite(y) && std::abs(x - y) <= 1e-12 * std::abs(y);
    if (!(x == y || close || (std::isnan(x) && std::isnan(y)))) return false;
  }
  return true;
}

}  // namespace

CellArrays split_cell_arrays(const HexMesh& mesh, const std::vector<MeshArray>& arrays) {
  std::optional<HexQualityField> quality;  // computed when an array needs it
  CellArrays out;
  for (const MeshArray& a : arrays) {
    const auto named = std::find(std::begin(kVtuQualityArrays), std::end(kVtuQualityArrays), a.name);
    if (named == std::end(kVtuQualityArrays)) {
      out.own.push_back(a);
      continue;
    }
    if (!quality) quality = compute_hex_quality(mesh);
    if (!is_hexbite_quality(a, vtu_quality_array(*quality, named - std::begin(kVtuQualityArrays))))
      out.clashing.push_back(a.name);
  }
  return out;
}

void warn_arrays_not_carried(const std::string& input, const std::string& output, const std::string& command,
                             const CellArrays& cells, const std::vector<MeshArray>& point_arrays,
                             bool points_carried, const std::vector<std::string>& not_read) {
  const bool vtu = lower_extension(output) == ".vtu";
  for (std::size_t i = 0; vtu && i < cells.clashing.size(); ++i) {
    const std::string& name = cells.clashing[i];
    std::cerr << "hexbite: warning: cell array '" << name << "' of " << input
              << " is not hexbite's quality array of that name (its values differ): " << output
              << " holds hexbite's '" << name << "' (Float64) in its place; rename the array in " << input
              << " to keep it.\n";
  }
  std::vector<std::string> lost;
  if (!vtu) {
    for (const MeshArray& a : cells.own) lost.push_back("cell array '" + a.name + "'");
    for (const std::string& name : cells.clashing) lost.push_back("cell array '" + name + "'");
  }
  if (!vtu || !points_carried)
    for (const MeshArray& a : point_arrays) lost.push_back("point array '" + a.name + "'");
  lost.insert(lost.end(), not_read.begin(), not_read.end());
  if (lost.empty()) return;
  std::string list;
  for (const std::string& item : lost) list += (list.empty() ? "" : ", ") + item;
  std::cerr << "hexbite: warning: not carried over to " << output << ": " << list << " ("
            << (!vtu             ? "only a .vtu output carries arrays"
                : points_carried ? command + " carries the numeric cell and point arrays only"
                                 : command +
                                       " carries the numeric cell arrays only, each child hex with its "
                                       "parent's values: the new nodes have no values")
            << ").\n";
}

}  // namespace hexbite
