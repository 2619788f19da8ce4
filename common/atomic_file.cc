#include "common/atomic_file.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "common/error.h"
#include "common/paths.h"

namespace hexbite {

namespace fs = std::filesystem;

void write_atomically(const std::string& final_path, const std::function<void(const std::string&)>& write) {
  const fs::path target(final_path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  if (!fs::is_directory(dir))
    throw InputError("cannot write '" + final_path + "': directory '" + dir.string() +
                     "' does not exist; create it first");
  const std::string tmp = temporary_path_beside(final_path, target.extension().string());
  try {
    write(tmp);
  } catch (...) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw;
  }
  std::error_code ec;
  fs::rename(tmp, target, ec);
  if (ec) {
    std::error_code ignored;  // not ec: a remove that finds nothing clears it ("cannot write ...: Success")
    fs::remove(tmp, ignored);
    throw RunError("cannot write '" + final_path + "': " + ec.message());
  }
}

std::string temporary_path_beside(const std::string& final_path, const std::string& extension) {
  const fs::path target(final_path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  const std::string name = target.filename().string();
  std::string stem = name.substr(0, name.size() - std::min(name.size(), extension.size()));
  const std::string tag = ".tmp" + std::to_string(::getpid());
  const std::size_t most = longest_name_in(dir.string());
  const std::size_t added = 1 + tag.size() + extension.size();
  if (stem.size() + added > most) stem.resize(most > added ? most - added : 0);
  return (dir / ("." + stem + tag + extension)).string();
}

void write_file_atomically(const std::string& final_path, const std::string& contents) {
  write_atomically(final_path, [&](const std::string& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    if (!out)
      throw RunError("cannot write '" + final_path + "': " + std::strerror(errno) + " (creating '" + tmp +
                     "' beside it to write into first)");
    out.write(contents.data(), static_cast<std::streamsize>(contents.size()));
    out.close();
    if (!out) throw RunError("cannot write '" + final_path + "': " + kWriteFailed + ": " + kWriteAdvice);
  });
}

}  // namespace hexbite
