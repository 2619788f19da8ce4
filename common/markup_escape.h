// Text safe inside HTML and XML: the reports' HTML and the attribute values of the .vtu and .pvtu files.
#pragma once

#include <string>

namespace hexbite {

// `text` safe inside HTML or XML elements and attribute values: & < > " ' as character references.
std::string markup_escape(const std::string& text);

}  // namespace hexbite
