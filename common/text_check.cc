#include "common/text_check.h"

#include <utf8cpp/utf8.h>

#include <cstdio>

#include "common/error.h"

namespace hexbite {

namespace {

std::string byte_code(char c) {
  char code[8];
  std::snprintf(code, sizeof code, "0x%02X", static_cast<unsigned>(static_cast<unsigned char>(c)));
  return code;
}

}  // namespace

std::string control_character_problem(const std::string& text) {
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
      return "holds a control character (" + byte_code(c) + (c == '\n' ? ", a line break" : "") + ")";
    // The C1 controls and the Unicode line and paragraph separators passed (helper AA).
    if (const unsigned c1 = c1_control_at(text, i)) {
      char code[8];
      std::snprintf(code, sizeof code, "U+%04X", c1);
      return std::string("holds a control character (") + code + (c1 == 0x85 ? ", a line break" : "") + ")";
    }
    if (text.compare(i, 3, "\u2028") == 0) return "holds a Unicode line separator (U+2028)";
    if (text.compare(i, 3, "\u2029") == 0) return "holds a Unicode paragraph separator (U+2029)";
  }
  return {};
}

std::string utf8_problem(const std::string& text) {
  const auto invalid = utf8::find_invalid(text.begin(), text.end());
  if (invalid == text.end()) return {};
  return "is not valid UTF-8 (byte " + byte_code(*invalid) + " at position " +
         std::to_string(invalid - text.begin() + 1) + ")";
}

}  // namespace hexbite
