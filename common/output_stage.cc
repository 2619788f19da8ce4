#include "common/output_stage.h"

#include <fcntl.h>
#include <stdlib.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <iostream>
#include <map>
#include <set>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/progress.h"

namespace hexbite {

namespace fs = std::filesystem;

namespace {

// "out/" and "out" are the same folder; keep the spelling the user gave otherwise.
std::string without_trailing_separator(std::string dir) {
  while (dir.size() > 1 && dir.back() == '/') dir.pop_back();
  return dir;
}

constexpr char kStagePrefix[] = ".hexbite-stage-";

// The stage's maker holds an flock on the stage folder for the stage's life, taken right after creating it;
// a stage younger than this may not be locked yet.
constexpr auto kLockGrace = std::chrono::seconds(10);

// A run killed while it wrote (Ctrl-C, SIGKILL, a lost node) leaves its stage behind. A stage that nobody
// holds locked and that is older than kLockGrace is abandoned and removed, unless it holds an earlier run's
// files that an interrupted commit had set aside (.previous): those are the user's and are named instead.
void remove_abandoned_stages(const fs::path& dir) {
  std::error_code ec;
  std::vector<fs::path> stages;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir, ec)) {
    std::error_code kind;
    if (entry.path().filename().string().rfind(kStagePrefix, 0) == 0 && !entry.is_symlink(kind) &&
        entry.is_directory(kind))
      stages.push_back(entry.path());
  }
  for (const fs::path& stage : stages) {
    const fs::file_time_type written = fs::last_write_time(stage, ec);
    if (ec || fs::file_time_type::clock::now() - written < kLockGrace) continue;
    const int fd = ::open(stage.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    if (fd < 0) continue;
    if (::flock(fd, LOCK_EX | LOCK_NB) == 0) {  // no live run holds it (a failed flock: leave it be)
      const fs::path previous = stage / ".previous";
      if (fs::is_directory(previous, ec) && !fs::is_empty(previous, ec))
        std::cerr << "hexbite: warning: '" << previous.string()
                  << "' holds files of an earlier run that an interrupted run had set aside; move them back "
                     "into '"
                  << dir.string() << "' or delete the folder.\n";
      else
        fs::remove_all(stage, ec);
    }
    ::close(fd);
  }
}

// The folders this process holds locked (CommitLock), by device and inode: the descriptor holding the flock
// and how many CommitLocks hold it. Commits run on one thread.
struct HeldFolder {
  int fd = -1;
  int holders = 0;
};
std::map<std::pair<dev_t, ino_t>, HeldFolder> g_held;

}  // namespace

CommitLock::CommitLock(const std::vector<std::string>& dirs) {
  // Sorted: the order every process locks in. The descriptor and the folder's name as given.
  std::map<std::pair<dev_t, ino_t>, std::pair<int, std::string>> opened;
  for (const std::string& dir : dirs) {
    const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    struct stat st {};
    if (fd < 0) continue;  // the commit names what is wrong with the folder
    if (::fstat(fd, &st) != 0 ||
        !opened.emplace(std::make_pair(st.st_dev, st.st_ino), std::make_pair(fd, dir)).second)
      ::close(fd);
  }
  for (const auto& [folder, opened_dir] : opened) {
    const auto& [fd, dir] = opened_dir;
    HeldFolder& held = g_held[folder];
    if (held.holders++ > 0) {
      ::close(fd);
    } else {
      held.fd = fd;
      // A wait can be long (the other run stopped with Ctrl-Z): say why nothing happens.
      if (::flock(fd, LOCK_EX | LOCK_NB) != 0 && errno == EWOULDBLOCK)
        info("waiting for another hexbite process to finish writing into '" + dir + "'");
      while (::flock(fd, LOCK_EX) != 0 && errno == EINTR) {
      }
    }
    held_.push_back(folder);
  }
  deferred_.emplace();
}

CommitLock::~CommitLock() {
  for (const auto& folder : held_) {
    const auto it = g_held.find(folder);
    if (--it->second.holders > 0) continue;
    ::close(it->second.fd);  // lets go of the flock
    g_held.erase(it);
  }
}

OutputStage::OutputStage(const std::string& dir) : dir_(without_trailing_separator(dir)) {
  // The folders that do not exist yet, deepest first: a failed run removes them again.
  std::error_code ec;
  for (fs::path p = fs::path(dir_); !p.empty() && !fs::exists(fs::symlink_status(p, ec));
       p = p.parent_path()) {
    created_.push_back(p);
    if (p == p.parent_path()) break;
  }
  for (const fs::path& p : created_)
    on_signal_.push_back(std::make_unique<RemovedOnSignal>(p.string(), RemovedOnSignal::kFolder));
  fs::create_directories(dir_, ec);
  if (ec) {
    discard();
    throw RunError("cannot create the output folder '" + dir_ + "': " + ec.message());
  }
  remove_abandoned_stages(dir_);
  std::string name = (fs::path(dir_) / (std::string(kStagePrefix) + "XXXXXX")).string();
  if (::mkdtemp(name.data()) == nullptr) {
    const std::string reason = std::strerror(errno);
    discard();
    throw RunError("cannot write in the output folder '" + dir_ + "': " + reason +
                   "; make it writable or choose another output folder");
  }
  stage_ = name;
  on_signal_.push_back(std::make_unique<RemovedOnSignal>(stage_, RemovedOnSignal::kTree));
  // Marks the stage as in use for remove_abandoned_stages() of other runs into the same folder. On a file
  // system without flock their lock fails as well, and they leave the stage alone.
  lock_ = ::open(stage_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (lock_ >= 0) ::flock(lock_, LOCK_EX | LOCK_NB);
}

OutputStage::~OutputStage() {
  if (!done_) discard();
}

void OutputStage::discard() noexcept {
  done_ = true;
  std::error_code ec;
  if (!stage_.empty()) fs::remove_all(stage_, ec);
  for (const fs::path& p : created_) fs::remove(p, ec);  // only if empty: never what others put there
  release();
}

void OutputStage::release() noexcept {
  if (lock_ >= 0) ::close(lock_);
  lock_ = -1;
  on_signal_.clear();
}

std::string OutputStage::blocked(const std::vector<std::string>& files) const {
  const fs::path dir(dir_);
  std::error_code ec;
  for (const std::string& name : files) {
    const fs::path target = dir / name;
    for (fs::path p = fs::path(name).parent_path(); !p.empty(); p = p.parent_path()) {
      const fs::file_status status = fs::symlink_status(dir / p, ec);
      if (fs::exists(status) && !fs::is_directory(status))
        return "cannot write '" + target.string() + "': '" + (dir / p).string() +
               "' is a file, not a folder; remove or rename it, or choose another output folder";
    }
    if (fs::is_directory(fs::symlink_status(target, ec)))
      return "cannot write '" + target.string() +
             "': a folder of that name is in the way; remove or rename it, or choose another output folder";
  }
  return {};
}

void OutputStage::commit(const std::vector<std::string>& files,
                         const std::function<bool(const std::string&)>& retire) {
  const CommitLock locked({dir_});
  const fs::path dir(dir_), stage(stage_), previous = fs::path(stage_) / ".previous";
  // Every move done so far, to be undone (last first) when a later one fails; a move without `from` is a
  // folder made in the output folder, removed again.
  struct Move {
    fs::path from, to;
  };
  std::vector<Move> done;
  const auto move = [&](const fs::path& from, const fs::path& to, const fs::path& named) {
    std::error_code ec;
    fs::create_directories(to.parent_path(), ec);  // inside the stage's .previous: removed with the stage
    fs::rename(from, to, ec);
    if (ec) throw RunError(replace_refused(named.string(), ec));
    done.push_back({from, to});
  };
  // The folders of the output folder that the files go into ("" for the output folder itself).
  std::set<std::string> folders = {""};
  for (const std::string& name : files)
    for (fs::path p = fs::path(name).parent_path(); !p.empty(); p = p.parent_path())
      folders.insert(p.string());
  try {
    const std::string why = blocked(files);
    if (!why.empty()) throw RunError(why);
    std::error_code ec;
    fs::create_directory(previous, ec);
    if (ec) throw RunError("cannot write in the output folder '" + dir_ + "': " + ec.message());
    // The earlier run's files that this one does not rewrite go aside first (folders of such names are
    // not outputs and stay).
    const std::set<std::string> writing(files.begin(), files.end());
    if (retire) {
      std::vector<std::string> stale;
      for (const std::string& folder : folders) {
        if (!fs::is_directory(dir / folder, ec)) continue;
        const std::string prefix = folder.empty() ? "" : folder + "/";
        for (const fs::directory_entry& entry : fs::directory_iterator(dir / folder, ec)) {
          const std::string name = prefix + entry.path().filename().string();
          std::error_code kind;
          if (retire(name) && writing.count(name) == 0 && !entry.is_directory(kind)) stale.push_back(name);
        }
        if (ec)
          throw RunError("cannot list the output folder '" + (dir / folder).string() + "': " + ec.message());
      }
      std::sort(stale.begin(), stale.end());
      for (const std::string& name : stale) move(dir / name, previous / name, dir / name);
    }
    for (const std::string& name : files) {
      const fs::path target = dir / name, staged = stage / name;
      if (!fs::is_regular_file(staged, ec))
        throw RunError("cannot write '" + target.string() + "': it was not written to " + stage_ +
                       " (under mpirun the output folder must be on a file system that every rank sees)");
      // The folders above the file inside the output folder, outermost first.
      std::vector<fs::path> above;
      for (fs::path p = fs::path(name).parent_path(); !p.empty(); p = p.parent_path()) above.push_back(p);
      for (auto p = above.rbegin(); p != above.rend(); ++p) {
        if (fs::is_directory(fs::symlink_status(dir / *p, ec))) continue;
        fs::create_directory(dir / *p, ec);
        if (ec) throw RunError("cannot write '" + target.string() + "': " + ec.message());
        done.push_back({fs::path(), dir / *p});
      }
      if (fs::exists(fs::symlink_status(target, ec))) move(target, previous / name, target);
      move(staged, target, target);
    }
  } catch (const std::exception& e) {
    // Undo, last move first. Should that fail too (it renames within the same folders), the stage is kept
    // so that no earlier file is lost, and the message says where they are.
    std::string stuck;
    for (auto it = done.rbegin(); it != done.rend(); ++it) {
      std::error_code ec;
      if (it->from.empty()) {
        fs::remove(it->to, ec);  // a folder this commit made, empty again by now
        continue;
      }
      fs::rename(it->to, it->from, ec);
      if (ec) stuck += (stuck.empty() ? "" : ", ") + it->to.string();
    }
    if (!stuck.empty()) {
      done_ = true;  // keep the stage, and on a signal too
      release();
      throw RunError(std::string(e.what()) + "; moving the earlier files back failed as well: " + stuck +
                     " are in " + stage_ + ", move them back by hand");
    }
    discard();
    throw;
  }
  done_ = true;
  // The set is in place; what is left in the stage are the earlier run's replaced files.
  std::error_code ec;
  fs::remove_all(stage_, ec);
  release();
}

std::string named_in_dir(std::string message, const std::string& stage_dir, const std::string& dir) {
  if (stage_dir.empty()) return message;
  for (std::size_t at = message.find(stage_dir); at != std::string::npos;
       at = message.find(stage_dir, at + dir.size()))
    message.replace(at, stage_dir.size(), dir);
  return message;
}

}  // namespace hexbite
