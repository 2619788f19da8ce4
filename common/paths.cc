#include "common/paths.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <system_error>

#include "common/error.h"

namespace hexbite {

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::string quoted(const std::string& path) {
  return "'" + path + "'";
}

std::size_t longest_name_in(const std::string& dir) {
  const long limit = ::pathconf(dir.c_str(), _PC_NAME_MAX);
  return limit > 0 ? static_cast<std::size_t>(limit) : 255;
}

void require_regular_file(const std::string& path, const std::string& what) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  const std::string named = what + " " + quoted(path);
  switch (status.type()) {
    case fs::file_type::regular:
      return;
    case fs::file_type::not_found:
      throw InputError(named + " does not exist: check the path and the spelling");
    case fs::file_type::directory:
      throw InputError(named + " is a folder, not a file: give a file");
    case fs::file_type::fifo:
      throw InputError(named + " is a named pipe (a FIFO, or a shell's <(...)), not a regular file: save " +
                       "its contents to a file and give that");
    case fs::file_type::character:
    case fs::file_type::block:
      throw InputError(named + " is a device, not a regular file: give a file");
    case fs::file_type::socket:
      throw InputError(named + " is a socket, not a regular file: give a file");
    default:
      // A path too long, or a folder on it that cannot be searched: the system's reason.
      throw InputError("cannot read " + named + ": " + (ec ? ec.message() : "not a regular file") +
                       "; give a regular file");
  }
}

}  // namespace hexbite
