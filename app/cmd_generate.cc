// `hexbite generate mandible`: the built-in CT-like mandible with its landmark file and, on request,
// the CT-like volume it was extracted from.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <iterator>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "app/commands.h"
#include "app/option_checks.h"
#include "common/error.h"
#include "common/output_stage.h"
#include "common/progress.h"
#include "mesher/ct_surface.h"
#include "mesher/dicom_series.h"
#include "mesher/landmarks.h"
#include "mesher/mandible_generator.h"
#include "mesher/surface_io.h"

namespace hexbite {

namespace {

namespace fs = std::filesystem;

struct GenerateArgs {
  std::string output, landmarks, ct, dicom, variant = "dentate";
  MandibleParameters parameters;
};

std::string default_landmark_path(const std::string& surface_path) {
  fs::path p(surface_path);
  return (p.parent_path() / (p.stem().string() + ".landmarks.yaml")).string();
}

double enclosed_volume(const TriSurface& s) {
  double six = 0;
  for (const auto& t : s.triangles) {
    const Vec3& a = s.vertices[t[0]];
    const Vec3& b = s.vertices[t[1]];
    const Vec3& c = s.vertices[t[2]];
    six += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
           a[2] * (b[0] * c[1] - b[1] * c[0]);
  }
  return six / 6.0;
}

// The surface, the landmarks and the CT go to up to three folders of the user's choice. Each file is written
// into a stage inside its folder (common/output_stage.h), and the stages are moved in only when every file
// is complete: a write that fails (a full disk, an unwritable folder) leaves none of this run's files, and
// the earlier ones untouched. Before, a failed CT write left the new surface beside an old CT. The moves of
// two folders are not one transaction, but the moves are renames of paths checked while parsing; the
// writes, where disks fill up, are all done before the first of them.
class GenerateOutputs {
 public:
  // Calls write(path in the stage of `path`'s folder); an error names the file by `path`.
  void write(const std::string& path, const std::function<void(const std::string&)>& write) {
    const fs::path target(path);
    const OutputStage& stage = stage_for(target.has_parent_path() ? target.parent_path().string() : ".");
    guarded(stage, [&] { write(stage.stage_dir() + "/" + target.filename().string()); });
  }

  // Calls write(the stage of the folder `dir`) for a set of files of its own (a DICOM series); at the
  // commit, the files of the folder for which `retire(name)` is true and that this run did not write (a
  // longer series of an earlier run) are removed.
  void write_folder(const std::string& dir, const std::function<void(const std::string&)>& write,
                    const std::function<bool(const std::string&)>& retire) {
    const OutputStage& stage = stage_for(dir);
    retire_[&stage] = retire;
    guarded(stage, [&] { write(stage.stage_dir()); });
  }

  // Moves every staged file into its folder (a .mhd's data file too, which the writer names itself). Every
  // folder is checked before the first is moved in: a folder in the way of a DICOM slice's name failed the
  // DICOM folder's commit after the surface, landmarks and CT were in place, replacing the earlier ones.
  // The folders stay locked over all the moves, and signals wait: another generate into the same folders
  // moved its surface in between ours and our DICOM series.
  void commit() {
    std::vector<std::string> dirs;
    for (const auto& stage : stages_) dirs.push_back(stage->dir());
    const CommitLock locked(dirs);
    std::vector<std::vector<std::string>> files(stages_.size());
    for (std::size_t i = 0; i < stages_.size(); ++i) {
      for (const fs::directory_entry& entry : fs::directory_iterator(stages_[i]->stage_dir()))
        if (entry.is_regular_file()) files[i].push_back(entry.path().filename().string());
      std::sort(files[i].begin(), files[i].end());
      const std::string why = stages_[i]->blocked(files[i]);
      if (!why.empty()) throw RunError(why + kKept);
    }
    for (std::size_t i = 0; i < stages_.size(); ++i) {
      const auto retire = retire_.find(stages_[i].get());
      stages_[i]->commit(files[i], retire == retire_.end() ? nullptr : retire->second);
    }
  }

 private:
  OutputStage& stage_for(const std::string& dir) {
    auto it = std::find_if(stages_.begin(), stages_.end(),
                           [&](const std::unique_ptr<OutputStage>& s) { return s->dir() == dir; });
    if (it != stages_.end()) return **it;
    stages_.push_back(std::make_unique<OutputStage>(dir));  // throws naming `dir`
    return *stages_.back();
  }

  // Runs `write`; its error names the file by its place in the output folder, and says nothing was written.
  static void guarded(const OutputStage& stage, const std::function<void()>& write) {
    try {
      write();
    } catch (const InputError& e) {
      throw InputError(named_in_dir(e.what(), stage.stage_dir(), stage.dir()) + kKept);
    } catch (const std::exception& e) {
      throw RunError(named_in_dir(e.what(), stage.stage_dir(), stage.dir()) + kKept);
    }
  }

  static constexpr const char* kKept =
      "; none of the outputs was written (files of those names are as they were)";

  std::vector<std::unique_ptr<OutputStage>> stages_;  // one per output folder; uncommitted ones discarded
  std::map<const OutputStage*, std::function<bool(const std::string&)>> retire_;
};

// The slice files of a series that write_dicom_series wrote into `dir`: ct_0001.dcm, ct_0002.dcm, ...,
// each a DICOM file. A file of such a name that is no DICOM file (the user's notes) was never written by
// hexbite, and an earlier series' retirement must not remove it.
bool is_series_slice(const std::string& dir, const std::string& name) {
  return name.size() == 11 && name.compare(0, 3, "ct_") == 0 && name.compare(7, 4, ".dcm") == 0 &&
         std::all_of(name.begin() + 3, name.begin() + 7, [](char c) { return c >= '0' && c <= '9'; }) &&
         has_dicom_preamble((fs::path(dir) / name).string());
}

// Two outputs of one path (`-o jaw.stl --dicom jaw.stl`), or the DICOM folder inside another output's path,
// failed only when the files were moved in, after the work ("a folder of that name is in the way", exit 1).
// The paths are compared as the system would resolve them (links, "./", a trailing "/").
struct NamedOutput {
  std::string option, path;
  bool folder = false;  // --dicom: the other outputs may lie in it
};

void require_distinct_outputs(const std::vector<NamedOutput>& outputs) {
  const auto resolved = [](const std::string& path) {
    std::error_code ec;
    fs::path p = fs::weakly_canonical(fs::absolute(path), ec);
    if (ec) p = fs::absolute(path).lexically_normal();
    return p.has_filename() ? p : p.parent_path();  // "ct/" is "ct"
  };
  for (std::size_t i = 0; i < outputs.size(); ++i)
    for (std::size_t j = 0; j < outputs.size(); ++j) {
      if (i == j) continue;
      const fs::path a = resolved(outputs[i].path), b = resolved(outputs[j].path);
      const std::string both = outputs[i].option + " '" + outputs[i].path + "' and " + outputs[j].option +
                               " '" + outputs[j].path + "'";
      if (i < j && a == b) throw InputError(both + " are the same path; give each output its own name");
      const fs::path inside = b.lexically_relative(a);
      if (!outputs[i].folder && a != b && !inside.empty() && *inside.begin() != "..")
        throw InputError(both + ": the second lies inside the first, which is a file; give each output " +
                         "its own place");
    }
}

void run_generate(const GenerateArgs& args) {
  MandibleParameters params = args.parameters;
  params.variant = parse_variant(args.variant);
  params = complete_parameters(params);
  const std::string landmark_path =
      args.landmarks.empty() ? default_landmark_path(args.output) : args.landmarks;
  // Every output path given was checked while parsing (app/option_checks.h), so a mistake in one of them
  // is found before any work. The default landmark path is checked here, before the work too: a folder of
  // that name, or a name too long for the file system, failed only after the mandible was made (exit 1).
  if (args.landmarks.empty()) {
    std::string path = landmark_path;
    const std::string problem = output_file({".yaml"})(path);
    if (!problem.empty())
      throw InputError(problem +
                       " (the landmark file's default name, from -o); give --landmarks another path");
  }
  std::vector<NamedOutput> named = {
      {"-o", args.output},
      {args.landmarks.empty() ? "the landmark file (its default name, from -o)" : "--landmarks",
       landmark_path}};
  if (!args.ct.empty()) named.push_back({"--ct", args.ct});
  if (!args.dicom.empty()) named.push_back({"--dicom", args.dicom, true});
  require_distinct_outputs(named);

  const auto start = std::chrono::steady_clock::now();
  Progress progress("generate mandible");
  const GeneratedMandible jaw = generate_mandible(params);
  progress.finish();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  GenerateOutputs outputs;
  outputs.write(args.output, [&](const std::string& p) { write_surface(p, jaw.surface); });
  outputs.write(landmark_path, [&](const std::string& p) {
    write_landmarks(p, jaw.landmarks, mandible_landmark_header(params));
  });
  if (!args.ct.empty()) outputs.write(args.ct, [&](const std::string& p) { write_volume(p, jaw.ct); });
  if (!args.dicom.empty())
    outputs.write_folder(
        args.dicom, [&](const std::string& dir) { write_dicom_series(dir, jaw.ct); },
        [&](const std::string& name) { return is_series_slice(args.dicom, name); });
  outputs.commit();

  Vec3 lo{std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
          std::numeric_limits<double>::max()};
  Vec3 hi{-lo[0], -lo[1], -lo[2]};
  for (const auto& v : jaw.surface.vertices)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], v[k]);
      hi[k] = std::max(hi[k], v[k]);
    }
  char buf[512];
  std::snprintf(buf, sizeof buf, "mandible (%s): %zu triangles, %zu vertices", variant_name(params.variant),
                jaw.surface.triangles.size(), jaw.surface.vertices.size());
  info(buf);
  std::snprintf(buf, sizeof buf,
                "  bounding box %.1f x %.1f x %.1f mm, from (%.1f, %.1f, %.1f) to (%.1f, %.1f, %.1f)",
                hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
  info(buf);
  std::snprintf(buf, sizeof buf, "  volume %.1f cm^3", enclosed_volume(jaw.surface) / 1000.0);
  info(buf);
  std::snprintf(
      buf, sizeof buf,
      "  dimensions: arch width %g, arch depth %g, body height %g, body thickness %g, ramus height %g, "
      "ramus width %g mm, gonial angle %g deg",
      params.arch_width_mm, params.arch_depth_mm, params.body_height_mm, params.body_thickness_mm,
      params.ramus_height_mm, params.ramus_width_mm, params.gonial_angle_deg);
  info(buf);
  std::snprintf(buf, sizeof buf, "  CT grid %d x %d x %d voxels of %g mm, threshold %g HU; %.2f s",
                jaw.ct.dims[0], jaw.ct.dims[1], jaw.ct.dims[2], jaw.ct.spacing, jaw.threshold, seconds);
  info(buf);
  info("wrote " + args.output + ", " + landmark_path + (args.ct.empty() ? "" : ", " + args.ct) +
       (args.dicom.empty() ? ""
                           : ", " + (fs::path(args.dicom) / "ct_0001.dcm").lexically_normal().string() +
                                 " ... (a DICOM series of " + std::to_string(jaw.ct.dims[2]) + " slices)"));
}

// "Body height at the first molar in mm, 8 to 40 (default: dentate 27, edentulous 21, atrophic 12)": the
// range and the defaults from the generator's one table (mandible_dimensions, mandible_defaults); one
// default when the variants share it.
std::string dimension_help(const MandibleDimension& dim) {
  const bool degrees = std::string(dim.unit) == "deg";
  std::string help = std::string(dim.meaning) + (degrees ? " in degrees" : " in mm");
  char buf[160];
  std::snprintf(buf, sizeof buf, ", %g to %g (default: ", dim.lo, dim.hi);
  help += buf;
  const MandibleVariant variants[] = {MandibleVariant::kDentate, MandibleVariant::kEdentulous,
                                      MandibleVariant::kAtrophic};
  const double first = mandible_defaults(variants[0]).*dim.field;
  const bool same = std::all_of(std::begin(variants), std::end(variants),
                                [&](MandibleVariant v) { return mandible_defaults(v).*dim.field == first; });
  for (const MandibleVariant v : variants) {
    if (same) {
      std::snprintf(buf, sizeof buf, "%g", first);
    } else {
      std::snprintf(buf, sizeof buf, "%s%s %g", v == variants[0] ? "" : ", ", variant_name(v),
                    mandible_defaults(v).*dim.field);
    }
    help += buf;
    if (same) break;
  }
  return help + ")";
}

}  // namespace

void add_generate_commands(CLI::App& app) {
  CLI::App* generate = app.add_subcommand("generate", "Generate built-in input geometry");
  generate->require_subcommand(1);
  CLI::App* cmd = generate->add_subcommand(
      "mandible", "The built-in CT-like adult mandible: surface (marching cubes), landmarks and CT volume");
  auto args = std::make_shared<GenerateArgs>();
  MandibleParameters& p = args->parameters;
  cmd->add_option("-o,--output", args->output, "Surface file to write (STL, OBJ, PLY, OFF, VTP)")
      ->required()
      ->check(output_surface_file());
  cmd->add_option("--landmarks", args->landmarks,
                  "Landmark and muscle file to write (YAML); default: OUTPUT's name with .landmarks.yaml")
      ->check(output_file({".yaml", ".yml"}));
  cmd->add_option("--ct", args->ct, "Also write the CT-like volume (.mha, .mhd, .nii, .nii.gz)")
      ->check(output_file({".mha", ".mhd", ".nii", ".nii.gz"}));
  cmd->add_option(
         "--dicom", args->dicom,
         "Also write the CT-like volume as a DICOM series into this folder (created if missing): one "
         "file per axial slice, ct_0001.dcm, ct_0002.dcm, ...; surface from-ct reads the folder")
      ->check(output_folder());
  cmd->add_option("--variant", args->variant, "dentate, edentulous or atrophic (resorbed, low body)");
  // One option per row of the generator's table of dimensions, its range and the variants' defaults
  // printed from that table, so that the help cannot drift from what the generator accepts.
  // The range is checked while parsing: an explicit 0 would otherwise read as "not given" and silently
  // become the default (complete_parameters).
  for (const MandibleDimension& dim : mandible_dimensions()) {
    char range[64];
    std::snprintf(range, sizeof range, "from %g to %g", dim.lo, dim.hi);
    cmd->add_option(std::string("--") + dim.option, p.*dim.field, dimension_help(dim))
        ->check(number_in_range(dim.lo, dim.hi, range));
  }
  cmd->callback([args] { run_generate(*args); });
}

}  // namespace hexbite
