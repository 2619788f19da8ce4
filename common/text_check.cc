#include "common/text_check.h"

#include <utf8cpp/utf8.h>

#include <cstdio>

namespace hexbite {

namespace {

std::string byte_code(char c) {
  char code[8];
  std::snprintf(code, sizeof code, "0x%02X", static_cast<unsigned>(static_cast<unsigned char>(c)));
  return code;
}

}  // namespace

std::string control_character_problem(const std::string& text) {
  for (const char c : text)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
      return "holds a control character (" + byte_code(c) + (c == '\n' ? ", a line break" : "") + ")";
  return {};
}

std::string utf8_problem(const std::string& text) {
  const auto invalid = utf8::find_invalid(text.begin(), text.end());
  if (invalid == text.end()) return {};
  return "is not valid UTF-8 (byte " + byte_code(*invalid) + " at position " +
         std::to_string(invalid - text.begin() + 1) + ")";
}

}  // namespace hexbite
