// Small pieces of self-contained HTML: embedded pictures (escaped text: common/markup_escape.h).
#pragma once

#include <string>

namespace hexbite {

// `bytes` in base64 (RFC 4648, with padding), e.g. for a data: URI.
std::string base64(const std::string& bytes);

}  // namespace hexbite
