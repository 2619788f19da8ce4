// Error types that map to the command line's exit codes: bad input or usage (2) and failed runs (1).
#pragma once

#include <stdexcept>
#include <string>

namespace hexbite {

// The user's input (a file, an option, a scenario) is wrong; the message says where and what to do.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The input was acceptable but the run could not finish (a solver diverged, a mesh stayed inverted).
class RunError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum ExitCode : int { kExitOk = 0, kExitRunFailed = 1, kExitBadInput = 2 };

}  // namespace hexbite
