#include "app/option_checks.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>

#include <unistd.h>

#include "common/paths.h"
#include "common/text_check.h"

namespace hexbite {
namespace {

namespace fs = std::filesystem;

// 5000000 -> "5,000,000", as the option descriptions write counts.
std::string thousands(long n) {
  std::string digits = std::to_string(n);
  for (int i = static_cast<int>(digits.size()) - 3; i > 0; i -= 3)
    digits.insert(static_cast<std::size_t>(i), ",");
  return digits;
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

// ".vtu" or ".stl, .obj or .ply".
std::string listed(const std::vector<std::string>& extensions) {
  std::string text;
  for (std::size_t i = 0; i < extensions.size(); ++i)
    text += (i == 0 ? "" : i + 1 == extensions.size() ? " or " : ", ") + extensions[i];
  return text;
}

// Why `value` is not a finite number in [lo, hi] (ending in `give`, what to give instead), or empty with the
// number in `number`. NaN and infinities are out of range (CLI::Range lets NaN through).
std::string out_of_range(const std::string& value, double lo, double hi, const std::string& give,
                         double* number) {
  std::size_t used = 0;
  try {
    *number = std::stod(value, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  // std::stod reads hexadecimal too ("0x1"), which a count or a length written by a user never is.
  if (used == 0 || used != value.size() || value.find_first_of("xX") != std::string::npos)
    return value + " is not a number: " + give;
  if (!std::isfinite(*number) || *number < lo || *number > hi) return value + " is out of range: " + give;
  return {};
}

// Why no new entry can be made in the existing folder `dir` (a read-only file system, /proc), or empty when
// one can: a hidden folder is made there and at once removed, as the outputs' stages and temporary files
// are made there later.
std::string cannot_make_entries(const fs::path& dir) {
  std::string probe = (dir / ".hexbite-probe-XXXXXX").string();
  if (::mkdtemp(probe.data()) == nullptr) return std::strerror(errno);
  ::rmdir(probe.c_str());
  return {};
}

// Why a name of `path` below the existing folder `existing` is longer than that folder's file system allows
// (255 bytes on most), or empty: found only when the outputs are written, after the work, otherwise.
std::string name_too_long(const fs::path& existing, const fs::path& path) {
  const std::size_t most = longest_name_in(existing.string());
  for (const fs::path& part : path.lexically_relative(existing))
    if (part.string().size() > most)
      return "a name in it is " + std::to_string(part.string().size()) + " bytes long, more than the " +
             std::to_string(most) + " that its file system allows; give a shorter name";
  return {};
}

// Why `value` is longer than the system takes for a path (PATH_MAX, with its closing NUL), with the `added`
// bytes of names that hexbite puts in or beside it, or empty. The checks below would take such a path for a
// missing folder (every call on it fails), and a run found it only when it wrote its outputs, after the work.
std::string path_too_long(const std::string& value, std::size_t added) {
  if (value.size() + added < PATH_MAX) return {};
  const std::size_t shown = 60;
  return "the path '" + (value.size() > shown ? value.substr(0, shown) + "..." : value) + "' is " +
         thousands(long(value.size())) + " bytes long; with the " + std::to_string(added) +
         " bytes of the names hexbite writes in it, that is more than the " + thousands(PATH_MAX - 1) +
         " a path may have (PATH_MAX): give a shorter path";
}

// The deepest part of `path` that exists ("." when none does), or a link on it whose target does not exist
// (or a loop of links), which the caller names.
fs::path deepest_existing(fs::path path) {
  std::error_code ec;
  while (!fs::exists(path, ec)) {
    if (fs::is_symlink(fs::symlink_status(path, ec))) return path;
    path = path.parent_path();
    if (path.empty()) return ".";
  }
  return path;
}

// "'a.stl' is a file, not a folder; ": for a file where an output's path needs a folder.
std::string file_not_folder(const fs::path& file) {
  return "'" + file.string() + "' is a file, not a folder; ";
}

}  // namespace

CLI::Validator count_in_range(long lo, long hi) {
  const std::string range = "give a whole number from " + thousands(lo) + " to " + thousands(hi);
  return CLI::Validator(
      [lo, hi, range](std::string& value) -> std::string {
        double number = 0;
        const std::string error = out_of_range(value, double(lo), double(hi), range, &number);
        if (!error.empty()) return error;
        if (number != std::floor(number)) return value + " is not a whole number: " + range;
        value = std::to_string(static_cast<long>(number));
        return {};
      },
      "");
}

CLI::Validator number_in_range(double lo, double hi, const std::string& range) {
  const std::string give = "give a number " + range;
  return CLI::Validator(
      [lo, hi, give](std::string& value) -> std::string {
        double number = 0;
        return out_of_range(value, lo, hi, give, &number);
      },
      "");
}

CLI::Validator one_line_of_text(const std::string& what) {
  return CLI::Validator(
      [what](std::string& value) -> std::string {
        const std::string not_utf8 = utf8_problem(value);
        if (!not_utf8.empty())
          return what + " " + not_utf8 +
                 ": give it in UTF-8 (a terminal or script set to another encoding, such as Latin-1, sends "
                 "other bytes; `iconv -f latin1 -t utf-8` converts such text)";
        const std::string control = control_character_problem(value);
        if (!control.empty()) return what + " " + control + "; it is one line of printable text: remove it";
        return {};
      },
      "");
}

CLI::Validator output_file(std::vector<std::string> extensions) {
  return CLI::Validator(
      [extensions](std::string& value) -> std::string {
        // The temporary file beside the output: "." + name + ".tmp" + a process id.
        const std::string too_long = path_too_long(value, 16);
        if (!too_long.empty()) return "cannot write: " + too_long;
        const fs::path path(value);
        std::error_code ec;
        if (fs::is_directory(path, ec))
          return "'" + value + "' is a folder: give a file name in it, e.g. '" + (path / "out").string() +
                 extensions.front() + "'";
        const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
        if (!fs::is_directory(dir, ec)) {
          const fs::path existing = deepest_existing(dir);
          if (fs::exists(existing, ec) && !fs::is_directory(existing, ec))
            return "cannot write '" + value + "': " + file_not_folder(existing) +
                   "give a path in a folder (or a new folder, created first)";
          return "cannot write '" + value + "': folder '" + dir.string() +
                 "' does not exist; create it first";
        }
        const std::string name = lower(path.filename().string());
        for (const std::string& ext : extensions)
          if (name.size() > ext.size() && name.compare(name.size() - ext.size(), ext.size(), ext) == 0) {
            const std::string long_name = name_too_long(dir, path);
            if (!long_name.empty()) return "cannot write '" + value + "': " + long_name;
            // The file is written to a temporary name beside it first, so the folder must take new entries.
            const std::string refused = cannot_make_entries(dir);
            if (refused.empty()) return {};
            return "cannot write '" + value + "': no file can be made in '" + dir.string() + "' (" + refused +
                   "); give a path in a folder you can write to";
          }
        return "'" + value + "': this command writes " + listed(extensions) +
               "; give a file name ending in " +
               (extensions.size() == 1 ? extensions.front() : "one of them");
      },
      "");
}

CLI::Validator output_surface_file() {
  return output_file({".stl", ".obj", ".ply", ".off", ".vtp"});
}

CLI::Validator output_hex_mesh_file() {
  return output_file({".vtu", ".inp", ".msh"});
}

CLI::Validator output_folder() {
  return CLI::Validator(
      [](std::string& value) -> std::string {
        const std::string give = "give a folder for the outputs (it is created if missing)";
        if (value.empty()) return "the output folder is an empty name: " + give;
        // The stage folder (".hexbite-stage-XXXXXX") and the names of the files in it, the longest a study's
        // "<variant>/solution_level3.vtu".
        const std::string too_long = path_too_long(value, 64);
        if (!too_long.empty()) return "cannot create the output folder: " + too_long;
        std::error_code ec;
        if (fs::exists(value, ec) && !fs::is_directory(value, ec))
          return "'" + value + "' is a file, not a folder: " + give;
        // A missing folder is created after the work; a file where a folder of its path should be, or a
        // folder that takes no new entries (a read-only file system, /proc), would only be found then, so
        // the path's deepest existing part is looked at now.
        const fs::path existing = deepest_existing(value);
        // A dangling link (or a loop of links) on the path was found only when the folder was made, after
        // the whole run: "cannot create the output folder 'dl': File exists", exit 1.
        if (!fs::exists(existing, ec))
          return "cannot create the output folder '" + value + "': '" + existing.string() +
                 "' is a link to '" + fs::read_symlink(existing, ec).string() +
                 "', which does not exist or loops; remove the link, point it at a folder, or " + give;
        if (!fs::is_directory(existing, ec))
          return "cannot create the output folder '" + value + "': " + file_not_folder(existing) + give;
        const std::string long_name = name_too_long(existing, value);
        if (!long_name.empty()) return "cannot create the output folder '" + value + "': " + long_name;
        const std::string refused = cannot_make_entries(existing);
        if (refused.empty()) return {};
        return "cannot create the output folder '" + value + "': no folder can be made in '" +
               existing.string() + "' (" + refused + "); give a folder you can write to";
      },
      "");
}

void add_export_option(CLI::App& command, std::vector<std::string>& formats) {
  // A set of formats: a repeated --export (a script adding it to a command line that has it) is no error.
  command
      .add_option("--export", formats,
                  "Also write the model for another solver: inp (CalculiX); may be repeated")
      ->expected(1)
      ->allow_extra_args(false)  // one format per --export: `--export inp SCENARIO` is not two formats
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
      ->check(CLI::Validator(
          [](std::string& format) -> std::string {
            return format == "inp" ? std::string()
                                   : "unknown format '" + format +
                                         "': the one format is inp (CalculiX); the VTU files are written "
                                         "unless the scenario says outputs.vtu: false";
          },
          "inp"));
}

}  // namespace hexbite
