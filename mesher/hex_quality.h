// Quality of a whole hex mesh: per-element measures, a summary like the seed paper's Table 1 (min / average /
// max per measure, inverted elements), node degree histograms and histograms of the element measures.
//
// Input: a HexMesh whose hexes index valid vertices (the readers check this).
// Output: plain arrays and structs; the definitions are those of mesher/hex_quality_kernel.h.
// Cost: compute_hex_quality is one plain loop over the hexes (8 corner kernels each, no allocation per hex);
// node_degrees and summarize_quality also sort the 12 m edges and 6 m faces, O(m log m) for m hexes.
#pragma once

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "mesher/hex_mesh.h"
#include "mesher/hex_quality_kernel.h"

namespace hexbite {

// Per-element measures of a mesh, one entry per hex.
struct HexQualityField {
  std::vector<double> jacobian;         // minimum corner det(A)
  std::vector<double> scaled_jacobian;  // minimum corner scaled Jacobian
  std::vector<double> condition;        // maximum corner kappa (cube = 3); +inf for an inverted hex
  std::vector<double> oddy;             // maximum corner Oddy value; +inf for an inverted hex
};

HexQualityField compute_hex_quality(const HexMesh& mesh);

// Minimum, arithmetic mean and maximum over `count` elements; NaN when count is 0.
struct MeasureStats {
  int count = 0;
  double min = std::numeric_limits<double>::quiet_NaN();
  double mean = std::numeric_limits<double>::quiet_NaN();
  double max = std::numeric_limits<double>::quiet_NaN();
};

// Equal-width bins over [lo, hi], the last bin closed so that it holds hi; values below lo (or NaN) go to
// `below`, values above hi (or +inf) to `above`.
struct Histogram {
  double lo = 0.0;
  double hi = 1.0;
  std::vector<int> counts;
  int below = 0;
  int above = 0;
};

Histogram make_histogram(const std::vector<double>& values, double lo, double hi, int bins);

// Degrees of the interior nodes (nodes not on a boundary face): edges[d] and hexes[d] count the interior
// nodes with d incident mesh edges and d incident hexes. A regular interior node has 6 edges and 8 hexes.
struct NodeDegrees {
  int interior_nodes = 0;
  std::vector<int> edges;
  std::vector<int> hexes;
  int max_edges = 0;
  int max_hexes = 0;
};

NodeDegrees node_degrees(const HexMesh& mesh);

// The quality report of a mesh.
// Jacobian and scaled Jacobian statistics cover all hexes. Condition number and Oddy statistics cover the
// hexes that are not inverted (their values are +inf on inverted hexes, which would make every mean
// infinite); `inverted` says how many hexes were left out.
struct QualitySummary {
  int hexes = 0;
  int nodes = 0;
  MeasureStats jacobian;
  MeasureStats scaled_jacobian;
  MeasureStats condition;          // cube = 3
  MeasureStats condition_verdict;  // Verdict's scale, cube = 1: condition / 3
  MeasureStats oddy;
  int inverted = 0;
  std::vector<int> inverted_hexes;  // indices of the inverted hexes, ascending
  NodeDegrees node_degree;
  Histogram scaled_jacobian_histogram;  // [-1, 1] in 20 bins
  Histogram condition_histogram;        // [3, 13] in 20 bins (cube = 3)
  Histogram oddy_histogram;             // [0, 20] in 20 bins
};

QualitySummary summarize_quality(const HexMesh& mesh);
QualitySummary summarize_quality(const HexMesh& mesh, const HexQualityField& field);

// "hex 12 at (1.00, 2.00, 3.00) mm, ...": the first `shown` of `hexes` (such as the inverted ones) with
// their centroids, then "and N more"; `label(h)`, when given, is written after the hex number (for
// instance " (in input hex 1)").
std::string hex_list_text(const HexMesh& mesh, const std::vector<int>& hexes, std::size_t shown = 20,
                          const std::function<std::string(int)>& label = {});

// "1 hex", "3 hexes".
std::string hex_count_text(std::size_t n);

// "1 hex stays inverted after optimization: hex 12 at (...) mm" ("3 hexes stay ..."), listing `inverted`.
std::string stay_inverted_text(const HexMesh& mesh, const std::vector<int>& inverted);

}  // namespace hexbite
