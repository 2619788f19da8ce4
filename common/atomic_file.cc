#include "common/atomic_file.h"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "common/error.h"

namespace hexbite {

namespace fs = std::filesystem;

void write_atomically(const std::string& final_path, const std::function<void(const std::string&)>& write) {
  const fs::path target(final_path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  if (!fs::is_directory(dir))
    throw InputError("cannot write '" + final_path + "': directory '" + dir.string() +
                     "' does not exist; create it first");
  // The temporary keeps the final extension: some writers (VTK) choose the format from it.
  const std::string tmp = (dir / ("." + target.stem().string() + ".tmp" + std::to_string(::getpid()) +
                                  target.extension().string()))
                              .string();
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

void write_file_atomically(const std::string& final_path, const std::string& contents) {
  write_atomically(final_path, [&](const std::string& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    if (!out)
      throw RunError("cannot write '" + final_path + "': " + std::strerror(errno) + " (creating '" + tmp +
                     "' beside it to write into first)");
    out.write(contents.data(), static_cast<std::streamsize>(contents.size()));
    out.close();
    if (!out) throw RunError("cannot write '" + final_path + "': disk full or not writable");
  });
}

}  // namespace hexbite
