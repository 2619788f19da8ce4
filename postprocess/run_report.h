// The validation report of a finished run (hexbite report): one self-contained HTML file, inline CSS and
// pictures embedded as PNG data URIs, no scripts or external resources, laid out for A4. Contents in
// order: title, what was run, warnings (when there are any), the model (materials, muscle loads, supports),
// results of the coarse level, the convergence table of the validation levels, mesh quality (the seed
// paper's Table 1 layout) and geometric fidelity, probes, solver, pictures. Every string from results.json
// is HTML-escaped. Deterministic: the same figures and pictures give the same bytes.
#pragma once

#include <string>
#include <vector>

#include "postprocess/report_pictures.h"
#include "postprocess/run_results.h"

namespace hexbite {

// Above these the report warns (docs/reports.md): the run's own equilibrium check fails above the first,
// and a change of more than the second between the last two levels means the coarse mesh is not converged.
constexpr double kReportEquilibriumLimit = 1e-8;
constexpr double kReportChangeLimit = 0.05;

// What the reader of the figures should know first, as plain sentences: weak supports (with their axis),
// an equilibrium residual above kReportEquilibriumLimit, a relative change between the last two levels
// above kReportChangeLimit, inverted hexes. Empty when there is nothing to warn about.
std::vector<std::string> report_warnings(const RunFigures& run);

struct ReportOptions {
  std::string title;            // empty: the scenario's name
  std::string hexbite_version;  // of the program writing the report (results.json does not record one)
};

// The report's HTML. With no pictures it says that it was made without them (--no-pictures).
std::string report_html(const RunFigures& run, const std::vector<std::string>& warnings,
                        const std::vector<ReportPicture>& pictures, const ReportOptions& options);

}  // namespace hexbite
