// Progress display for long steps: a self-updating line on a terminal, nothing when quiet or piped.
#pragma once

#include <chrono>
#include <string>

namespace hexbite {

// Wall seconds elapsed since t0 (steady clock): the stage timings that reports carry.
double seconds_since(std::chrono::steady_clock::time_point t0);

// Global verbosity of the command line program; set once from --quiet.
void set_quiet(bool quiet);
// Whether output is off: set_quiet(true), or inside a QuietThread on this thread.
bool is_quiet();

// While it lives, info() and Progress on the constructing thread print nothing when `quiet` (helper threads
// of a computation whose calling thread shows the progress).
class QuietThread {
 public:
  explicit QuietThread(bool quiet);
  ~QuietThread();
  QuietThread(const QuietThread&) = delete;
  QuietThread& operator=(const QuietThread&) = delete;

 private:
  bool before_;
};

// Set once from the command line when the command prints a JSON document (--json): standard output then
// carries that document alone, and info() lines go to standard error.
void set_json_output(bool json);

// Prints an informational line unless quiet: to stdout, or to stderr under set_json_output(true); flushed at
// once, so that a file or a pipe has it while the command works.
void info(const std::string& line);

// A progress bar for one named step. On a terminal (stderr is a TTY) it redraws
// "label  [#####     ]  45%  3.2 s" at most every 0.1 s; otherwise it stays silent.
// finish() (or the destructor) prints the step's total time on a terminal.
class Progress {
 public:
  explicit Progress(std::string label);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  // fraction in [0, 1]; an optional short note (e.g. "pass 3") is shown after the bar.
  void update(double fraction, const std::string& note = "");
  void finish(const std::string& note = "");
  double seconds() const;

 private:
  void draw(double fraction, const std::string& note, bool final_line);

  std::string label_;
  bool active_;
  bool finished_ = false;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
};

}  // namespace hexbite
