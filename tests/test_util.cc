#include "tests/test_util.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace hexbite::test {

namespace fs = std::filesystem;

namespace {

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) {
    if (c == '\'')
      q += "'\\''";
    else
      q += c;
  }
  return q + "'";
}

struct TempRoot {
  fs::path path;
  TempRoot() {
    std::string templ = (fs::temp_directory_path() / "hexbite-test-XXXXXX").string();
    path = ::mkdtemp(templ.data());
  }
  ~TempRoot() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

}  // namespace

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void write_file(const std::string& path, const std::string& contents) {
  std::ofstream out(path, std::ios::binary);
  out << contents;
}

std::string temp_dir() {
  static TempRoot root;
  static int counter = 0;
  fs::path dir = root.path / std::to_string(counter++);
  fs::create_directories(dir);
  return dir.string();
}

VirtualDisplay::VirtualDisplay(const std::vector<std::string>& options) {
  int ready[2];
  if (::pipe(ready) != 0) {
    problem_ = "no pipe for Xvfb";
    return;
  }
  std::vector<std::string> args = {"Xvfb", "-displayfd", std::to_string(ready[1]), "-nolisten", "tcp"};
  args.insert(args.end(), options.begin(), options.end());
  pid_ = ::fork();
  if (pid_ == 0) {
    ::close(ready[0]);
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, 1);
    ::dup2(null, 2);
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execvp(argv[0], argv.data());
    ::_exit(127);
  }
  ::close(ready[1]);
  // Xvfb writes the display number when it is ready; the pipe ends without one when it stops (or is missing).
  std::string number;
  char c = 0;
  while (pid_ > 0 && ::read(ready[0], &c, 1) == 1 && c != '\n') number += c;
  ::close(ready[0]);
  if (!number.empty()) {
    display_ = ":" + number;
    return;
  }
  int status = 0;
  if (pid_ > 0) ::waitpid(pid_, &status, 0);
  pid_ = -1;
  problem_ = WIFEXITED(status) && WEXITSTATUS(status) == 127 ? "Xvfb is not installed"
                                                             : "Xvfb stopped without opening a display";
}

VirtualDisplay::~VirtualDisplay() {
  if (pid_ <= 0) return;
  ::kill(pid_, SIGTERM);
  ::waitpid(pid_, nullptr, 0);
}

CommandResult run_hexbite(const std::vector<std::string>& args, const std::vector<std::string>& launcher) {
  const std::string dir = temp_dir();
  const std::string out_file = dir + "/stdout", err_file = dir + "/stderr";
  std::string cmd;
  for (const auto& a : launcher) cmd += shell_quote(a) + " ";
  cmd += shell_quote(HEXBITE_EXE);
  for (const auto& a : args) cmd += " " + shell_quote(a);
  cmd += " >" + shell_quote(out_file) + " 2>" + shell_quote(err_file) + " </dev/null";
  const int status = std::system(cmd.c_str());
  CommandResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = read_file(out_file);
  r.err = read_file(err_file);
  return r;
}

std::string shared_data(const std::string& relative) {
  const std::string path = std::string(HEXBITE_SHARED_DATA) + "/" + relative;
  if (!fs::exists(path)) ADD_FAILURE() << "shared test data missing: " << path;
  return path;
}

std::map<std::string, std::string> files_under(const std::string& dir) {
  std::map<std::string, std::string> files;
  for (const fs::directory_entry& e : fs::recursive_directory_iterator(dir)) {
    const std::string name = fs::relative(e.path(), dir).string();
    files[name] = e.is_directory() ? "<folder>" : read_file(e.path().string());
  }
  return files;
}

void expect_same_files(const std::map<std::string, std::string>& before,
                       const std::map<std::string, std::string>& after) {
  for (const auto& [name, contents] : before) {
    const auto it = after.find(name);
    if (it == after.end())
      ADD_FAILURE() << name << " is gone";
    else if (it->second != contents)
      ADD_FAILURE() << name << " changed";
  }
  for (const auto& [name, contents] : after)
    if (before.count(name) == 0) ADD_FAILURE() << name << " is new";
}

FileSizeLimit::FileSizeLimit(unsigned long long bytes) {
  std::signal(SIGXFSZ, SIG_IGN);
  rlimit limit{};
  getrlimit(RLIMIT_FSIZE, &limit);
  soft_ = limit.rlim_cur;
  limit.rlim_cur = bytes;
  setrlimit(RLIMIT_FSIZE, &limit);
}

FileSizeLimit::~FileSizeLimit() {
  rlimit limit{};
  getrlimit(RLIMIT_FSIZE, &limit);
  limit.rlim_cur = soft_;
  setrlimit(RLIMIT_FSIZE, &limit);
}

std::string cubes_obj(int cubes) {
  std::string text;
  const int faces[12][3] = {{1, 3, 4}, {1, 4, 2}, {5, 6, 8}, {5, 8, 7}, {1, 2, 6}, {1, 6, 5},
                            {3, 7, 8}, {3, 8, 4}, {1, 5, 7}, {1, 7, 3}, {2, 4, 8}, {2, 8, 6}};
  for (int cube = 0; cube < cubes; ++cube) {
    for (int v = 0; v < 8; ++v)
      text += "v " + std::to_string(40 * cube + 20 * (v & 1)) + " " + std::to_string(20 * ((v >> 1) & 1)) +
              " " + std::to_string(20 * ((v >> 2) & 1)) + "\n";
    for (const auto& f : faces)
      text += "f " + std::to_string(f[0] + 8 * cube) + " " + std::to_string(f[1] + 8 * cube) + " " +
              std::to_string(f[2] + 8 * cube) + "\n";
  }
  return text;
}

}  // namespace hexbite::test
