// How much memory this process may use: the machine's physical memory, or less when a control group (a
// container's or a batch job's memory limit) caps it. `hexbite run` refuses validation levels that would
// need more (app/run_pipeline.cc).
#pragma once

#include <string>

namespace hexbite {

// The cgroup v2 limit ("max" for none) and the cgroup v1 limit (a huge number, about 2^63, for none), as
// mounted in a container.
inline constexpr const char* kCgroupV2MemoryMax = "/sys/fs/cgroup/memory.max";
inline constexpr const char* kCgroupV1MemoryLimit = "/sys/fs/cgroup/memory/memory.limit_in_bytes";

struct MemoryLimit {
  double bytes = 0;  // 0: not known
  // What sets `bytes`: "this machine's physical memory", or "the cgroup memory limit in <file>".
  std::string source;
};

// The smaller of `physical_bytes` (0 or less: not known) and the limits in the cgroup files; a file that is
// missing, unreadable, "max", not a whole number, or 2^62 bytes or more (cgroup v1's "no limit") sets none.
// The paths are parameters so that tests can give their own files.
MemoryLimit available_memory(double physical_bytes, const std::string& cgroup_v2_max = kCgroupV2MemoryMax,
                             const std::string& cgroup_v1_limit = kCgroupV1MemoryLimit);

// available_memory() of this machine (sysconf's physical pages times the page size) and its cgroup files.
MemoryLimit machine_memory();

}  // namespace hexbite
