#include "common/atomic_file.h"

#include <dirent.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "common/error.h"
#include "common/paths.h"

namespace hexbite {

namespace fs = std::filesystem;

namespace {

// The temporary files being written, for the signal handler: fixed slots, since a handler may only call
// async-signal-safe functions (unlink, signal, raise) and read lock-free atomics. A path longer than a slot
// is not registered (it is then left behind on a signal, as before).
constexpr int kSlots = 32;
constexpr std::size_t kSlotBytes = 4096;
char g_paths[kSlots][kSlotBytes];
std::atomic<int> g_state[kSlots];  // 0 free, 1 being filled, then 2 + RemovedOnSignal::Kind

// Whether signals act now (kRunning), wait for the end of a SignalsDeferred (kDeferring, the waiting one in
// g_pending), or one is ending the process already (kEnding: a second signal, on another thread, does
// nothing).
enum Phase { kRunning, kDeferring, kEnding };
std::atomic<int> g_phase{kRunning};
std::atomic<int> g_pending{0};
int g_deferrals = 0;  // SignalsDeferred alive (on the one thread that defers)

// Removes the folder `name` in the folder `at` with everything in it. By system calls alone: opendir and
// std::filesystem allocate, and a handler that allocates hangs when the signal came inside malloc. Each
// level holds a descriptor and a small buffer on the stack, and a stage is a few levels deep (a study's
// variant's stage); a name that cannot be removed is left, as the process ends anyway.
void remove_tree_at(int at, const char* name) {
  const int fd = ::openat(at, name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) return;
  alignas(dirent64) char entries[2048];
  for (ssize_t n; (n = ::getdents64(fd, entries, sizeof entries)) > 0;)
    for (ssize_t at_byte = 0; at_byte < n;) {
      const auto* entry = reinterpret_cast<const dirent64*>(entries + at_byte);
      at_byte += entry->d_reclen;
      const char* child = entry->d_name;
      if (std::strcmp(child, ".") == 0 || std::strcmp(child, "..") == 0) continue;
      if (::unlinkat(fd, child, 0) != 0 && errno == EISDIR) remove_tree_at(fd, child);
    }
  ::close(fd);
  ::unlinkat(at, name, AT_REMOVEDIR);
}

void remove_temporaries_and_die(int signal_number) {
  for (int i = 0; i < kSlots; ++i)
    if (g_state[i].load() == 2 + RemovedOnSignal::kFile) ::unlink(g_paths[i]);
  for (int i = 0; i < kSlots; ++i)
    if (g_state[i].load() == 2 + RemovedOnSignal::kTree) remove_tree_at(AT_FDCWD, g_paths[i]);
  // Folders after their files, and until none more goes: a folder in a registered folder empties it.
  for (bool removed = true; removed;) {
    removed = false;
    for (int i = 0; i < kSlots; ++i)
      if (g_state[i].load() == 2 + RemovedOnSignal::kFolder && ::rmdir(g_paths[i]) == 0) removed = true;
  }
  std::signal(signal_number, SIG_DFL);
  std::raise(signal_number);
}

extern "C" void on_signal(int signal_number) {
  int phase = kRunning;
  if (g_phase.compare_exchange_strong(phase, kEnding))
    remove_temporaries_and_die(signal_number);
  else if (phase == kDeferring)
    g_pending.store(signal_number);
}

}  // namespace

RemovedOnSignal::RemovedOnSignal(const std::string& path, Kind kind) {
  if (path.size() >= kSlotBytes) return;
  for (int i = 0; i < kSlots; ++i) {
    int expected = 0;
    if (!g_state[i].compare_exchange_strong(expected, 1)) continue;
    std::memcpy(g_paths[i], path.c_str(), path.size() + 1);
    g_state[i].store(2 + kind);
    slot_ = i;
    return;
  }
}

RemovedOnSignal::~RemovedOnSignal() {
  if (slot_ >= 0) g_state[slot_].store(0);
}

void remove_temporary_files_on_signals() {
  static_assert(std::atomic<int>::is_always_lock_free, "the signal handler reads these atomics");
  for (int signal_number : {SIGINT, SIGTERM, SIGHUP}) std::signal(signal_number, on_signal);
}

SignalsDeferred::SignalsDeferred() {
  if (g_deferrals++ > 0) return;
  int phase = kRunning;
  if (!g_phase.compare_exchange_strong(phase, kDeferring))
    for (;;) ::pause();  // a signal on another thread is ending the process: start nothing more
}

SignalsDeferred::~SignalsDeferred() {
  if (--g_deferrals > 0) return;
  g_phase.store(kRunning);
  const int pending = g_pending.exchange(0);
  if (pending != 0) on_signal(pending);  // as if it came now
}

void write_atomically(const std::string& final_path, const std::function<void(const std::string&)>& write) {
  const fs::path target(final_path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  if (!fs::is_directory(dir))
    throw InputError("cannot write '" + final_path + "': directory '" + dir.string() +
                     "' does not exist; create it first");
  const std::string tmp = temporary_path_beside(final_path, target.extension().string());
  const RemovedOnSignal registered(tmp);
  try {
    write(tmp);
  } catch (...) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw;
  }
  std::error_code ec;
  fs::rename(tmp, target, ec);
  if (ec) {
    std::error_code ignored;  // not ec: a remove that finds nothing clears it ("cannot write ...: Success")
    fs::remove(tmp, ignored);
    throw RunError(replace_refused(final_path, ec));
  }
}

std::string replace_refused(const std::string& path, const std::error_code& ec) {
  return "cannot write '" + path + "': " + ec.message() +
         " (the finished file could not take its place: an immutable file, which lsattr marks 'i' and "
         "chattr -i frees, or a read-only mount refuse it); free the file or choose another output name";
}

std::string temporary_path_beside(const std::string& final_path, const std::string& extension) {
  const fs::path target(final_path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  const std::string name = target.filename().string();
  std::string stem = name.substr(0, name.size() - std::min(name.size(), extension.size()));
  const std::string tag = ".tmp" + std::to_string(::getpid());
  const std::size_t most = longest_name_in(dir.string());
  const std::size_t added = 1 + tag.size() + extension.size();
  if (stem.size() + added > most) stem.resize(most > added ? most - added : 0);
  return (dir / ("." + stem + tag + extension)).string();
}

void write_file_atomically(const std::string& final_path, const std::string& contents) {
  write_atomically(final_path, [&](const std::string& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    if (!out)
      throw RunError("cannot write '" + final_path + "': " + std::strerror(errno) + " (creating '" + tmp +
                     "' beside it to write into first)");
    out.write(contents.data(), static_cast<std::streamsize>(contents.size()));
    out.close();
    if (!out) throw RunError("cannot write '" + final_path + "': " + kWriteFailed + ": " + kWriteAdvice);
  });
}

}  // namespace hexbite
