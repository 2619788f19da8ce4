// JSON documents as text, for files and --json output.
#pragma once

#include <string>

namespace hexbite {

// `j` indented by 2, with bytes that are not UTF-8 (a file name in Latin-1, as Linux allows) written as
// U+FFFD: nlohmann's dump() throws on them by default, which failed a `--json` command after its output
// file was written (exit 1, "[json.exception.type_error.316] invalid UTF-8 byte").
template <class Json>
std::string json_text(const Json& j) {
  return j.dump(2, ' ', false, Json::error_handler_t::replace);
}

}  // namespace hexbite
