// Checks of user text that goes into the heading lines of the files written (names, titles): one line of
// printable UTF-8.
#pragma once

#include <string>

namespace hexbite {

// What keeps `text` from being one line of printable text, for a message after the text's name: "holds a
// control character (0x0A, a line break)" for a byte below 0x20 or 0x7F, or a C1 control character
// (U+0080-U+009F) or a Unicode line or paragraph separator in UTF-8; empty when there is none.
std::string control_character_problem(const std::string& text);

// What keeps `text` from being UTF-8, for a message after the text's name: "is not valid UTF-8 (byte 0xE9
// at position 2)"; empty when it is UTF-8.
std::string utf8_problem(const std::string& text);

}  // namespace hexbite
