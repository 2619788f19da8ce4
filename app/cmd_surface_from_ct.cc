// `hexbite surface from-ct`: the iso-surface of a CT volume, the first step of the seed paper's pipeline.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <limits>

#include "app/commands.h"
#include "app/option_checks.h"
#include "common/error.h"
#include "common/progress.h"
#include "mesher/ct_surface.h"
#include "mesher/surface_io.h"
#include "mesher/units.h"

namespace hexbite {

namespace {

struct FromCtArgs {
  std::string volume, output, series;
  std::string units;  // empty: the unit the file states, or mm
  double threshold = 0;
};

void run_from_ct(const FromCtArgs& args) {
  // The output folder is checked first: a long extraction should not end in "cannot write".
  const std::filesystem::path out(args.output);
  const auto dir = out.has_parent_path() ? out.parent_path() : std::filesystem::path(".");
  if (!std::filesystem::is_directory(dir))
    throw InputError("cannot write '" + args.output + "': directory '" + dir.string() +
                     "' does not exist; create it first");

  if (!args.units.empty()) unit_to_mm(args.units);  // an unknown unit is refused before the reading

  const auto start = std::chrono::steady_clock::now();
  Progress progress("extract surface");
  VolumeInfo source;
  VoxelVolume volume = read_volume(args.volume, &source, args.series);
  if (!args.units.empty()) rescale_volume_units(volume, source.length_unit, args.units);
  CtExtraction dropped;
  TriSurface surface;
  try {
    surface = surface_from_volume(volume, args.threshold, &dropped);
  } catch (const InputError& e) {
    // The threshold's messages speak of "the volume": say which file.
    throw InputError("'" + args.volume + "': " + e.what());
  }
  progress.finish();
  write_surface(args.output, surface);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  double six_volume = 0;
  for (const auto& t : surface.triangles) {
    const Vec3& a = surface.vertices[t[0]];
    const Vec3& b = surface.vertices[t[1]];
    const Vec3& c = surface.vertices[t[2]];
    six_volume += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                  a[2] * (b[0] * c[1] - b[1] * c[0]);
  }
  const Vec3 h = volume.spacing_xyz();
  if (!source.description.empty()) info(source.description);
  for (const std::string& sentence : source.warnings)
    std::fprintf(stderr, "hexbite: warning: '%s': %s.\n", args.volume.c_str(), sentence.c_str());
  char buf[512];
  std::snprintf(buf, sizeof buf, "volume %d x %d x %d voxels of %g x %g x %g mm, threshold %g",
                volume.dims[0], volume.dims[1], volume.dims[2], h[0], h[1], h[2], args.threshold);
  info(buf);
  std::snprintf(buf, sizeof buf, "surface: %zu triangles, %zu vertices, enclosed volume %.1f cm^3; %.2f s",
                surface.triangles.size(), surface.vertices.size(), six_volume / 6000.0, seconds);
  info(buf);
  info("wrote " + args.output);
  // A volume whose spacing is in metres gives a bone a thousand times too small. Its lengths were read in
  // --units, else in the unit the file states (a NIfTI header, DICOM's mm), else (MetaImage) in mm.
  const std::string read_as = !args.units.empty()          ? args.units
                              : source.length_unit.empty() ? "mm"
                                                           : source.length_unit;
  const std::string size_warning = implausible_size_warning(
      largest_extent(surface), read_as,
      "give --units <unit>" + (args.units.empty() && !source.length_unit.empty()
                                   ? " (it overrides the unit the file states, " + source.length_unit + ")"
                                   : std::string()));
  if (!size_warning.empty())
    std::fprintf(stderr, "hexbite: warning: '%s': %s.\n", args.volume.c_str(), size_warning.c_str());
  // Only the largest piece is kept; what else the threshold found must not vanish without a word
  // (a second bone or a fracture fragment, a marrow cavity that is now solid).
  for (const std::string& sentence : describe_dropped(dropped, args.threshold))
    std::fprintf(stderr, "hexbite: warning: '%s': %s.\n", args.volume.c_str(), sentence.c_str());
}

}  // namespace

void add_surface_from_ct_command(CLI::App& surface) {
  CLI::App* cmd = surface.add_subcommand("from-ct",
                                         "Extract the bone surface from a CT volume (MetaImage .mha/.mhd, "
                                         "NIfTI .nii/.nii.gz, or a folder holding a DICOM series)");
  auto args = std::make_shared<FromCtArgs>();
  cmd->add_option("VOLUME", args->volume, "CT volume file, or a folder of DICOM slices (one series)")
      ->required();
  cmd->add_option("--threshold", args->threshold,
                  "Iso-value in the volume's units (e.g. Hounsfield units; the built-in mandible uses 620)")
      ->required()
      ->check(number_in_range(-std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
                              "that is finite, in the volume's units (e.g. 620 Hounsfield units)"));
  cmd->add_option(
      "--units", args->units,
      "Length unit of the volume's spacing and origin: mm, cm or m (the surface is written in mm); "
      "overrides the unit a NIfTI or DICOM file states; a MetaImage states none and is read as mm");
  cmd->add_option("--series", args->series,
                  "In a folder holding several DICOM series, the one to read: its Series Number, Series "
                  "Description or Series Instance UID");
  cmd->add_option("-o,--output", args->output, "Surface file to write (STL, OBJ, PLY, OFF, VTP)")
      ->required()
      ->check(output_surface_file());
  cmd->callback([args] { run_from_ct(*args); });
}

}  // namespace hexbite
