// Small helpers on file names shared by the readers, writers and commands.
#pragma once

#include <string>

namespace hexbite {

// The extension of `path` in lower case, with its dot (".stl"), or empty.
std::string lower_extension(const std::string& path);

// True when `s` ends with `suffix` (case-sensitive), e.g. for double extensions like ".nii.gz".
bool ends_with(const std::string& s, const std::string& suffix);

// `path` in single quotes, the way error messages name files.
std::string quoted(const std::string& path);

}  // namespace hexbite
