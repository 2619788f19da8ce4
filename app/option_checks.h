// CLI11 checks run while the command line is parsed, so a bad value is an input error (exit 2) before any
// work: counts such as --target-hexes, and output files and folders.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace hexbite {

// Counts: accepts a whole number written plainly or in scientific notation ("30000", "3e4") and rejects
// fractions, non-numbers and counts outside [lo, hi] with a message that gives the range (CLI11's own
// integer conversion rejects "3e4" and says only "Could not convert", without the range). A transforming
// validator (add it with Option::transform): it rewrites an accepted value to its plain decimal form.
CLI::Validator count_in_range(long lo, long hi);

// A real number in [lo, hi]: rejects non-numbers, NaN and infinities (CLI::Range lets NaN through, since
// every comparison with it is false) with a message that gives the range, `range` ("from -0.8 to 2").
CLI::Validator number_in_range(double lo, double hi, const std::string& range);

// Text that goes into a heading of the output (a --title, `what` is "the title"): refuses bytes that are
// not UTF-8 and control characters, with what to do, as a scenario's names are refused. Before, a Latin-1
// title made the report's HTML invalid UTF-8 (it declares utf-8), a control character invalid HTML, and
// `render` dropped such a caption from the picture and still said "wrote".
CLI::Validator one_line_of_text(const std::string& what);

// An output file: its folder exists, it is not itself a folder, and it ends (in any case) in one of
// `extensions` (".vtu", or ".nii.gz"), the formats the command writes. Checked before the work, so a typo
// in -o does not cost a whole meshing run, and a .txt name never gets a VTU written into it.
CLI::Validator output_file(std::vector<std::string> extensions);

// An output surface: output_file with the formats write_surface knows (.stl, .obj, .ply, .off, .vtp).
CLI::Validator output_surface_file();
// An output hex mesh: output_file with the formats write_hex_mesh knows (.vtu, .inp, .msh).
CLI::Validator output_hex_mesh_file();

// An output folder: a folder or a path that does not exist yet (it is created), never an existing file.
CLI::Validator output_folder();

// `--export FORMAT` of run and study into `formats`: inp (CalculiX) is the one format; it may be repeated.
void add_export_option(CLI::App& command, std::vector<std::string>& formats);

}  // namespace hexbite
