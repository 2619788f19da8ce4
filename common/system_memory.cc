#include "common/system_memory.h"

#include <unistd.h>

#include <cctype>
#include <fstream>

namespace hexbite {

namespace {

// The limit in a cgroup file in bytes, or 0 for none.
double cgroup_limit(const std::string& path) {
  std::ifstream in(path);
  if (!in) return 0;
  std::string text;
  if (!std::getline(in, text)) return 0;
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back()))) text.pop_back();
  if (text.empty() || text.size() > 20) return 0;
  for (char c : text)
    if (!std::isdigit(static_cast<unsigned char>(c))) return 0;  // also "max"
  const double bytes = std::stod(text);
  // cgroup v1 says "no limit" with the largest page-aligned 64-bit value (9223372036854771712).
  constexpr double kNoLimit = 4611686018427387904.0;  // 2^62
  return bytes > 0 && bytes < kNoLimit ? bytes : 0;
}

}  // namespace

MemoryLimit available_memory(double physical_bytes, const std::string& cgroup_v2_max,
                             const std::string& cgroup_v1_limit) {
  MemoryLimit limit;
  if (physical_bytes > 0) limit = {physical_bytes, "this machine's physical memory"};
  for (const std::string& path : {cgroup_v2_max, cgroup_v1_limit}) {
    const double bytes = cgroup_limit(path);
    if (bytes > 0 && (limit.bytes <= 0 || bytes < limit.bytes))
      limit = {bytes, "the cgroup memory limit in " + path};
  }
  return limit;
}

MemoryLimit machine_memory() {
  const long pages = sysconf(_SC_PHYS_PAGES), page_size = sysconf(_SC_PAGESIZE);
  const double physical =
      pages > 0 && page_size > 0 ? static_cast<double>(pages) * static_cast<double>(page_size) : 0;
  return available_memory(physical);
}

}  // namespace hexbite
