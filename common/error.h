// Error types that map to the command line's exit codes: bad input or usage (2) and failed runs (1).
#pragma once

#include <cstdio>
#include <stdexcept>
#include <string>

namespace hexbite {

// The C1 control character (U+0080-U+009F: U+0085 is a line break, U+009B acts on a terminal as ESC [
// does) whose UTF-8 form (C2 80-C2 9F) starts at text[i], or 0 when none does.
inline unsigned c1_control_at(const std::string& text, std::size_t i) {
  if (i + 1 >= text.size() || static_cast<unsigned char>(text[i]) != 0xC2) return 0;
  const auto second = static_cast<unsigned char>(text[i + 1]);
  return second >= 0x80 && second <= 0x9F ? second : 0;
}

// The message with control bytes other than line breaks and tabs written as \xNN, and the C1 control
// characters of UTF-8 as \u00NN. Messages quote lines and names from the user's files, and a NUL byte in
// one (binary bytes in a text file) cut the message there: what() is a C string, so the file's line and
// the advice after it were lost.
inline std::string printable_message(const std::string& message) {
  std::string out;
  out.reserve(message.size());
  for (std::size_t i = 0; i < message.size(); ++i) {
    const char c = message[i];
    const auto byte = static_cast<unsigned char>(c);
    if (const unsigned c1 = c1_control_at(message, i)) {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\u%04x", c1);
      out += escaped;
      ++i;
    } else if (byte >= 0x20 && byte != 0x7f) {
      out += c;
    } else if (c == '\n' || c == '\t') {
      out += c;
    } else {
      char escaped[5];
      std::snprintf(escaped, sizeof escaped, "\\x%02x", byte);
      out += escaped;
    }
  }
  return out;
}

// The user's input (a file, an option, a scenario) is wrong; the message says where and what to do.
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(printable_message(message)) {}
};

// The input was acceptable but the run could not finish (a solver diverged, a mesh stayed inverted).
class RunError : public std::runtime_error {
 public:
  explicit RunError(const std::string& message) : std::runtime_error(printable_message(message)) {}
};

enum ExitCode : int { kExitOk = 0, kExitRunFailed = 1, kExitBadInput = 2 };

}  // namespace hexbite
