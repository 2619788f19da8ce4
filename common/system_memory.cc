#include "common/system_memory.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <vector>

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

// Whether the comma-separated `controllers` of a /proc/self/cgroup line name the memory controller.
bool names_memory(const std::string& controllers) {
  std::istringstream in(controllers);
  for (std::string controller; std::getline(in, controller, ',');)
    if (controller == "memory") return true;
  return false;
}

// The memory-limit files `file` of the cgroup at `path` ("/a/b", from /proc/self/cgroup) under the hierarchy
// mounted at `mount`, and of each of its ancestors but the root cgroup ("/a"); none for a path that is not
// absolute.
void add_limit_files(const std::string& mount, std::string path, const std::string& file,
                     std::vector<std::string>& files) {
  if (path.empty() || path.front() != '/') return;
  while (!path.empty() && path.back() == '/') path.pop_back();
  for (; !path.empty(); path.erase(path.rfind('/'))) files.push_back(mount + path + "/" + file);
}

// The memory-limit files that apply to a process whose /proc/self/cgroup reads `proc_self_cgroup`: the
// process's own cgroup's and its ancestors' for cgroup v2 ("0::/path") and for the cgroup v1 hierarchy with
// the memory controller ("N:memory:/path" or "N:cpu,memory:/path"), then the root cgroups', whatever the
// text.
std::vector<std::string> limit_files(const std::string& root, const std::string& proc_self_cgroup) {
  const std::string v2_mount = root + "/sys/fs/cgroup", v1_mount = root + "/sys/fs/cgroup/memory";
  std::vector<std::string> files;
  std::istringstream lines(proc_self_cgroup);
  for (std::string line; std::getline(lines, line);) {
    const std::size_t first = line.find(':'), second = line.find(':', first + 1);
    if (first == std::string::npos || second == std::string::npos) continue;
    const std::string hierarchy = line.substr(0, first),
                      controllers = line.substr(first + 1, second - first - 1),
                      path = line.substr(second + 1);
    if (hierarchy == "0" && controllers.empty()) add_limit_files(v2_mount, path, "memory.max", files);
    if (names_memory(controllers)) add_limit_files(v1_mount, path, "memory.limit_in_bytes", files);
  }
  files.push_back(v2_mount + "/memory.max");
  files.push_back(v1_mount + "/memory.limit_in_bytes");
  return files;
}

}  // namespace

MemoryLimit available_memory(double physical_bytes, const std::string& root,
                             const std::string& proc_self_cgroup) {
  MemoryLimit limit;
  if (physical_bytes > 0) limit = {physical_bytes, "this machine's physical memory"};
  for (const std::string& path : limit_files(root, proc_self_cgroup)) {
    const double bytes = cgroup_limit(path);
    if (bytes > 0 && (limit.bytes <= 0 || bytes < limit.bytes))
      limit = {bytes, "the cgroup memory limit in " + path};
  }
  return limit;
}

MemoryLimit with_address_space_limit(MemoryLimit limit, double address_space_bytes, double mapped_bytes) {
  if (address_space_bytes <= 0) return limit;
  const double left = std::max(address_space_bytes - std::max(mapped_bytes, 0.0), 1.0);  // 0 is "not known"
  if (limit.bytes > 0 && left >= limit.bytes) return limit;
  char text[200];
  std::snprintf(text, sizeof text,
                "the address space left under this process's limit (ulimit -v: %.3g GB, of which it already "
                "maps %.3g GB)",
                address_space_bytes / 1e9, mapped_bytes / 1e9);
  return {left, text};
}

MemoryLimit machine_memory() {
  const long pages = sysconf(_SC_PHYS_PAGES), page_size = sysconf(_SC_PAGESIZE);
  const double physical =
      pages > 0 && page_size > 0 ? static_cast<double>(pages) * static_cast<double>(page_size) : 0;
  std::ifstream in(kProcSelfCgroup);
  std::ostringstream text;
  text << in.rdbuf();
  const MemoryLimit limit = available_memory(physical, "", text.str());
  rlimit address_space{};
  if (getrlimit(RLIMIT_AS, &address_space) != 0 || address_space.rlim_cur == RLIM_INFINITY) return limit;
  double mapped_pages = 0;  // the first number of /proc/self/statm: the mapped size in pages
  std::ifstream statm("/proc/self/statm");
  statm >> mapped_pages;
  return with_address_space_limit(limit, static_cast<double>(address_space.rlim_cur),
                                  mapped_pages * static_cast<double>(page_size));
}

}  // namespace hexbite
