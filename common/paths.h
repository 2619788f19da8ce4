// Small helpers on file names shared by the readers, writers and commands.
#pragma once

#include <cstddef>
#include <string>

namespace hexbite {

// The extension of `path` in lower case, with its dot (".stl"), or empty.
std::string lower_extension(const std::string& path);

// True when `s` ends with `suffix` (case-sensitive), e.g. for double extensions like ".nii.gz".
bool ends_with(const std::string& s, const std::string& suffix);

// `path` in single quotes, the way error messages name files.
std::string quoted(const std::string& path);

// The longest file name, in bytes, that the file system of the existing folder `dir` takes (255 on most,
// and 255 when it does not say).
std::size_t longest_name_in(const std::string& dir);

// Throws InputError unless `path` is a regular file (or a link to one), naming it as `what` ("surface
// file") and saying what it is instead: missing, a folder, a named pipe, a device. Every reader checks this
// before it opens the file: a named pipe or /dev/zero is read without end (the memory grows until the
// machine gives out), and a pipe read twice, as some readers do, looks like a damaged file.
void require_regular_file(const std::string& path, const std::string& what);

}  // namespace hexbite
