// How much memory this process may use: the machine's physical memory, or less when a control group (a
// container's, a batch job's or a systemd unit's memory limit) or an address-space limit (ulimit -v) caps
// it. `hexbite run` refuses validation
// levels that would need more (app/run_pipeline.cc).
#pragma once

#include <string>

namespace hexbite {

// Where the kernel says which cgroups this process is in, one "hierarchy:controllers:/path" line each.
inline constexpr const char* kProcSelfCgroup = "/proc/self/cgroup";

struct MemoryLimit {
  double bytes = 0;  // 0: not known
  // What sets `bytes`: "this machine's physical memory", or "the cgroup memory limit in <file>".
  std::string source;
};

// The smaller of `physical_bytes` (0 or less: not known) and the memory limits of the cgroups of a process
// whose /proc/self/cgroup reads `proc_self_cgroup`, with the cgroup file systems mounted under `root` ("" for
// this machine's /): cgroup v2's memory.max (in root/sys/fs/cgroup/<path>) and cgroup v1's
// memory.limit_in_bytes (in root/sys/fs/cgroup/memory/<path>) of the process's own cgroup, of each of its
// ancestors, and of the root cgroup (the only one a container that mounts its own cgroup as the root sees).
// A file that is missing, unreadable, "max", not a whole number, or 2^62 bytes or more (cgroup v1's "no
// limit") sets none. The root and the text are parameters so that tests can give their own.
MemoryLimit available_memory(double physical_bytes, const std::string& root,
                             const std::string& proc_self_cgroup);

// `limit`, or less when an address-space limit (ulimit -v, RLIMIT_AS, as batch schedulers set it) of
// `address_space_bytes` (0 or less: none) leaves less than that beyond the `mapped_bytes` the process
// already maps (its libraries and thread stacks: about 1 GB for `hexbite run`, of which a quarter is
// resident, so the limit binds long before the machine's memory does).
MemoryLimit with_address_space_limit(MemoryLimit limit, double address_space_bytes, double mapped_bytes);

// available_memory() of this machine (sysconf's physical pages times the page size), its cgroup file
// systems and its kProcSelfCgroup, with_address_space_limit() of this process's RLIMIT_AS and its mapped
// size (/proc/self/statm).
MemoryLimit machine_memory();

}  // namespace hexbite
