#include "common/progress.h"

#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <exception>
#include <iostream>
#include <string>

namespace hexbite {

namespace {
bool g_quiet = false;
bool g_json = false;
thread_local bool t_quiet = false;
}  // namespace

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void set_quiet(bool quiet) {
  g_quiet = quiet;
}
bool is_quiet() {
  return g_quiet || t_quiet;
}

QuietThread::QuietThread(bool quiet) : before_(t_quiet) {
  t_quiet = t_quiet || quiet;
}

QuietThread::~QuietThread() {
  t_quiet = before_;
}

void set_json_output(bool json) {
  g_json = json;
}

void info(const std::string& line) {
  if (is_quiet()) return;
  // Flushed: into a file or a pipe, a study's "check variant ..." lines waited in the buffer until the end
  // of the command, and a kill (a batch system's time limit) lost them.
  (g_json ? std::cerr : std::cout) << line << '\n' << std::flush;
}

Progress::Progress(std::string label)
    : label_(std::move(label)),
      active_(!is_quiet() && ::isatty(STDERR_FILENO)),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_) {
  if (active_) draw(0.0, "", false);
}

// A step that ends in an exception did not complete: its bar is wiped rather than drawn at 100 % just
// above the error.
Progress::~Progress() {
  if (finished_) return;
  if (std::uncaught_exceptions() == 0) {
    finish();
    return;
  }
  finished_ = true;
  if (active_) {
    std::fputs("\r\033[K", stderr);
    std::fflush(stderr);
  }
}

double Progress::seconds() const {
  return seconds_since(start_);
}

void Progress::update(double fraction, const std::string& note) {
  if (!active_) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - last_draw_ < std::chrono::milliseconds(100)) return;
  last_draw_ = now;
  draw(fraction, note, false);
}

void Progress::finish(const std::string& note) {
  if (finished_) return;
  finished_ = true;
  if (active_) draw(1.0, note, true);
}

void Progress::draw(double fraction, const std::string& note, bool final_line) {
  constexpr int kWidth = 24;
  fraction = std::clamp(fraction, 0.0, 1.0);
  const int filled = static_cast<int>(fraction * kWidth + 0.5);
  std::string bar(filled, '#');
  bar.append(kWidth - filled, ' ');
  char text[512];
  std::snprintf(text, sizeof text, "%-28s [%s] %3d%%  %6.1f s  %s", label_.c_str(), bar.c_str(),
                static_cast<int>(fraction * 100 + 0.5), seconds(), note.c_str());
  std::string line = text;
  // A line that is redrawn must fit the terminal: one that wraps is cleared only in its last row by
  // "\r\033[K", and on a narrow terminal every redraw left a row behind (helper K, 50 columns).
  winsize size{};
  if (!final_line && ::ioctl(STDERR_FILENO, TIOCGWINSZ, &size) == 0 && size.ws_col > 1 &&
      line.size() >= size.ws_col)
    line.resize(size.ws_col - 1);
  std::fprintf(stderr, "\r\033[K%s%s", line.c_str(), final_line ? "\n" : "");
  std::fflush(stderr);
}

}  // namespace hexbite
