// Small pieces of self-contained HTML: escaped text and embedded pictures.
#pragma once

#include <string>

namespace hexbite {

// `text` safe inside HTML elements and attribute values: & < > " ' as character references.
std::string html_escape(const std::string& text);

// `bytes` in base64 (RFC 4648, with padding), e.g. for a data: URI.
std::string base64(const std::string& bytes);

}  // namespace hexbite
