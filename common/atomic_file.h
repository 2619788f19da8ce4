// Writing outputs so that a failed run never leaves a half-written file behind.
#pragma once

#include <functional>
#include <string>

namespace hexbite {

// Calls write(tmp_path) with a temporary name next to final_path and renames it to final_path
// when write returns; removes the temporary file if write throws. The directory must exist.
void write_atomically(const std::string& final_path, const std::function<void(const std::string&)>& write);

// Convenience: writes a whole text or binary string atomically.
void write_file_atomically(const std::string& final_path, const std::string& contents);

}  // namespace hexbite
