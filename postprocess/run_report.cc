#include "postprocess/run_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "common/markup_escape.h"
#include "common/number_format.h"
#include "mesher/vec3.h"
#include "postprocess/html.h"
#include "postprocess/report_format.h"

namespace hexbite {

namespace {

// Inline style sheet: A4 pages, tables that do not break across pages, numbers right-aligned.
const char* const kStyle = R"(
@page { size: A4; margin: 15mm 14mm; }
body { font-family: "DejaVu Sans", "Helvetica Neue", Arial, sans-serif; font-size: 10pt; color: #111;
       max-width: 182mm; margin: 0 auto; line-height: 1.35; }
h1 { font-size: 17pt; margin: 0 0 1mm; }
h2 { font-size: 12pt; border-bottom: 1px solid #888; margin: 6mm 0 2mm; break-after: avoid; }
p { margin: 1.5mm 0; }
.subtitle { color: #444; margin-bottom: 4mm; }
table { border-collapse: collapse; margin: 2mm 0; break-inside: avoid; font-size: 9pt; }
th, td { border: 1px solid #bbb; padding: 0.8mm 2mm; text-align: left; vertical-align: top; }
th { background: #eee; font-weight: 600; }
td.n, th.n { text-align: right; font-variant-numeric: tabular-nums; }
td.n { white-space: nowrap; }
.warnings { border: 2px solid #b03a2e; background: #fbeae8; padding: 1mm 4mm; break-inside: avoid; }
.warnings li { margin: 1mm 0; }
.note { font-size: 9pt; color: #333; }
figure { margin: 3mm 0 5mm; break-inside: avoid; }
figure img { width: 100%; height: auto; border: 1px solid #ccc; }
figcaption { font-size: 9pt; margin-top: 1mm; }
footer { margin-top: 8mm; font-size: 8.5pt; color: #555; border-top: 1px solid #ccc; padding-top: 1mm; }
)";

std::string scientific(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2e", v);
  return text;
}

// (fine - coarse) / |fine|, the definition of results.json's relative_change; none when fine is zero.
std::optional<double> change(double coarse, double fine) {
  if (fine == 0) return std::nullopt;
  return (fine - coarse) / std::fabs(fine);
}

// A table row of cells; `numeric` cells are right-aligned. Cells are HTML already.
class Table {
 public:
  explicit Table(std::ostringstream& out) : out_(out) { out_ << "<table>\n"; }
  ~Table() { out_ << "</table>\n"; }
  Table& header(const std::vector<std::pair<std::string, bool>>& cells) { return row(cells, "th"); }
  Table& row(const std::vector<std::pair<std::string, bool>>& cells, const char* tag = "td") {
    out_ << "<tr>";
    for (const auto& [html, numeric] : cells)
      out_ << '<' << tag << (numeric ? " class=\"n\"" : "") << '>' << html << "</" << tag << '>';
    out_ << "</tr>\n";
    return *this;
  }

 private:
  std::ostringstream& out_;
};

std::pair<std::string, bool> text(const std::string& html) {
  return {html, false};
}
std::pair<std::string, bool> num(const std::string& html) {
  return {html, true};
}

std::string stat(const std::optional<double>& v, int decimals) {
  return v ? format_table_number(*v, decimals, 0) : "n/a";
}

void what_was_run(std::ostringstream& out, const RunFigures& r, const ReportOptions& o) {
  const LevelFigures& l = r.coarse;
  out << "<h2>What was run</h2>\n";
  Table t(out);
  t.row(
      {text("scenario"), text(markup_escape(r.scenario) + " (file " + markup_escape(r.scenario_file) + ")")});
  if (r.study)
    t.row({text("study"),
           text("variant " + markup_escape(r.study->variant) + " of study " + markup_escape(r.study->name) +
                " (file " + markup_escape(r.study->file) + "): " +
                (r.study->changes.empty() ? std::string("the scenario as it is")
                                          : "the scenario with " + markup_escape(r.study->changes)))});
  t.row({text("hexbite"), text(r.hexbite_version.empty()
                                   ? "report written by hexbite " + markup_escape(o.hexbite_version) +
                                         "; this results.json does not record the version that ran"
                                   : "run with hexbite " + markup_escape(r.hexbite_version) +
                                         ", report written by hexbite " + markup_escape(o.hexbite_version))});
  t.row({text("mesh"), text("method " + markup_escape(r.mesh_method) +
                            (r.mesh_core.empty() ? "" : ", core " + markup_escape(r.mesh_core)) + "; " +
                            format_count(l.hexes) + " hexes, " + format_count(l.nodes) + " nodes")});
  t.row({text("finite elements"), text("Q" + std::to_string(r.degree) + ", " + format_count(l.dofs) +
                                       " degrees of freedom on the coarse mesh (level 0)")});
  const std::size_t refinements = r.levels.size() - 1;
  t.row({text("levels"), text(std::to_string(r.levels.size()) + ": the coarse mesh" +
                              (refinements == 0 ? std::string(" only")
                                                : " and " + std::to_string(refinements) +
                                                      (refinements == 1 ? " refinement" : " refinements") +
                                                      " (8-way), each solved again"))});
  t.row({text("MPI ranks"), text(std::to_string(l.ranks))});
}

void warnings_section(std::ostringstream& out, const std::vector<std::string>& warnings) {
  if (warnings.empty()) return;
  out << "<h2>Warnings</h2>\n<div class=\"warnings\"><ul>\n";
  for (const std::string& w : warnings) out << "<li>" << markup_escape(w) << "</li>\n";
  out << "</ul></div>\n";
}

// What was simulated: the materials, the muscle loads and the supports, as results.json records them.
void model_section(std::ostringstream& out, const RunFigures& r) {
  out << "<h2>Model</h2>\n";
  if (r.default_material) {
    long in_regions = 0;
    for (const MaterialFigures& m : r.material_regions) in_regions += m.hexes.value_or(0);
    Table t(out);
    t.header({text("material"), num("E (MPa)"), num("Poisson&rsquo;s ratio"), num("hexes")});
    const auto row = [&](const std::string& name, const MaterialFigures& m, long hexes) {
      char e[32], nu[32];
      std::snprintf(e, sizeof e, "%g", m.E_MPa);
      std::snprintf(nu, sizeof nu, "%g", m.poisson);
      t.row({text(name), num(e), num(nu), num(format_count(hexes))});
    };
    row("bone (default)", *r.default_material, r.coarse.hexes - in_regions);
    for (const MaterialFigures& m : r.material_regions)
      row("region " + markup_escape(m.name), m, m.hexes.value_or(0));
  } else {
    out << "<p>This results.json records no materials (it was written by an older hexbite): see the "
           "scenario file.</p>\n";
  }
  if (!r.muscles.empty()) {
    out << "<p>Muscle loads: uniform tractions over each insertion patch, along the line of action.</p>\n";
    Table t(out);
    t.header({text("muscle"), num("activation"), num("force (N)"), text("direction"),
              num("patch (mm<sup>2</sup>)")});
    for (const MuscleFigures& m : r.muscles) {
      const std::string activation = format_table_number(m.activation.value_or(0), 2, 0);
      const Vec3 unit = m.magnitude > 0 ? vec3::scale(m.force, 1.0 / m.magnitude) : m.force;
      t.row({text(markup_escape(m.name)), num(m.activation ? activation : "n/a"),
             num(format_newtons(m.magnitude)), text(format_point(unit, 2)),
             num(format_significant_digits(m.patch_area_mm2, 3))});
    }
  }
  if (r.supports.empty()) return;
  out << "<p>Supports: patches of the bone surface around a centre.</p>\n";
  Table t(out);
  t.header({text("support"), text("condition"), text("centre (mm)"), num("radius (mm)"),
            num("patch (mm<sup>2</sup>)")});
  for (const SupportFigures& s : r.supports) {
    std::string condition = "n/a";
    if (s.spring_N_per_mm3) {
      char k[64];
      std::snprintf(k, sizeof k, "spring, %g N/mm<sup>3</sup>", *s.spring_N_per_mm3);
      condition = k;
    } else if (s.fixed) {
      condition = "fixed";
      for (std::size_t i = 0; i < s.fixed->size(); ++i)
        condition += (i == 0 ? " " : ", ") + markup_escape((*s.fixed)[i]);
      if (s.contact) condition += " (contact: pushes only)";
    }
    char radius[32];
    std::snprintf(radius, sizeof radius, "%g", s.radius_mm.value_or(0));
    t.row({text(markup_escape(s.name)), text(condition), text(s.center ? format_point(*s.center) : "n/a"),
           num(s.radius_mm ? radius : "n/a"), num(format_significant_digits(s.patch_area_mm2, 3))});
  }
}

void results_section(std::ostringstream& out, const RunFigures& r) {
  const LevelFigures& l = r.coarse;
  out << "<h2>Results</h2>\n<p>The coarse mesh (level 0, the mesh of <code>solution.vtu</code>, or "
         "<code>solution.pvtu</code> under mpirun); the validation table below gives every level. Units: "
         "mm, N, MPa, mJ.</p>\n";
  {
    Table t(out);
    t.header({text("figure"), num("value"), text("where / components")});
    t.row({text("bite force (N)"), num(l.bite_force ? format_newtons(*l.bite_force) : "n/a"),
           text(l.bite_force ? "magnitude of the summed reactions of the bite supports"
                             : "not reported (outputs.bite_force: false)")});
    t.row({text("applied force (N)"), num(format_newtons(vec3::norm(l.applied_force))),
           text(format_point(l.applied_force) + ", the sum of the muscle forces")});
    t.row({text("equilibrium residual"), num(scientific(l.equilibrium_residual)),
           text("|applied + reactions| / |applied|")});
    t.row({text("max displacement (mm)"), num(format_mm(l.max_displacement)),
           text("at " + format_point(l.max_displacement_at))});
    t.row({text("von Mises max (MPa)"), num(format_mpa(l.von_mises_max)),
           text("at " + format_point(l.von_mises_max_at) + ", over all quadrature points")});
    t.row({text("von Mises p99 (MPa)"), num(format_mpa(l.von_mises_p99)),
           text("99th percentile of the per-hex stress")});
    t.row({text("strain energy (mJ)"), num(format_significant_digits(l.strain_energy, 3)), text("")});
  }
  out << "<p>Reactions: the force each support exerts on the bone.</p>\n";
  Table t(out);
  t.header({text("support"), text("bite"), num("F<sub>x</sub> (N)"), num("F<sub>y</sub> (N)"),
            num("F<sub>z</sub> (N)"), num("|F| (N)")});
  for (const ReactionFigures& s : l.reactions)
    t.row({text(markup_escape(s.name) + (s.released ? " (contact released: it would pull the bone)" : "")),
           text(s.bite ? "yes" : "no"), num(format_newtons(s.force[0])), num(format_newtons(s.force[1])),
           num(format_newtons(s.force[2])), num(format_newtons(s.magnitude))});
}

void validation_section(std::ostringstream& out, const RunFigures& r) {
  out << "<h2>Validation: convergence under refinement</h2>\n";
  {
    Table t(out);
    t.header({num("level"), num("hexes"), num("dofs"), num("bite force (N)"), num("change"),
              num("max displ. (mm)"), num("change"), num("strain energy (mJ)"), num("change"),
              num("von Mises max (MPa)"), num("change")});
    const LevelFigures* previous = nullptr;
    for (const LevelFigures& l : r.levels) {
      const auto delta = [&](double coarse, double fine) {
        return num(previous == nullptr ? "&ndash;" : format_percent(change(coarse, fine)));
      };
      const bool bite = l.bite_force && (previous == nullptr || previous->bite_force);
      t.row({num(std::to_string(l.level)), num(format_count(l.hexes)), num(format_count(l.dofs)),
             num(l.bite_force ? format_newtons(*l.bite_force) : "n/a"),
             bite ? delta(previous ? *previous->bite_force : 0.0, *l.bite_force) : num("n/a"),
             num(format_mm(l.max_displacement)),
             delta(previous ? previous->max_displacement : 0.0, l.max_displacement),
             num(format_significant_digits(l.strain_energy, 3)),
             delta(previous ? previous->strain_energy : 0.0, l.strain_energy),
             num(format_mpa(l.von_mises_max)),
             delta(previous ? previous->von_mises_max : 0.0, l.von_mises_max)});
      previous = &l;
    }
  }
  if (r.levels.size() < 2) {
    out << "<p>This run has no validation level (<code>mesh.validation_levels: 0</code> or "
           "<code>--levels 0</code>), so nothing here shows how much its figures depend on the mesh: run "
           "with <code>--levels 1</code> to see.</p>\n";
    return;
  }
  // A contact released at some levels only: those levels were solved with other supports, and their change
  // holds that besides the refinement.
  std::string differs;
  for (std::size_t i = 0; i < r.levels.front().reactions.size(); ++i) {
    std::string at;
    for (const LevelFigures& l : r.levels)
      if (i < l.reactions.size() && l.reactions[i].released)
        at += (at.empty() ? "" : ", ") + std::to_string(l.level);
    const std::size_t count =
        at.empty() ? 0 : 1 + static_cast<std::size_t>(std::count(at.begin(), at.end(), ','));
    if (count > 0 && count < r.levels.size())
      differs += (differs.empty() ? "" : "; ") + markup_escape(r.levels.front().reactions[i].name) +
                 " at level " + at;
  }
  if (!differs.empty())
    out << "<p class=\"note\">Contacts released at some levels only (" << differs
        << "; a contact that would pull the bone is left out of that level&rsquo;s solve): the changes "
           "between a "
           "level with and one without it hold that change of supports, not only the refinement.</p>\n";
  out << "<p>Each change is (level k &minus; level k&minus;1) / |level k|: an estimate of how far the "
         "coarser level&rsquo;s figure is from the value of an ever finer mesh, not of the finer "
         "level&rsquo;s own error (usually smaller) nor of the model&rsquo;s (geometry, material, muscle "
         "forces); the von Mises maximum usually lies at the edge of a fixed patch, where the stress of the "
         "exact solution is unbounded, so its change need not shrink under refinement.</p>\n";
}

void quality_section(std::ostringstream& out, const RunFigures& r) {
  out << "<h2>Mesh quality (coarse mesh)</h2>\n";
  {
    Table t(out);
    t.header({text("quality measure"), num("min"), num("average"), num("max")});
    const auto row = [&](const char* name, const QualityFigures& q, int decimals) {
      t.row(
          {text(name), num(stat(q.min, decimals)), num(stat(q.mean, decimals)), num(stat(q.max, decimals))});
    };
    row("scaled Jacobian", r.scaled_jacobian, 3);
    row("condition number (cube = 3)", r.condition, 2);
    row("condition number (Verdict, cube = 1)", r.condition_verdict, 2);
    row("Oddy", r.oddy, 2);
  }
  out << "<p>Inverted elements: " << r.inverted << ".</p>\n";
  if (!r.fidelity) return;
  const FidelityFigures& f = *r.fidelity;
  out << "<h2>Geometric fidelity</h2>\n";
  const auto mm = [](const std::optional<double>& v) { return v ? format_mm(*v) : "n/a"; };
  const auto mm3 = [](const std::optional<double>& v) {
    return v ? format_count(std::lround(*v)) : std::string("n/a");
  };
  Table t(out);
  t.row({text("Hausdorff distance, mesh and bone surface (mm)"), num(mm(f.hausdorff))});
  t.row({text("&nbsp;&nbsp;mesh to surface / surface to mesh (mm)"),
         num(mm(f.hausdorff_mesh_to_surface) + " / " + mm(f.hausdorff_surface_to_mesh))});
  t.row({text("volume of the mesh / of the surface (mm<sup>3</sup>)"),
         num(mm3(f.mesh_volume) + " / " + mm3(f.surface_volume))});
  t.row(
      {text("volume difference (mesh &minus; surface) / surface"), num(format_percent(f.volume_difference))});
}

void probes_section(std::ostringstream& out, const RunFigures& r) {
  out << "<h2>Probes</h2>\n";
  if (r.coarse.probes.empty()) {
    out << "<p>The scenario has no probes.</p>\n";
    return;
  }
  {  // the table closed before the note: a <p> inside a <table> is invalid, and browsers move it above
    Table t(out);
    t.header({text("probe"), text("point (mm)"), text("displacement (mm)"), num("|u| (mm)"),
              num("von Mises (MPa)"), num("moved (mm)")});
    for (const ProbeFigures& p : r.coarse.probes) {
      if (!p.found) {
        t.row({text(markup_escape(p.name)), text(format_point(p.at)), text("not in the mesh"), num("n/a"),
               num("n/a"), num(format_mm(p.moved_mm))});
        continue;
      }
      char u[128];
      std::snprintf(u, sizeof u, "(%s, %s, %s)", format_mm(p.displacement[0]).c_str(),
                    format_mm(p.displacement[1]).c_str(), format_mm(p.displacement[2]).c_str());
      t.row({text(markup_escape(p.name)), text(format_point(p.at)), text(u),
             num(format_mm(vec3::norm(p.displacement))), num(format_mpa(p.von_mises)),
             num(format_mm(p.moved_mm))});
    }
  }
  out << "<p class=\"note\">A probe outside the mesh is evaluated at the closest point just inside it; "
         "&ldquo;moved&rdquo; says how far.</p>\n";
}

void solver_section(std::ostringstream& out, const RunFigures& r) {
  out << "<h2>Solver</h2>\n";
  Table t(out);
  t.header(
      {num("level"), num("dofs"), text("linear solver"), num("iterations"), num("seconds"), num("ranks")});
  for (const LevelFigures& l : r.levels) {
    const std::string seconds = format_table_number(l.solve_seconds, 2, 0);
    t.row({num(std::to_string(l.level)), num(format_count(l.dofs)),
           text(l.iterations == 0 ? "direct (MUMPS)" : "CG with algebraic multigrid (Trilinos ML)"),
           num(std::to_string(l.iterations)), num(seconds), num(std::to_string(l.ranks))});
  }
}

void pictures_section(std::ostringstream& out, const std::vector<ReportPicture>& pictures) {
  out << "<h2>Pictures</h2>\n";
  if (pictures.empty()) {
    out << "<p>This report has no pictures: it was written with <code>--no-pictures</code>.</p>\n";
    return;
  }
  out << "<p class=\"note\">The coarse level&rsquo;s solution on the outer surface of the mesh, node "
         "values (the corner stresses of the adjacent hexes averaged).</p>\n";
  for (const ReportPicture& p : pictures)
    out << "<figure><img alt=\"" << markup_escape(p.field + ", " + p.view + " view")
        << "\" src=\"data:image/png;base64," << base64(p.png) << "\">\n<figcaption>"
        << markup_escape(p.caption) << "</figcaption></figure>\n";
}

}  // namespace

std::vector<std::string> report_warnings(const RunFigures& r) {
  std::vector<std::string> w;
  for (std::size_t b = 0; b < r.support_hold.size(); ++b) {
    const SupportHoldFigures& h = r.support_hold[b];
    if (!h.weak) continue;
    char hold[32];
    std::snprintf(hold, sizeof hold, "%.2g", h.hold);
    const std::string body = r.support_hold.size() > 1 ? " of body " + std::to_string(b + 1) + " of " +
                                                             std::to_string(r.support_hold.size())
                                                       : "";
    const std::string motion = h.rotation
                                   ? "a rotation about the axis through " + format_point(*h.axis_point) +
                                         " mm along " + format_point(h.direction, 2)
                                   : "a translation along " + format_point(h.direction, 2);
    w.push_back(
        "Weak supports: the supports" + body + " hold the bone only weakly (hold " + hold +
        ", below 0.02) against " + motion +
        "; the displacements and stresses then depend mostly on how the patches resist that motion. "
        "A body clamped at one end (a cantilever) is held so by design; otherwise fix more components "
        "of a support (docs/scenario-format.md, \"Weak supports\").");
  }
  for (const LevelFigures& l : r.levels)
    if (!(l.equilibrium_residual <= kReportEquilibriumLimit))
      w.push_back("Equilibrium: on level " + std::to_string(l.level) +
                  " the applied forces and the reactions do not balance (relative residual " +
                  scientific(l.equilibrium_residual) +
                  ", above 1e-8): do not trust the reactions and the bite "
                  "force; tighten solver.tolerance and run again.");
  for (const LevelFigures& l : r.levels)
    if (!(l.max_displacement <= r.max_displacement_limit))
      w.push_back("Small displacements: on level " + std::to_string(l.level) + " the largest displacement, " +
                  format_significant_digits(l.max_displacement, 3) +
                  " mm, is more than 10 % of the bone's size (" + format_significant_digits(r.bone_size, 4) +
                  " mm), but linear elasticity holds only for small displacements: the run failed this "
                  "check and every figure of this report is meaningless. Check materials E_MPa (in MPa, "
                  "cortical bone about 11000), the muscles' max_force_N (in N) and that the supports hold "
                  "the bone, and run again.");
  const int last = r.levels.back().level;
  const auto changed = [&](const std::optional<double>& c, const char* figure) {
    if (c && std::fabs(*c) > kReportChangeLimit)
      w.push_back(std::string("Convergence: the ") + figure + " changes by " + format_percent(c) +
                  " from level " + std::to_string(last - 1) + " to level " + std::to_string(last) +
                  " (more than 5 %): the coarser mesh is too coarse for this figure; use a finer mesh "
                  "(mesh.target_hexes) or another validation level.");
  };
  changed(r.change_bite_force, "bite force");
  changed(r.change_max_displacement, "maximum displacement");
  changed(r.change_strain_energy, "strain energy");
  if (r.inverted > 0)
    w.push_back("Inverted elements: the coarse mesh has " + std::to_string(r.inverted) +
                " inverted hexes; its figures are not trustworthy.");
  return w;
}

std::string report_html(const RunFigures& r, const std::vector<std::string>& warnings,
                        const std::vector<ReportPicture>& pictures, const ReportOptions& o) {
  const std::string title = markup_escape(o.title.empty() ? r.scenario : o.title);
  std::ostringstream out;
  out << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>" << title
      << "</title>\n<style>" << kStyle << "</style>\n</head>\n<body>\n<h1>" << title
      << "</h1>\n<p class=\"subtitle\">Bite-force validation report of a <code>hexbite run</code></p>\n";
  what_was_run(out, r, o);
  warnings_section(out, warnings);
  model_section(out, r);
  results_section(out, r);
  validation_section(out, r);
  quality_section(out, r);
  probes_section(out, r);
  solver_section(out, r);
  pictures_section(out, pictures);
  out << "<footer>Written by <code>hexbite report</code> from the run&rsquo;s results.json"
      << (pictures.empty() ? "" : " and solution.vtu")
      << ". Units: mm, N, MPa, mJ.</footer>\n</body>\n</html>\n";
  return out.str();
}

}  // namespace hexbite
