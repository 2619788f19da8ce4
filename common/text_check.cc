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
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
      return "holds a control character (" + byte_code(c) + (c == '\n' ? ", a line break" : "") + ")";
    // The C1 controls U+0080-U+009F (UTF-8 C2 80-C2 9F: U+0085 is a line break, U+009B acts on a terminal
    // as ESC [ does) and the Unicode line and paragraph separators passed (helper AA).
    const std::string rest = text.substr(i, 3);
    const auto second = rest.size() > 1 ? static_cast<unsigned char>(rest[1]) : 0u;
    if (static_cast<unsigned char>(c) == 0xC2 && second >= 0x80 && second <= 0x9F) {
      char code[8];
      std::snprintf(code, sizeof code, "U+%04X", second);
      return std::string("holds a control character (") + code + (second == 0x85 ? ", a line break" : "") +
             ")";
    }
    if (rest == "\u2028" || rest == "\u2029")
      return std::string("holds a Unicode ") + (rest == "\u2028" ? "line" : "paragraph") + " separator (U+" +
             (rest == "\u2028" ? "2028" : "2029") + ")";
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
