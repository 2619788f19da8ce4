// Helpers shared by the test suites: running the hexbite program, temporary folders, shared data.
#pragma once

#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

namespace hexbite::test {

struct CommandResult {
  int exit_code = -1;
  std::string out;  // stdout
  std::string err;  // stderr
};

// Runs the built hexbite program with the given arguments (no shell quoting needed), behind `launcher`
// (e.g. mpirun -np 2) when one is given.
CommandResult run_hexbite(const std::vector<std::string>& args,
                          const std::vector<std::string>& launcher = {});

// A fresh, empty temporary folder per call, removed at process exit.
std::string temp_dir();

// Path of a file under ../shared/data; fails the current test if it is missing.
std::string shared_data(const std::string& relative);

// Reads or writes a whole file.
std::string read_file(const std::string& path);
void write_file(const std::string& path, const std::string& contents);

// Everything under `dir`: relative name -> the file's bytes, or "<folder>" for a folder.
std::map<std::string, std::string> files_under(const std::string& dir);

// Test failures naming every file added, removed or changed between two files_under() of one folder
// (without printing the contents, which may be megabytes).
void expect_same_files(const std::map<std::string, std::string>& before,
                       const std::map<std::string, std::string>& after);

// Separate 20 mm cubes (x 0-20, 40-60, ...) as OBJ text, outward triangles.
std::string cubes_obj(int cubes);

// While it lives, files this process writes may not grow beyond `bytes` (setrlimit RLIMIT_FSIZE, with
// SIGXFSZ ignored as hexbite's main does): a write past it fails as on a full disk.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(unsigned long long bytes);
  ~FileSizeLimit();
  FileSizeLimit(const FileSizeLimit&) = delete;
  FileSizeLimit& operator=(const FileSizeLimit&) = delete;

 private:
  unsigned long long soft_ = 0;
};

// An X server of its own (Xvfb) on a free display number (Xvfb -displayfd picks it), started with
// `options` (e.g. {"-extension", "GLX"}) and stopped when this ends. display() is ":N", or empty when none
// could be started, and problem() then says why (no Xvfb installed, or it stopped at once).
class VirtualDisplay {
 public:
  explicit VirtualDisplay(const std::vector<std::string>& options);
  ~VirtualDisplay();
  VirtualDisplay(const VirtualDisplay&) = delete;
  VirtualDisplay& operator=(const VirtualDisplay&) = delete;
  const std::string& display() const { return display_; }
  const std::string& problem() const { return problem_; }

 private:
  int pid_ = -1;
  std::string display_, problem_;
};

// The message of the exception of type E that f() throws; a test failure, and "", when it throws none.
template <class E, class F>
std::string message_of(F f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected an exception";
  return "";
}

}  // namespace hexbite::test
